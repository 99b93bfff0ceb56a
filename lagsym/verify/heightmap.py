"""The height map a cut leaves: a tool pressed into a grid of cells along straight moves.

``cut[i, j]`` is the lowest height any part of the tool reached over the
cell centre ``(xs[i], ys[j])``.  Every move is sampled so that consecutive
tool positions are at most half a cell apart sideways and ``dz_mm`` apart in
height, and at each position the tool's exact lower surface
(:func:`lagsym.machine.cutter_profile`) is pressed into every cell centre
under it.  Work that would run away is refused before it starts: more cells
than ``max_cells`` (:func:`height_map_axes`) or more tool positions times
cells under the tool than ``max_contacts``.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError, ToolpathError
from ..machine import Tool, cutter_profile

__all__ = ["press_moves", "height_map_axes", "sweep", "tool_grid", "check_work", "MAX_CELLS", "MAX_CONTACTS"]

_MOVES_PER_PASS = 20_000
MAX_CELLS = 16_000_000  # height-map cells by default: 4000 x 4000, about 0.5 GB with the arrays compared
MAX_CONTACTS = 20_000_000_000  # tool positions (all, before those far from the box are dropped) times cells under the tool


def _samples(a: np.ndarray, b: np.ndarray, ds: float, dz: float) -> np.ndarray:
    """Points along the segments ``a[k] -> b[k]`` no further apart than ``ds`` sideways and ``dz`` in height."""
    d = b - a
    n = np.maximum(np.ceil(np.maximum(np.hypot(d[:, 0], d[:, 1]) / ds, np.abs(d[:, 2]) / dz)), 1).astype(np.int64)
    seg = np.repeat(np.arange(len(a)), n)
    first = np.concatenate([[0], np.cumsum(n)[:-1]])
    t = (np.arange(int(n.sum())) - np.repeat(first, n)) / np.repeat(n, n)
    pts = a[seg] + t[:, None] * d[seg]
    return np.vstack([pts, b[-1:]])


def sweep(cut, a_all, b_all, xs, ys, r, corner, ds, dz_mm) -> int:
    """Press the tool into ``cut`` along every move; the number of tool positions simulated.

    A few thousand moves at a time, so a long program never needs all its samples in memory at once.
    """
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    x0, x1, y0, y1 = xs[0], xs[-1], ys[0], ys[-1]
    positions = 0
    for s in range(0, len(a_all), _MOVES_PER_PASS):
        pts = _samples(a_all[s:s + _MOVES_PER_PASS], b_all[s:s + _MOVES_PER_PASS], ds, dz_mm)
        near = (pts[:, 0] >= x0 - r - hx) & (pts[:, 0] <= x1 + r + hx) & (pts[:, 1] >= y0 - r - hy) & (
            pts[:, 1] <= y1 + r + hy)
        pts = pts[near]
        positions += len(pts)
        if len(pts):
            _press(cut, pts, xs, ys, r, corner)
    return positions


def height_map_axes(box_mm, cell_mm: float | None, max_cells: int | None) -> tuple[np.ndarray, np.ndarray]:
    """Cell centres in x and y of a height map over ``box_mm`` ``(x0, x1, y0, y1)``, refused beyond ``max_cells``.

    ``cell_mm`` defaults to the longer side / 400.
    """
    x0, x1, y0, y1 = box_mm
    if cell_mm is None:
        cell_mm = max(x1 - x0, y1 - y0) / 400.0
    if not cell_mm > 0:
        raise ToolpathError(f"cell size {cell_mm!r} must be a positive number of mm")
    nx = max(int(math.ceil((x1 - x0) / cell_mm)) + 1, 2)
    ny = max(int(math.ceil((y1 - y0) / cell_mm)) + 1, 2)
    if max_cells is not None and nx * ny > max_cells:
        raise InputError(f"a height map of {nx} x {ny} cells of {cell_mm:g} mm is {nx * ny:.3g} cells, more than the "
                         f"limit of {max_cells:.3g}; use a larger cell (--cell) or raise the limit (--max-cells)")
    return np.linspace(x0, x1, nx), np.linspace(y0, y1, ny)


def check_work(a, b, ds: float, dz: float, r: float, hx: float, hy: float, max_contacts: int | None) -> None:
    """Refuse a simulation whose tool positions times cells under the tool would exceed ``max_contacts``."""
    if max_contacts is None:
        return
    d = b - a
    positions = float(np.maximum(np.ceil(np.maximum(np.hypot(d[:, 0], d[:, 1]) / ds, np.abs(d[:, 2]) / dz)), 1).sum())
    footprint = (2 * math.ceil(r / hx) + 3) * (2 * math.ceil(r / hy) + 3)
    if positions * footprint > max_contacts:
        raise InputError(
            f"simulating {positions:.3g} tool positions over {footprint:.3g} cells under the tool each is "
            f"{positions * footprint:.3g} contacts, more than the limit of {max_contacts:.3g}; check the program's "
            f"moves and the tool diameter, use a larger cell (--cell), or raise the limit (--max-contacts)")


def _press(cut, pts, xs, ys, r, corner):
    """Lower ``cut`` to the tool's lower surface at every sampled position (in place)."""
    nx, ny = cut.shape
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    ix = np.rint((pts[:, 0] - xs[0]) / hx).astype(np.int64)
    iy = np.rint((pts[:, 1] - ys[0]) / hy).astype(np.int64)
    # Group the positions by their nearest cell once: the same grouping serves every offset of the tool's footprint.
    key = ix * (ny + 4 * int(r / hy) + 8) + iy
    order = np.argsort(key, kind="stable")
    key, px, py, pz, ix, iy = key[order], pts[order, 0], pts[order, 1], pts[order, 2], ix[order], iy[order]
    starts = np.flatnonzero(np.concatenate([[True], key[1:] != key[:-1]]))
    gx, gy = ix[starts], iy[starts]
    kx, ky = int(math.ceil(r / hx)) + 1, int(math.ceil(r / hy)) + 1
    r2 = r * r
    for di in range(-kx, kx + 1):
        tx = gx + di
        okx = (tx >= 0) & (tx < nx)
        if not okx.any():
            continue
        cxs = xs[np.clip(ix + di, 0, nx - 1)]
        dx2 = (cxs - px) ** 2
        for dj in range(-ky, ky + 1):
            ty = gy + dj
            ok = okx & (ty >= 0) & (ty < ny)
            if not ok.any():
                continue
            cys = ys[np.clip(iy + dj, 0, ny - 1)]
            d2 = dx2 + (cys - py) ** 2
            inside = d2 <= r2
            h = np.where(inside, pz + cutter_profile(np.where(inside, d2, 0.0), r, corner), np.inf)
            m = np.minimum.reduceat(h, starts)
            sel = ok & np.isfinite(m)
            if sel.any():
                a, b = tx[sel], ty[sel]
                cut[a, b] = np.minimum(cut[a, b], m[sel])


def press_moves(cut: np.ndarray, xs: np.ndarray, ys: np.ndarray, a: np.ndarray, b: np.ndarray, tool: Tool,
                dz_mm: float = 0.01, max_contacts: int | None = MAX_CONTACTS) -> tuple[int, float]:
    """Lower the height map ``cut`` (in place) to the tool's lower surface along the moves ``a[k] -> b[k]`` (mm).

    ``cut[i, j]`` is the height over ``(xs[i], ys[j])``, evenly spaced cell
    centres.  Returns the number of tool positions simulated and the
    simulation's vertical resolution (as :func:`simulate_cut` states it).
    """
    r, corner, ds, resolution = tool_grid(tool, xs, ys, dz_mm)
    if not len(a):
        return 0, resolution
    check_work(a, b, ds, dz_mm, r, xs[1] - xs[0], ys[1] - ys[0], max_contacts)
    return sweep(cut, a, b, xs, ys, r, corner, ds, dz_mm), resolution


def tool_grid(tool: Tool, xs: np.ndarray, ys: np.ndarray, dz_mm: float) -> tuple[float, float, float, float]:
    """The simulated tool's radius and corner, the sample step along a move and the simulation's vertical resolution."""
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    r = tool.radius_mm if tool.radius_mm > 0 else 0.5 * min(hx, hy)
    corner = tool.corner_mm if tool.radius_mm > 0 else 0.0
    ds = 0.5 * min(hx, hy)
    # Between two samples the tool's lower surface can rise by its corner's sag over half a sample step.
    resolution = (corner - math.sqrt(max(corner * corner - (ds / 2) ** 2, 0.0)) if corner > 0 else 0.0) + dz_mm / 2
    return r, corner, ds, resolution
