"""Read-only NumPy arrays for the frozen values lagsym passes around, and an exact scale for very large ones."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["readonly", "freeze_fields", "power_of_two_scale"]


def readonly(values, dtype=float) -> np.ndarray:
    """A read-only copy of ``values`` (never the caller's own array, which stays writable).

    Examples
    --------
    >>> a = np.zeros(2)
    >>> b = readonly(a)
    >>> b.flags.writeable, a.flags.writeable
    (False, True)
    """
    a = np.array(values, dtype=dtype)
    a.setflags(write=False)
    return a


def freeze_fields(obj, names, dtype=None) -> None:
    """Replace the array fields ``names`` of a frozen dataclass instance by read-only copies (in ``__post_init__``)."""
    for name in names:
        object.__setattr__(obj, name, readonly(getattr(obj, name), dtype))


def power_of_two_scale(*arrays) -> float:
    """1, or the power of two that brings the largest magnitude in ``arrays`` near 1 when it is beyond 2**500.

    Dividing by a power of two is exact, so sums and squares of heights near 1e300 can be taken in its
    units without overflow and scaled back.

    Examples
    --------
    >>> power_of_two_scale(np.array([3.0])), power_of_two_scale(np.array([1e300])) == 2.0**996
    (1.0, True)
    """
    big = max(float(np.max(np.abs(a))) for a in arrays)
    return 1.0 if big < 2.0**500 else math.ldexp(1.0, math.frexp(big)[1] - 1)
