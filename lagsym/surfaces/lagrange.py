"""The Lagrange surface as one of the compared methods.

A thin view of :class:`lagsym.lagrange.LagrangeSurface` with the shape every
compared surface has: a ``name`` and numeric ``evaluate``/``evaluate_grid``
(barycentric, from :mod:`lagsym.evaluate`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..evaluate import evaluate_grid, evaluate_points
from ..grid import ControlGrid
from ..exactsize import MAX_EXACT_MB
from ..lagrange import LagrangeSurface, lagrange_surface

__all__ = ["LagrangeMethod", "lagrange_method"]


@dataclass(frozen=True)
class LagrangeMethod:
    """The tensor-product Lagrange interpolant of a control grid, as a compared surface."""

    surface: LagrangeSurface
    name: str = "Lagrange"

    def evaluate(self, x, y) -> np.ndarray:
        """``F(x, y)`` at scattered points (broadcast together)."""
        return evaluate_points(self.surface, x, y)

    def evaluate_grid(self, xs, ys) -> np.ndarray:
        """``Z[i, j] = F(xs[i], ys[j])``."""
        return evaluate_grid(self.surface, xs, ys)


def lagrange_method(grid: ControlGrid, *, max_mb: float | None = MAX_EXACT_MB) -> LagrangeMethod:
    """The Lagrange surface through ``grid`` (exact core, numeric evaluation); ``max_mb`` as :func:`.lagrange_surface`."""
    return LagrangeMethod(lagrange_surface(grid, max_mb=max_mb))
