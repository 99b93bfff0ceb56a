"""B-spline surfaces: clamped, uniform knots, the control points as the net.

The basis (:class:`BSplineBasis`) is a value of its own: a degree and a knot
vector.  Its values come from SciPy's :meth:`scipy.interpolate.BSpline.design_matrix`.
With clamped uniform knots of degree ``n - 1`` over ``n`` control points
there are no interior knots and the basis *is* the Bernstein basis, so the
B-spline surface of full degree equals the Bezier surface.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from ..errors import InputError
from ..grid import ControlGrid
from .parametric import ParametricSurface

__all__ = ["BSplineBasis", "clamped_uniform_knots", "bspline_basis", "bspline_surface"]


def clamped_uniform_knots(size: int, degree: int) -> tuple[Fraction, ...]:
    """The clamped knot vector on ``[0, 1]`` with uniformly spaced interior knots.

    ``degree + 1`` zeros, ``size - degree - 1`` interior knots ``j / (size - degree)``
    and ``degree + 1`` ones: ``size + degree + 1`` knots in all.

    Examples
    --------
    >>> [str(k) for k in clamped_uniform_knots(5, 2)]
    ['0', '0', '0', '1/3', '2/3', '1', '1', '1']
    """
    if not 1 <= degree < size:
        raise ValueError(f"B-spline degree {degree} should be between 1 and {size - 1} for {size} control points")
    spans = size - degree
    interior = [Fraction(j, spans) for j in range(1, spans)]
    return (Fraction(0),) * (degree + 1) + tuple(interior) + (Fraction(1),) * (degree + 1)


@dataclass(frozen=True)
class BSplineBasis:
    """A B-spline basis on ``[0, 1]``: a degree and a clamped knot vector (exact).

    Attributes
    ----------
    degree : int
    knots : tuple of Fraction
    """

    degree: int
    knots: tuple[Fraction, ...]

    @property
    def size(self) -> int:
        """Number of basis functions, ``len(knots) - degree - 1``."""
        return len(self.knots) - self.degree - 1

    def evaluate(self, t) -> np.ndarray:
        """``B[p, i] = N_{i,degree}(t[p])`` for a 1-D array of parameters in ``[0, 1]``."""
        # Imported here: scipy.interpolate takes most of a second to load, and every
        # lagsym command would pay for it through the CLI's module discovery.
        from scipy.interpolate import BSpline

        t = np.clip(np.asarray(t, dtype=float).ravel(), 0.0, 1.0)
        knots = np.array([float(k) for k in self.knots])
        return BSpline.design_matrix(t, knots, self.degree).toarray()


def bspline_basis(size: int, degree: int) -> BSplineBasis:
    """The clamped uniform B-spline basis of ``degree`` with ``size`` functions.

    Examples
    --------
    >>> bspline_basis(4, 3).evaluate([0.5]).round(6).tolist()
    [[0.125, 0.375, 0.375, 0.125]]
    """
    return BSplineBasis(degree, clamped_uniform_knots(size, degree))


def bspline_surface(grid: ControlGrid, degree: int = 3) -> ParametricSurface:
    """The clamped uniform B-spline surface whose control net is ``grid``.

    Parameters
    ----------
    grid : ControlGrid
        The control net.
    degree : int, optional
        Degree in each direction (default 3), capped at one less than the
        number of control points in that direction.

    Returns
    -------
    ParametricSurface
        Named ``"B-spline"``.
    """
    if isinstance(degree, bool) or not isinstance(degree, int) or degree < 1:
        raise InputError(f"B-spline degree {degree!r} should be an integer >= 1")
    n, m = grid.shape
    return ParametricSurface("B-spline", grid, bspline_basis(n, min(degree, n - 1)),
                             bspline_basis(m, min(degree, m - 1)))
