"""What drop-cutter on one polynomial (:mod:`.dropcutter`) and on pieces (:mod:`.droppieces`) share.

The margin added to every value, the tool positions kept within the box's
reach, the lattice of candidate contact points and the compiled kernel's
surface arguments.
"""

from __future__ import annotations

import functools
import math
import weakref
from typing import NamedTuple

import numpy as np

from ..errors import ToolpathError
from .newton import jet_coefficients, kernel_geometry

__all__ = ["CL_MARGIN"]

CL_MARGIN = 1e-7
"""Relative margin (of the surface's height span plus tool radius) added to every drop-cutter value."""


def _inside_box(cx, cy, box, radius=0.0):
    """The tool positions, refused if further than ``radius`` from the box (beyond rounding).

    A position within reach of the box keeps the box under part of the tool;
    those beyond the box are kept within ``radius`` of it.
    """
    x0, x1, y0, y1 = box
    eps_box = 1e-9 * max(x1 - x0, y1 - y0, radius)
    nx, ny = np.clip(cx, x0, x1), np.clip(cy, y0, y1)
    d = np.hypot(cx - nx, cy - ny)
    outside = d > radius + eps_box
    if np.any(outside):
        bad = int(np.flatnonzero(outside)[0])
        reach = f" by more than the tool radius {radius:g}" if radius > 0 else ""
        raise ToolpathError(f"tool position ({cx[bad]:g}, {cy[bad]:g}) lies outside the control points' box "
                            f"x {x0:g}..{x1:g}, y {y0:g}..{y1:g}{reach}")
    if radius == 0:
        return nx, ny
    return _kept_within(cx, cy, nx, ny, d, radius)


def _kept_within(cx, cy, nx, ny, d, radius: float):
    """Positions ``d`` from their nearest box points ``nx, ny`` moved towards them to at most ``radius``."""
    f = np.where(d > radius, radius / np.where(d > 0, d, 1.0), 1.0)
    return nx + (cx - nx) * f, ny + (cy - ny) * f


_HEIGHT_SCALES: weakref.WeakKeyDictionary[object, float] = weakref.WeakKeyDictionary()  # by evaluator


@functools.lru_cache(maxsize=16)
def _lattice(radius: float, spacing: float) -> _Lattice:
    """A square lattice inside the disc, plus points on its rim (for a flat end), laid out for the kernel.

    The offsets of the lattice points inside the disc (row by row) and then
    of the rim; their squared distances from the axis (the rim's the radius
    squared, which rounding would put just past); each lattice point's eight
    neighbours (-1 where none is inside); and for each rim point the
    lattice point nearest to it.
    """
    k = max(int(math.ceil(radius / spacing)), 1)
    t = np.linspace(-radius, radius, 2 * k + 1)
    gx, gy = np.meshgrid(t, t, indexing="ij")
    inside = gx**2 + gy**2 <= radius**2 * (1 + 1e-12)
    rim_n = max(8 * k, 16)
    a = np.linspace(0.0, 2 * math.pi, rim_n, endpoint=False)
    rim = radius * np.stack([np.cos(a), np.sin(a)], axis=1)
    pts = np.stack([gx[inside], gy[inside]], axis=1)
    nearest = np.argmin(((rim[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2), axis=1)
    index = np.full((2 * k + 3, 2 * k + 3), -1)
    index[1:-1, 1:-1][inside] = np.arange(len(pts))
    li, lj = np.nonzero(inside)
    nb = np.stack([index[li + 1 + di, lj + 1 + dj] for di in (-1, 0, 1) for dj in (-1, 0, 1) if di or dj], axis=1)
    reach2 = np.concatenate([np.minimum((pts**2).sum(axis=1), radius * radius), np.full(rim_n, radius * radius)])
    out = _Lattice(np.concatenate([pts, rim]), reach2, nb.astype(np.int64), nearest.astype(np.int64))
    for v in out:
        v.setflags(write=False)
    return out


class _Lattice(NamedTuple):
    offsets: np.ndarray
    reach2: np.ndarray
    neighbours: np.ndarray
    nearest: np.ndarray


def _kernel_surface(ev, radius, corner, spacing, settle, *, jets=None, at=None):
    """The kernel's surface arguments: the coefficients, the ball's jet coefficients and the geometry; the jets
    from ``jets[at]`` where a piecewise surface has made every piece's (the same, bit for bit)."""
    c = np.ascontiguousarray(ev.coefficients, dtype=float)
    if corner != radius:
        jet = np.zeros((6 * c.shape[1], c.shape[0]))
    else:
        # A writable copy: Numba compiles the kernel once for each kind of array, read-only ones included.
        jet = jet_coefficients(ev) if jets is None else np.require(jets[at], requirements="CW")
    return c, jet, kernel_geometry(ev, ev.bounds, radius, corner, spacing, settle)
