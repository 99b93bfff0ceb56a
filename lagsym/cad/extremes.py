"""How high and how low a surface goes over its box, bounded from its Bezier form (certified, not sampled).

A Bezier patch lies within the range of its control points, and each half of
a patch (de Casteljau at the middle) is a Bezier patch whose points are
averages of the whole's: the halves' ranges close in on the surface's.
:func:`height_bounds` starts from the exact Bezier form of the surface over
its control box (:func:`.convert.bezier_patch`), rounded once to floats,
and halves the patches whose highest control point is more than a tolerance
above the highest value known to be reached (a sample, a corner), highest
first, until none is or a budget of patches is spent; what it states is
then the highest control point left, so never below the surface's maximum.
Floats stand for the exact averages: each rounding is half a unit of the
largest control point's size, and a patch is some tens of halvings from the
whole, so a pad of ``1e-10`` of the largest control point covers them all.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np

from ..evaluate import evaluate_grid
from .convert import bezier_patch

__all__ = ["height_bounds", "MAX_PATCHES", "Overshoot", "overshoot"]

MAX_PATCHES = 4000
"""Patches halved at most for each bound: beyond it the bound stated is the highest control point left."""

_PAD = 1e-10  # of the largest control point: the float roundings of the conversion and of every halving


def height_bounds(surface, *, reached: tuple[float, float], tolerance: float) -> tuple[float, float]:
    """``(lowest, highest)``: no point of ``surface`` over its control box lies outside.

    ``reached`` is a ``(low, high)`` pair of values the surface is known to
    take (the lowest and highest samples): patches are halved until their
    bound is within ``tolerance`` of what is reached, or :data:`MAX_PATCHES`
    are spent.  The exact Bezier form counts against the command's time limit
    for exact work (:mod:`lagsym.exactsize`).

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> from lagsym.lagrange import lagrange_surface
    >>> s = lagrange_surface(grid_from_table([0, 1, 2], [0, 1], [[0, 0], [1, 1], [0, 0]]))  # 2x - x**2
    >>> lo, hi = height_bounds(s, reached=(0.0, 1.0), tolerance=1e-6)
    >>> abs(lo) < 1e-9, 1.0 <= hi < 1.0 + 2e-6
    (True, True)
    """
    net = np.array([[float(v) for v in row] for row in bezier_patch(surface).heights()])
    pad = _PAD * float(np.abs(net).max())
    low, high = reached
    top = _highest(net, high, tolerance)
    bottom = -_highest(-net, -low, tolerance)
    return bottom - pad, top + pad


def _highest(net: np.ndarray, reached: float, tolerance: float) -> float:
    """The highest control point left once the patches within ``tolerance`` of the best value seen are kept."""
    seen = max(reached, float(net[0, 0]), float(net[0, -1]), float(net[-1, 0]), float(net[-1, -1]))
    heap = [(-float(net.max()), 0, 0, net)]  # by highest control point; ties by order of making
    made = 1
    while -heap[0][0] > seen + tolerance and made < MAX_PATCHES:
        _, _, depth, patch = heapq.heappop(heap)
        axis = depth % 2 if min(patch.shape) > 1 else int(patch.shape[1] > 1)
        for half in _halves(patch, axis):
            corners = (half[0, 0], half[0, -1], half[-1, 0], half[-1, -1])  # points of the surface itself
            seen = max(seen, *(float(c) for c in corners))
            heapq.heappush(heap, (-float(half.max()), made, depth + 1, half))
            made += 1
    return max(-heap[0][0], seen)


def _halves(net: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """The Bezier nets of the two halves of ``net`` along ``axis`` (de Casteljau at one half)."""
    rows = np.moveaxis(net, axis, 0).copy()
    n = rows.shape[0]
    left, right = np.empty_like(rows), np.empty_like(rows)
    for k in range(n):
        left[k] = rows[0]
        right[n - 1 - k] = rows[n - 1 - k]
        rows[:n - 1 - k] = 0.5 * (rows[:n - 1 - k] + rows[1:n - k])
    return np.moveaxis(left, 0, axis), np.moveaxis(right, 0, axis)


@dataclass(frozen=True)
class Overshoot:
    """How far a surface leaves its control points' height range over their box.

    ``sampled`` is the most seen on a grid of samples (near ``at``),
    ``most`` the certified bound (:func:`height_bounds`), ``share`` that bound
    over the data range, the figure judged.
    """

    sampled: float
    most: float
    share: float
    at: tuple[float, float]
    data_range: float


def overshoot(surface, samples_per_interval: int = 24) -> Overshoot:
    """The overshoot of the interpolant ``surface`` between its nodes: sampled on ``samples_per_interval``
    points between nodes each way, and bounded from its Bezier form within 0.1 % of the heights."""
    g = surface.grid
    dx, dy = g.degree
    xs = np.linspace(g.x_array[0], g.x_array[-1], dx * samples_per_interval + 1)
    ys = np.linspace(g.y_array[0], g.y_array[-1], dy * samples_per_interval + 1)
    zs = evaluate_grid(surface, xs, ys)
    zmin, zmax = float(g.z_array.min()), float(g.z_array.max())
    zrange = zmax - zmin
    over = max(float(zs.max()) - zmax, zmin - float(zs.min()), 0.0)
    i, j = np.unravel_index(np.argmax(np.maximum(zs - zmax, zmin - zs)), zs.shape)
    lo, hi = height_bounds(surface, reached=(float(zs.min()), float(zs.max())),
                           tolerance=1e-3 * max(zrange, abs(zmax), abs(zmin), 1e-300))
    most = max(hi - zmax, zmin - lo, over, 0.0)
    share = most / zrange if zrange > 0 else (0.0 if most <= 1e-9 * max(abs(zmax), 1.0) else float("inf"))
    return Overshoot(over, most, share, (float(xs[i]), float(ys[j])), zrange)
