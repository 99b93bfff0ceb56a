"""The checks of the public evaluation functions' arguments: what they are given, as one InputError naming it."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..values import of_type

__all__ = ["coordinates", "broadcast_pair", "a_surface", "finite_heights"]


def coordinates(value, what: str) -> np.ndarray:
    """``value`` as a float array, or an InputError that names it."""
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what} = {value!r:.80} is not an array of numbers") from None


def broadcast_pair(x, y) -> tuple[np.ndarray, np.ndarray]:
    """``x`` and ``y`` as float arrays that broadcast together, or an InputError that gives their shapes."""
    x, y = coordinates(x, "x"), coordinates(y, "y")
    try:
        np.broadcast_shapes(x.shape, y.shape)
    except ValueError:
        raise InputError(f"x of shape {x.shape} and y of shape {y.shape} do not broadcast together") from None
    return x, y


def a_surface(value):
    """``value`` if it is a :class:`~lagsym.lagrange.LagrangeSurface`, else an InputError that names it."""
    from ..lagrange import LagrangeSurface

    return of_type(value, LagrangeSurface, "surface")


def finite_heights(z: np.ndarray, places) -> np.ndarray:
    """``z``, or an InputError naming the first point with finite coordinates whose height overflowed float64.

    ``places()`` gives the points' ``x`` and ``y`` in ``z``'s shape; it is
    called only when some height is not finite (a grid's coordinates are not
    spread out on every call for a check that nearly always passes).
    """
    if np.isfinite(z).all():
        return z
    x, y = places()
    bad = ~np.isfinite(z) & np.isfinite(x) & np.isfinite(y)
    if bad.any():
        k = np.flatnonzero(bad)[0]
        raise InputError(f"the height at x = {x.flat[k]:.6g}, y = {y.flat[k]:.6g} ({int(bad.sum())} of {z.size} "
                         "points) is beyond float64's range, far outside the control points' box: evaluate the exact "
                         "expression there")
    return z
