"""Tensor-product parametric surfaces over a control net, read as graphs ``z = F(x, y)``.

A Bezier or B-spline surface is ``P(u, v) = sum_ik B_i(u) C_k(v) p_ik`` with
the control points ``p_ik = (x_i, y_k, z_ik)`` as its net.  Because every
``p_ik`` in a row shares ``x_i`` and the basis sums to one,

    x(u) = sum_i B_i(u) x_i,        y(v) = sum_k C_k(v) y_k,

so ``x`` depends on ``u`` alone and ``y`` on ``v`` alone.  Both are strictly
increasing when the nodes are (their derivatives are non-negative
combinations of the node differences), so each has an inverse.  To compare
with a function of ``(x, y)`` this module finds ``u(x)`` and ``v(y)`` first:
deviations are taken at the same ``(x, y)``, not at the same ``(u, v)``.  On an
evenly spaced Bezier net ``x(u)`` is affine; on a clamped B-spline net it is
not, even when the nodes are evenly spaced.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..grid import ControlGrid

__all__ = ["ParameterBasis", "ParametricSurface", "invert_parameter"]

_BISECTIONS = 64  # halves [0, 1] below one unit in the last place of a double


class ParameterBasis(Protocol):
    """A basis of functions of one parameter on ``[0, 1]`` that sum to one."""

    @property
    def size(self) -> int:
        """Number of basis functions (control points in this direction)."""

    def evaluate(self, t) -> np.ndarray:
        """Values ``B[p, i] = B_i(t[p])`` as an array of shape ``(len(t), size)``."""


def invert_parameter(basis: ParameterBasis, nodes, values) -> np.ndarray:
    """The parameters ``t`` in ``[0, 1]`` with ``sum_i B_i(t) nodes[i] == values``.

    Parameters
    ----------
    basis : ParameterBasis
        The basis in this direction.
    nodes : array_like
        Strictly increasing control coordinates, one per basis function.
    values : array_like
        Coordinates inside ``[nodes[0], nodes[-1]]``.

    Returns
    -------
    numpy.ndarray
        One parameter per value, found by bisection (the map is monotone, so
        bisection cannot miss).  The end nodes map to exactly 0 and 1; values
        outside the nodes' span are clamped to the nearer end.

    Examples
    --------
    >>> from lagsym.surfaces.bezier import BernsteinBasis
    >>> invert_parameter(BernsteinBasis(2), [0.0, 1.0, 2.0], [0.0, 0.5, 2.0]).tolist()
    [0.0, 0.25, 1.0]
    """
    nodes = np.asarray(nodes, dtype=float)
    values = np.asarray(values, dtype=float).ravel()
    lo = np.zeros(values.shape)
    hi = np.ones(values.shape)
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        below = basis.evaluate(mid) @ nodes < values
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    t = 0.5 * (lo + hi)
    t[values <= nodes[0]] = 0.0
    t[values >= nodes[-1]] = 1.0
    return t




@dataclass(frozen=True)
class ParametricSurface:
    """A tensor-product surface ``P(u, v)`` over a control grid, with its ``(x, y)`` inverse.

    Attributes
    ----------
    name : str
        The label tables use (``"Bezier"``, ``"B-spline"``).
    grid : ControlGrid
        The control net ``p_ik = (x_i, y_k, z_ik)``.
    basis_u, basis_v : ParameterBasis
        The bases in the ``u`` (along x) and ``v`` (along y) directions.
    """

    name: str
    grid: ControlGrid = field(repr=False)
    basis_u: ParameterBasis
    basis_v: ParameterBasis

    def parameters(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """``(u(x), v(y))``: the parameters at which the surface lies above ``x`` and ``y``."""
        return (invert_parameter(self.basis_u, self.grid.x_array, x),
                invert_parameter(self.basis_v, self.grid.y_array, y))

    def evaluate_uv(self, u, v) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The surface point ``(x, y, z)`` at parameters ``u`` and ``v`` (broadcast together)."""
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        bu = self.basis_u.evaluate(u.ravel())
        bv = self.basis_v.evaluate(v.ravel())
        x = bu @ self.grid.x_array
        y = bv @ self.grid.y_array
        z = np.einsum("pk,pk->p", bu @ self.grid.z_array, bv)
        return x.reshape(u.shape), y.reshape(u.shape), z.reshape(u.shape)

    def evaluate(self, x, y) -> np.ndarray:
        """Height of the surface above the points ``(x, y)`` (broadcast together)."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        u, v = self.parameters(x.ravel(), y.ravel())
        return self.evaluate_uv(u, v)[2].reshape(x.shape)

    def evaluate_grid(self, xs, ys) -> np.ndarray:
        """``Z[i, j]``: height above ``(xs[i], ys[j])``."""
        u, v = self.parameters(xs, ys)
        return self.basis_u.evaluate(u) @ self.grid.z_array @ self.basis_v.evaluate(v).T
