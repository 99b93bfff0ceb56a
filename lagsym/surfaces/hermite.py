"""Bicubic Hermite (Ferguson) surfaces with tangents and twists estimated from the net.

A Ferguson patch over ``[x0, x1] x [y0, y1]`` is fixed by, at each corner, the
height ``z``, the slopes ``z_x`` and ``z_y`` and the twist ``z_xy``.  With the
cubic Hermite basis on one interval (:class:`HermiteBasis` holds it, for any
number of nodes, as value and slope matrices ``H``, ``K``) the surface is the
tensor product

    F = Hx Z Hy' + Kx Zx Hy' + Hx Zy Ky' + Kx Zxy Ky'.

The slopes come from :func:`difference_matrix`, the tangent rule used here:

* at an interior node, the central difference over the two neighbours,
  ``(z[i+1] - z[i-1]) / (x[i+1] - x[i-1])`` (Catmull-Rom on even spacing);
* at an end node, the one-sided difference to the neighbour,
  ``(z[1] - z[0]) / (x[1] - x[0])``.

Twists apply the same rule in both directions: ``Zxy = Dx Z Dy'``.

Two kinds are built from a control net (:data:`HERMITE_KINDS`):

``"corner"``
    one patch over the whole box from the four corner points, with the
    corner tangents taken from the net.  It meets the data only at the four
    corners, which is how the paper's table counts 4 coincided points.
``"piecewise"``
    one patch per cell of the net, C1 across cell edges, through every control point.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._arrays import readonly as _readonly
from ..errors import InputError
from ..grid import ControlGrid

__all__ = ["HERMITE_KINDS", "HermiteBasis", "HermiteSurface", "difference_matrix", "hermite_surface"]

HERMITE_KINDS = ("corner", "piecewise")


def difference_matrix(nodes) -> np.ndarray:
    """The matrix ``D`` with ``(D @ f)[i]`` the estimated slope at ``nodes[i]``.

    Central differences inside, one-sided differences at the two ends.

    Examples
    --------
    >>> difference_matrix([0.0, 1.0, 3.0]).tolist()
    [[-1.0, 1.0, 0.0], [-0.3333333333333333, 0.0, 0.3333333333333333], [0.0, -0.5, 0.5]]
    """
    x = np.asarray(nodes, dtype=float)
    n = len(x)
    d = np.zeros((n, n))
    for i in range(n):
        lo, hi = max(i - 1, 0), min(i + 1, n - 1)
        d[i, lo] -= 1.0 / (x[hi] - x[lo])
        d[i, hi] += 1.0 / (x[hi] - x[lo])
    return d


@dataclass(frozen=True)
class HermiteBasis:
    """The piecewise cubic Hermite basis on strictly increasing nodes.

    ``values(t)[p, i]`` and ``slopes(t)[p, i]`` are the weights of the value and of
    the slope at ``nodes[i]`` in the cubic through ``t[p]``'s interval.

    Examples
    --------
    >>> b = HermiteBasis((0.0, 2.0))
    >>> b.values([1.0]).tolist(), b.slopes([1.0]).tolist()
    ([[0.5, 0.5]], [[0.25, -0.25]])
    """

    nodes: tuple[float, ...]

    def _locate(self, t):
        x = np.asarray(self.nodes, dtype=float)
        t = np.asarray(t, dtype=float).ravel()
        j = np.clip(np.searchsorted(x, t, side="right") - 1, 0, len(x) - 2)
        h = x[j + 1] - x[j]
        s = (t - x[j]) / h
        return j, h, s

    def _spread(self, j, left, right) -> np.ndarray:
        out = np.zeros((len(j), len(self.nodes)))
        rows = np.arange(len(j))
        out[rows, j] = left
        out[rows, j + 1] = right
        return out

    def values(self, t) -> np.ndarray:
        """Weights of the node values: ``h00(s)`` and ``h01(s)``."""
        j, _, s = self._locate(t)
        return self._spread(j, 1 - 3 * s**2 + 2 * s**3, 3 * s**2 - 2 * s**3)

    def slopes(self, t) -> np.ndarray:
        """Weights of the node slopes: ``h * h10(s)`` and ``h * h11(s)``."""
        j, h, s = self._locate(t)
        return self._spread(j, h * (s - 2 * s**2 + s**3), h * (s**3 - s**2))


@dataclass(frozen=True)
class HermiteSurface:
    """A bicubic Hermite surface ``z = F(x, y)`` from corner data at a grid of nodes.

    Attributes
    ----------
    name : str
        Label for tables.
    basis_x, basis_y : HermiteBasis
        The nodes of the patches in each direction.
    z, zx, zy, zxy : numpy.ndarray
        Read-only ``(nodes_x, nodes_y)`` arrays: heights, slopes and twists at the nodes.
    """

    name: str
    basis_x: HermiteBasis
    basis_y: HermiteBasis
    z: np.ndarray = field(repr=False)
    zx: np.ndarray = field(repr=False)
    zy: np.ndarray = field(repr=False)
    zxy: np.ndarray = field(repr=False)

    def evaluate_grid(self, xs, ys) -> np.ndarray:
        """``Z[i, j] = F(xs[i], ys[j])``."""
        hx, kx = self.basis_x.values(xs), self.basis_x.slopes(xs)
        hy, ky = self.basis_y.values(ys), self.basis_y.slopes(ys)
        return hx @ self.z @ hy.T + kx @ self.zx @ hy.T + hx @ self.zy @ ky.T + kx @ self.zxy @ ky.T

    def evaluate(self, x, y) -> np.ndarray:
        """``F(x, y)`` at scattered points (broadcast together)."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        xr, yr = x.ravel(), y.ravel()
        hx, kx = self.basis_x.values(xr), self.basis_x.slopes(xr)
        hy, ky = self.basis_y.values(yr), self.basis_y.slopes(yr)
        z = sum(np.einsum("pk,pk->p", a @ c, b) for a, c, b in
                ((hx, self.z, hy), (kx, self.zx, hy), (hx, self.zy, ky), (kx, self.zxy, ky)))
        return z.reshape(x.shape)


def hermite_surface(grid: ControlGrid, kind: str = "corner") -> HermiteSurface:
    """The bicubic Hermite surface of ``grid``, of kind ``"corner"`` or ``"piecewise"``.

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> g = grid_from_table([0, 1, 2], [0, 1], [[0, 0], [1, 1], [4, 4]])
    >>> hermite_surface(g, "piecewise").evaluate(1.0, 0.5).item()
    1.0
    """
    if kind not in HERMITE_KINDS:
        raise InputError(f"Hermite kind {kind!r} is not one of {', '.join(HERMITE_KINDS)}")
    x, y, z = grid.x_array, grid.y_array, grid.z_array
    dx, dy = difference_matrix(x), difference_matrix(y)
    zx, zy, zxy = dx @ z, z @ dy.T, dx @ z @ dy.T
    if kind == "piecewise":
        return HermiteSurface("Hermite", HermiteBasis(tuple(map(float, x))), HermiteBasis(tuple(map(float, y))),
                              _readonly(z), _readonly(zx), _readonly(zy), _readonly(zxy))
    ends = np.ix_([0, -1], [0, -1])
    corners_x, corners_y = HermiteBasis((float(x[0]), float(x[-1]))), HermiteBasis((float(y[0]), float(y[-1])))
    return HermiteSurface("Hermite", corners_x, corners_y,
                          _readonly(z[ends]), _readonly(zx[ends]), _readonly(zy[ends]), _readonly(zxy[ends]))
