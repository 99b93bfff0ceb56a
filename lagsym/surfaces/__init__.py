"""Surfaces built from one control net, compared at the same ``(x, y)`` positions.

Every method here is a frozen value with a ``name`` and two numeric
evaluators, the small protocol :class:`Surface`:

``evaluate(x, y)``
    heights at scattered points (``x`` and ``y`` broadcast together);
``evaluate_grid(xs, ys)``
    ``Z[i, j]``, the height above ``(xs[i], ys[j])``.

Factories are plain functions, one module per method: :func:`bezier_surface`,
:func:`bspline_surface`, :func:`hermite_surface` and :func:`lagrange_method`.
:func:`make_surface` picks one by the names in :data:`METHODS`.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from ..exactsize import MAX_EXACT_MB
from ..values import choice
from ..grid import ControlGrid
from .bezier import BernsteinBasis, bernstein_matrix, bezier_surface
from .bspline import BSplineBasis, bspline_basis, bspline_surface, clamped_uniform_knots
from .hermite import HERMITE_KINDS, HermiteBasis, HermiteSurface, difference_matrix, hermite_surface
from .lagrange import LagrangeMethod, lagrange_method
from .parametric import ParametricSurface, invert_parameter

__all__ = [
    "HERMITE_KINDS",
    "METHODS",
    "BSplineBasis",
    "BernsteinBasis",
    "HermiteBasis",
    "HermiteSurface",
    "LagrangeMethod",
    "ParametricSurface",
    "Surface",
    "bernstein_matrix",
    "bezier_surface",
    "bspline_basis",
    "bspline_surface",
    "clamped_uniform_knots",
    "difference_matrix",
    "hermite_surface",
    "invert_parameter",
    "lagrange_method",
    "make_surface",
]

METHODS = ("lagrange", "hermite", "bezier", "bspline")


@runtime_checkable
class Surface(Protocol):
    """What every compared surface offers."""

    name: str

    def evaluate(self, x, y) -> np.ndarray:
        """Heights at scattered points."""

    def evaluate_grid(self, xs, ys) -> np.ndarray:
        """``Z[i, j]`` above ``(xs[i], ys[j])``."""


def make_surface(method: str, grid: ControlGrid, *, degree: int = 3, hermite: str = "corner",
                 max_mb: float | None = MAX_EXACT_MB) -> Surface:
    """Build the surface of ``method`` (one of :data:`METHODS`) from ``grid``.

    Parameters
    ----------
    method : {"lagrange", "hermite", "bezier", "bspline"}
    grid : ControlGrid
        The control net all methods share.
    degree : int, optional
        B-spline degree in each direction (default 3, capped at ``n - 1``).
    hermite : {"corner", "piecewise"}, optional
        Which Hermite surface (see :mod:`lagsym.surfaces.hermite`).
    max_mb : float or None, optional
        The Lagrange surface's limit on its exact rationals (:func:`lagsym.lagrange.lagrange_surface`).

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> g = grid_from_table([0, 1], [0, 1], [[0, 1], [1, 2]])
    >>> [make_surface(m, g).name for m in METHODS]
    ['Lagrange', 'Hermite', 'Bezier', 'B-spline']
    """
    choice(method, METHODS, "method")
    if method == "lagrange":
        return lagrange_method(grid, max_mb=max_mb)
    if method == "hermite":
        return hermite_surface(grid, hermite)
    if method == "bezier":
        return bezier_surface(grid)
    return bspline_surface(grid, degree)
