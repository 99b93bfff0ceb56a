"""Lagrange curves in the Chebyshev basis of a normalized coordinate (the 1-D case of :mod:`.surface`)."""

from __future__ import annotations

from dataclasses import dataclass

import flint
import numpy as np

from .._arrays import readonly as _readonly
from ..values import of_type
from .arguments import coordinates
from .cache import ObjectCache
from .chebyshev import chebyshev_basis, chebyshev_transform, data_range, fmpq, fraction

__all__ = ["CurveEvaluator", "curve_evaluator", "evaluate_curve"]


@dataclass(frozen=True, eq=False)
class CurveEvaluator:
    """A 1-D Lagrange curve in the Chebyshev basis of a normalized coordinate (see :class:`SurfaceEvaluator`)."""

    offset: float
    scale: float
    coefficients: np.ndarray
    data_range: float

    def __call__(self, x) -> np.ndarray:
        """``F(x)`` for ``x`` of any shape."""
        x = np.asarray(x, dtype=float)
        basis = chebyshev_basis(x, self.offset, self.scale, len(self.coefficients))
        return (self.coefficients @ basis).reshape(x.shape)


def curve_evaluator(curve) -> CurveEvaluator:
    """The :class:`CurveEvaluator` of a :class:`~lagsym.lagrange.LagrangeCurve` (remembered like :func:`surface_evaluator`)."""
    return _CURVES.get(curve)


def _make_evaluator(curve) -> CurveEvaluator:
    """The exact change of basis of ``curve``, rounded once to floats."""
    off, scale, a = chebyshev_transform(curve.points.x)
    n = len(curve.coefficients)
    d = a * flint.fmpq_mat(n, 1, [fmpq(c) for c in curve.coefficients])
    return CurveEvaluator(offset=off, scale=scale,
                          coefficients=_readonly([float(fraction(d[k, 0])) for k in range(n)]),
                          data_range=data_range(curve.points.y))


_CURVES: ObjectCache[CurveEvaluator] = ObjectCache(_make_evaluator)


def evaluate_curve(curve, x) -> np.ndarray:
    """Evaluate a :class:`~lagsym.lagrange.LagrangeCurve` at ``x`` (any shape)."""
    from ..lagrange import LagrangeCurve

    return curve_evaluator(of_type(curve, LagrangeCurve, "curve"))(coordinates(x, "x"))
