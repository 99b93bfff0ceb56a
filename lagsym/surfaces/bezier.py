"""Bezier surfaces: the tensor-product Bernstein surface with the control points as its net.

The Bernstein basis of degree ``n`` on ``[0, 1]``,

    b_{i,n}(t) = C(n, i) t**i (1 - t)**(n - i),      i = 0..n,

is a value of its own (:class:`BernsteinBasis`); :func:`bernstein_matrix` does
the work and accepts exact :class:`fractions.Fraction` parameters as well as
floats, so its exact properties can be checked with ``==``.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from math import comb

import numpy as np

from ..grid import ControlGrid
from .parametric import ParametricSurface

__all__ = ["BernsteinBasis", "bernstein_matrix", "bezier_surface"]


def bernstein_matrix(degree: int, t) -> np.ndarray:
    """Values of the Bernstein polynomials of ``degree`` at the parameters ``t``.

    Parameters
    ----------
    degree : int
        ``n >= 0``; there are ``n + 1`` polynomials.
    t : array_like
        Parameters in ``[0, 1]``: floats, or ints and Fractions for exact values.

    Returns
    -------
    numpy.ndarray
        Shape ``t.shape + (degree + 1,)``; entry ``[..., i]`` is ``b_{i,n}(t)``.
        Object dtype holding Fractions when ``t`` is exact.

    Examples
    --------
    >>> bernstein_matrix(2, [Fraction(1, 2)]).tolist()
    [[Fraction(1, 4), Fraction(1, 2), Fraction(1, 4)]]
    >>> bernstein_matrix(3, [0.0, 1.0]).tolist()
    [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    """
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or degree < 0:
        raise ValueError(f"Bernstein degree {degree!r} should be an integer >= 0")
    raw = np.asarray(t, dtype=object)
    if raw.size and all(isinstance(v, (int, Fraction)) and not isinstance(v, bool) for v in raw.ravel()):
        flat = [Fraction(v) for v in raw.ravel()]
        rows = [[comb(degree, i) * v**i * (1 - v) ** (degree - i) for i in range(degree + 1)] for v in flat]
        out = np.empty((len(flat), degree + 1), dtype=object)
        out[:] = rows if rows else out
        return out.reshape(raw.shape + (degree + 1,))
    t = np.asarray(t, dtype=float)[..., None]
    i = np.arange(degree + 1)
    c = np.array([comb(degree, k) for k in i], dtype=float)
    return c * t**i * (1.0 - t) ** (degree - i)


@dataclass(frozen=True)
class BernsteinBasis:
    """The Bernstein basis of one degree on ``[0, 1]``.

    Examples
    --------
    >>> BernsteinBasis(3).size
    4
    """

    degree: int

    def __post_init__(self):
        if isinstance(self.degree, bool) or not isinstance(self.degree, int) or self.degree < 1:
            raise ValueError(f"Bernstein degree {self.degree!r} should be an integer >= 1")

    @property
    def size(self) -> int:
        """Number of basis functions, ``degree + 1``."""
        return self.degree + 1

    def evaluate(self, t) -> np.ndarray:
        """``B[p, i] = b_{i,n}(t[p])`` for a 1-D array of parameters."""
        return bernstein_matrix(self.degree, np.ravel(t))


def bezier_surface(grid: ControlGrid) -> ParametricSurface:
    """The Bezier surface whose control net is ``grid``, of degree ``(n - 1, m - 1)``.

    It meets the control net at the four corners and nowhere else in general.

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> s = bezier_surface(grid_from_table([0, 1, 2], [0, 1], [[0, 0], [4, 4], [0, 0]]))
    >>> float(s.evaluate(1.0, 0.5))
    2.0
    """
    n, m = grid.shape
    return ParametricSurface("Bezier", grid, BernsteinBasis(n - 1), BernsteinBasis(m - 1))
