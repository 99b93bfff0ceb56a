"""Numbers as a CNC control reads them.

Every number carries a decimal point (a Fanuc reads ``X12`` as 0.012 mm in
least-input-increment mode) and a fixed number of decimals; scientific
notation never appears (``8e-04`` is not a number to a control).
"""

from __future__ import annotations

import math
from decimal import ROUND_HALF_EVEN, Decimal
from fractions import Fraction

import numpy as np

from ..errors import ProgramError

__all__ = ["fixed", "program_ints"]


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



def program_ints(points_mm, unit_factor: float, digits: int) -> np.ndarray:
    """Points (mm) in units of the program's last decimal: X and Y to the nearest, Z rounded up.

    Rounding Z up means a written point never lies below its cutter location,
    so the rounding cannot gouge; it raises a point by less than one unit of
    the last decimal.  ``unit_factor`` is program units per mm.

    Examples
    --------
    >>> program_ints(np.array([[1.0004, 2.0, -0.0008]]), 1.0, 3).tolist()
    [[1000, 2000, 0]]
    """
    v = np.asarray(points_mm, dtype=float) * (unit_factor * 10 ** digits)
    out = np.empty(v.shape, dtype=np.int64)
    out[:, :2] = np.rint(v[:, :2])
    out[:, 2] = np.ceil(v[:, 2] - 1e-6)  # 1e-6 of a unit: a value that is a whole unit up to float error stays
    return out
