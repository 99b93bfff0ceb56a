"""The public evaluation functions: a surface's heights at points or on a grid, with the arguments checked.

The evaluator (:mod:`.surface`) computes; here NaN coordinates give NaN
and a height beyond float64's range is refused naming the point, with no
NumPy warning on the way.
"""

from __future__ import annotations

import numpy as np

from .arguments import a_surface, broadcast_pair, coordinates, finite_heights
from .surface import surface_evaluator

__all__ = ["evaluate_points", "evaluate_grid"]


def evaluate_points(surface, x, y) -> np.ndarray:
    """Evaluate a surface at scattered points; ``x`` and ``y`` broadcast together.

    A NaN coordinate gives NaN; a height beyond float64's range (far outside
    the box, at a high degree) is an InputError naming the point.
    """
    x, y = broadcast_pair(x, y)
    with np.errstate(over="ignore", invalid="ignore"):
        z = surface_evaluator(a_surface(surface)).points(x, y)
    return finite_heights(z, lambda: np.broadcast_arrays(x, y))


def evaluate_grid(surface, xs, ys) -> np.ndarray:
    """Evaluate a surface on the grid ``xs`` x ``ys``; result ``Z[i, j] = F(xs[i], ys[j])``; as :func:`evaluate_points`
    for NaN and overflow."""
    xs, ys = coordinates(xs, "xs"), coordinates(ys, "ys")
    with np.errstate(over="ignore", invalid="ignore"):
        z = surface_evaluator(a_surface(surface)).grid(xs, ys)
    return finite_heights(z, lambda: np.meshgrid(xs, ys, indexing="ij"))
