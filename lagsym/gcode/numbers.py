"""Numbers as a CNC control reads them.

Every number carries a decimal point (a Fanuc reads ``X12`` as 0.012 mm in
least-input-increment mode) and a fixed number of decimals; scientific
notation never appears (``8e-04`` is not a number to a control).
"""

from __future__ import annotations

import math
from decimal import ROUND_HALF_EVEN, Decimal
from fractions import Fraction

from ..errors import ProgramError

__all__ = ["fixed"]


def fixed(value: float | Fraction | Decimal, decimals: int = 3, trim: bool = False) -> str:
    """Format ``value`` with a decimal point and ``decimals`` places, never in scientific notation.

    With ``trim`` the trailing zeros go, but the point stays (``12.`` not ``12``).

    Examples
    --------
    >>> fixed(12, 3), fixed(0.0008, 4), fixed(-0.0001, 3), fixed(12.5, 3, trim=True), fixed(12, 3, trim=True)
    ('12.000', '0.0008', '0.000', '12.5', '12.')
    """
    if isinstance(value, float) and not math.isfinite(value):
        raise ProgramError(f"cannot write {value!r} in a program")
    if isinstance(value, Fraction):
        d = Decimal(value.numerator) / Decimal(value.denominator)
    else:
        d = Decimal(repr(value)) if isinstance(value, float) else Decimal(value)
    q = d.quantize(Decimal(1).scaleb(-decimals), rounding=ROUND_HALF_EVEN)
    if q == 0:
        q = abs(q)  # never "-0.000"
    text = format(q, "f")
    if "." not in text:
        text += "."
    if trim:
        text = text.rstrip("0")
    return text

