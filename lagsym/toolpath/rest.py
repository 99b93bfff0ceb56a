"""Rest roughing: z levels and moves only where the stock earlier tools left stands above what this tool reaches.

The stock is a height map (machine mm) of what the tools before left
(:class:`StockMap`; a job builds it by pressing their moves into the block,
:mod:`lagsym.job.rest`).  The rows, their samples and each sample's floor
(the exact drop-cutter height of this tool plus its stock to leave, lifted
so the moves between samples stay above it) are the raster roughing's
(:func:`~lagsym.toolpath.rough.raster_samples`) over the block grown by the
tool radius (so the side of the tool takes what stands at the block's
edges), and so are the levels: the block's top down by the step-down.  At each sample the height map gives the
lowest tip at which the tool touches none of the stock left,

    M(x, y) = max over the cells within the tool radius of  H(cell) - profile(d)

(``d`` the cell's distance from the axis).  At a level ``z`` a sample needs
cutting where ``M`` stands more than :data:`MIN_CUT_MM` above the tip
``max(z, floor + lift)``; the tool cuts only the runs of such samples along
each row, each from the sample before it to the sample after it (where the
tool is clear of the stock).  It comes to each run at rapid above the block,
down at rapid to the clearance above the run's first tip and at the plunge
feed from there, cuts the run (no descent into what is left steeper than the
tool's ramp angle: :func:`~lagsym.toolpath.roughmoves.ramped`, with ``M``,
then the level's own tips, as the material under the tool) and goes straight
up at rapid.  Runs closer than their way up and down are joined: the tool
feeds through the air between them at the level.

So nothing is cut below the floor, as in the raster roughing, and a level
that finds nothing standing above it makes no moves at all.  ``M`` is the
height map's, to its resolution: the clearance above each run's first tip
keeps the rapid down clear of what lies between the cells.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import freeze_fields
from ..errors import ToolpathError
from ..machine import MachineSettings, Tool
from ..progress import Progress
from .plan import MAX_PLAN_POINTS
from .rough import (FEED, MAX_ROUGH_SAMPLES, PLUNGE, RAPID, RoughPath, RoughSpec, Stock, ramp_slope, raster_samples,
                    rough_levels)
from .roughmoves import climb_forward, kept_visits, ramped

__all__ = ["StockMap", "rest_toolpath", "material_under", "MIN_CUT_MM"]

MIN_CUT_MM = 0.05
"""A sample needs cutting where the stock left stands more than this above the tool's tip there."""
_CHUNK = 2048  # tool positions whose cells are gathered at once


@dataclass(frozen=True)
class StockMap:
    """What earlier tools left: ``heights_mm[i, j]`` over the cell centres ``(xs_mm[i], ys_mm[j])`` (evenly spaced,
    machine mm).  Beyond the map there is no stock."""

    xs_mm: np.ndarray
    ys_mm: np.ndarray
    heights_mm: np.ndarray

    def __post_init__(self):
        freeze_fields(self, ("xs_mm", "ys_mm", "heights_mm"), dtype=float)
        if self.heights_mm.shape != (len(self.xs_mm), len(self.ys_mm)) or min(self.heights_mm.shape) < 2:
            raise ToolpathError(f"a stock map of {self.heights_mm.shape} heights over {len(self.xs_mm)} x "
                                f"{len(self.ys_mm)} cells: it needs one height a cell, at least 2 x 2")


def material_under(left: StockMap, x, y, tool: Tool) -> np.ndarray:
    """The lowest tip (mm) at which ``tool`` centred at each ``(x[k], y[k])`` touches none of the stock ``left``.

    ``-inf`` where no cell of the map lies under the tool.

    Examples
    --------
    >>> m = StockMap(np.arange(5.0), np.arange(5.0), np.where(np.arange(5.0)[:, None] == 2, 3.0, 1.0) + 0 * np.arange(5.0))
    >>> material_under(m, [0.0, 2.0, 9.0], [2.0, 2.0, 2.0], Tool("flat", 2.0)).tolist()
    [1.0, 3.0, -inf]
    >>> # the ball's rim rises 1 - sqrt(1 - 0.5**2) = 0.134 over the cells 0.5 off its axis; the row x = 2 is 1.5 off
    >>> material_under(m, [0.5], [2.0], Tool("ball", 2.0)).round(3).tolist()
    [0.866]
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    xs, ys, h = left.xs_mm, left.ys_mm, left.heights_mm
    hx, hy, r = xs[1] - xs[0], ys[1] - ys[0], tool.radius_mm
    kx, ky = int(np.ceil(r / hx)) + 1, int(np.ceil(r / hy)) + 1
    di, dj = (a.ravel() for a in np.meshgrid(np.arange(-kx, kx + 1), np.arange(-ky, ky + 1), indexing="ij"))
    out = np.full(x.shape, -np.inf)
    for s in range(0, x.size, _CHUNK):
        px, py = x[s:s + _CHUNK], y[s:s + _CHUNK]
        ix = np.rint((px - xs[0]) / hx).astype(np.int64)[:, None] + di
        iy = np.rint((py - ys[0]) / hy).astype(np.int64)[:, None] + dj
        ok = (ix >= 0) & (ix < len(xs)) & (iy >= 0) & (iy < len(ys))
        ix, iy = np.clip(ix, 0, len(xs) - 1), np.clip(iy, 0, len(ys) - 1)
        d2 = (xs[ix] - px[:, None]) ** 2 + (ys[iy] - py[:, None]) ** 2
        ok &= d2 <= r * r
        top = h[ix, iy] - tool.profile_mm(np.minimum(d2, r * r))
        out[s:s + _CHUNK] = np.where(ok, top, -np.inf).max(axis=1)
    return out


def rest_toolpath(surface, tool: Tool, stock: Stock, left: StockMap, spec: RoughSpec, settings: MachineSettings, *,
                  evaluator=None, max_points: int | None = MAX_PLAN_POINTS,
                  max_samples: int | None = MAX_ROUGH_SAMPLES, progress: Progress | None = None) -> RoughPath:
    """Plan raster roughing of what ``left`` holds above this tool's floor, from ``stock``'s levels.

    As :func:`~lagsym.toolpath.rough.rough_toolpath` (the same ``spec``, raster
    rows only) but cutting only where the stock left stands above the tip
    (see the module).  Refused, in one line, when it stands nowhere more than
    :data:`MIN_CUT_MM` above what this tool reaches plus its stock to leave.
    """
    if spec.pattern != "raster":
        raise ToolpathError(f"rest roughing runs raster rows, not pattern {spec.pattern!r}")
    # Rows a tool radius beyond the block too: the side of the tool takes what stands at the block's edges.
    r = tool.radius_mm
    wider = Stock(stock.x0 - r, stock.x1 + r, stock.y0 - r, stock.y1 + r, stock.top_mm)
    rows, floors, lifts, sigma = raster_samples(surface, tool, wider, spec, settings, evaluator=evaluator,
                                                max_samples=max_samples, progress=progress)
    z_levels = rough_levels(floors, sigma, stock, (tool, spec), max_points)
    along_x = spec.direction == "x"
    mats = [material_under(left, r.along if along_x else np.full(len(r.along), r.cross),
                           np.full(len(r.along), r.cross) if along_x else r.along, tool) for r in rows]
    pts, kinds, floor = assemble_rest(rows, (floors, lifts, mats), z_levels, wider, spec, ramp_slope(tool))
    if not pts:
        most = max(float(np.max(m - np.where(np.isfinite(f), f + u, np.inf), initial=-np.inf))
                   for m, f, u in zip(mats, floors, lifts))
        raise ToolpathError(f"nothing left for rest roughing with {tool.label}: the stock left stands at most "
                            f"{max(most, 0.0):.3f} mm above what it reaches plus its stock to leave "
                            f"{spec.stock_to_leave_mm:g} mm (less than {MIN_CUT_MM:g} mm)")
    if max_points is not None and len(pts) > max_points:
        raise ToolpathError(f"the rest roughing is {len(pts):.3g} points, more than the limit of {max_points:.3g}; "
                            "use larger steps or raise the limit (--max-points)")
    return RoughPath(np.array(pts), np.array(kinds, dtype=np.int8), np.array(floor), z_levels, tool, stock, spec)


def cut_runs(cutting: np.ndarray, along: np.ndarray, join_mm: float) -> list[tuple[int, int]]:
    """``(lo, hi)`` sample ranges to cut: each run of cutting samples with the clear sample either side (where the
    row has one), runs whose gap along the row (``along``, the samples' positions on it) is shorter than
    ``join_mm`` joined."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], cutting.astype(np.int8), [0]])))
    out: list[tuple[int, int]] = []
    for p, q in zip(edges[::2], edges[1::2]):
        lo, hi = max(int(p) - 1, 0), min(int(q), len(cutting) - 1)  # a roughing row's ends are clear: 0 < p, q < n
        if out and abs(along[lo] - along[out[-1][1]]) < join_mm:
            out[-1] = (out[-1][0], hi)
        else:
            out.append((lo, hi))
    return out


def assemble_rest(rows, samples: tuple, z_levels, stock: Stock, spec: RoughSpec, tan_a: float):
    """The rest roughing's moves level by level: each row's runs, entered from above and left straight up.

    ``samples`` is ``(floors, lifts, mats)`` per row, ``mats`` the lowest tip
    clear of the stock left (:func:`material_under`); ``tan_a`` the steepest
    descent into material (rise per mm).  Returns points, kinds and floors as
    :func:`~lagsym.toolpath.roughmoves.assemble_raster` does.
    """
    floors, lifts, mats = samples
    mats = [m.copy() for m in mats]
    along_x = spec.direction == "x"
    top = stock.top_mm + spec.clearance_mm
    pts, kinds, floor = [], [], []

    def add(a, c, z, kind, f=-np.inf):
        pts.append((float(a), float(c), float(z)) if along_x else (float(c), float(a), float(z)))
        kinds.append(kind)
        floor.append(f)

    toggle = 0
    for k, zl in enumerate(z_levels):
        order = range(len(rows)) if k % 2 == 0 else range(len(rows) - 1, -1, -1)
        for i in order:
            r, f, mat = rows[i], floors[i], mats[i]
            want = np.maximum(zl, f + lifts[i])
            cutting = mat > want + MIN_CUT_MM
            if not cutting.any():
                continue
            if spec.milling == "zigzag":
                fwd, toggle = toggle % 2 == 0, toggle + 1
            else:
                fwd = climb_forward(spec.direction, 1 if k % 2 == 0 else -1) == (spec.milling == "climb")
            idx = np.arange(len(r.along)) if fwd else np.arange(len(r.along))[::-1]
            for lo, hi in cut_runs(cutting[idx], r.along[idx], 2 * (top - zl)):
                seg = idx[lo:hi + 1]
                visits, low = ramped(np.abs(np.diff(r.along[seg])), want[seg], mat[seg], tan_a)
                mat[seg] = np.minimum(mat[seg], low)
                vi = np.array([v[0] for v in visits])
                vz = np.array([v[1] for v in visits])
                a0 = r.along[seg[0]]
                add(a0, r.cross, top, RAPID)
                if vz[0] + spec.clearance_mm < top:
                    add(a0, r.cross, vz[0] + spec.clearance_mm, RAPID)
                add(a0, r.cross, vz[0], PLUNGE)
                for j in kept_visits(vi, vz)[1:]:
                    add(r.along[seg[vi[j]]], r.cross, vz[j], FEED, float(f[seg[vi[j]]]))
                add(r.along[seg[-1]], r.cross, top, RAPID)
    return pts, kinds, floor
