"""What the STEP and IGES writers share: numbers as text, units, knot multiplicities.

Exact coordinates become the nearest binary double (``float(Fraction)`` rounds
correctly) written with the 17 significant digits that read back to the same
double; CAD kernels store doubles, so this is as exact as the files can be.
"""

from __future__ import annotations

from fractions import Fraction

from ..values import choice

__all__ = ["UNITS", "check_units", "real", "multiplicities"]

UNITS = ("mm", "inch")  # the length units the files declare, as lagsym.io reads them


def check_units(units: str) -> str:
    """``units`` if it is one lagsym can write, else an InputError naming the choices."""
    return choice(units, UNITS, "units")


def real(v) -> str:
    """A number as a STEP/IGES real: always with a decimal point, exponent in upper case.

    Examples
    --------
    >>> real(Fraction(53, 50)), real(2), real(Fraction(1, 10**9))
    ('1.06', '2.', '1.E-09')
    """
    text = repr(float(v)).upper()
    mantissa, _, exponent = text.partition("E")
    if "." not in mantissa:
        mantissa += "."
    elif mantissa.endswith(".0"):
        mantissa = mantissa[:-1]
    return mantissa + (f"E{int(exponent):+03d}" if exponent else "")


def multiplicities(knots) -> tuple[list[Fraction], list[int]]:
    """Distinct knots and how often each repeats.

    Examples
    --------
    >>> multiplicities([0, 0, 1, 2, 2])
    ([0, 1, 2], [2, 1, 2])
    """
    values, counts = [], []
    for k in knots:
        if values and values[-1] == k:
            counts[-1] += 1
        else:
            values.append(k)
            counts.append(1)
    return values, counts
