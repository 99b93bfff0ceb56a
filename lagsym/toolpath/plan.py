"""The plan: pattern, cutter locations, filtering and chordal checks put together into a :class:`Toolpath`.

:func:`plan_toolpath` runs the steps in order, each a function of its own
below: choose the steps, sample every row and the links between rows finely
with drop-cutter, keep the points the filter (or the fixed step) emits, bound
and check the sag of each move, lift the moves by it, and place the result on
the machine.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._arrays import freeze_fields
from ..errors import ToolpathError
from ..evaluate import SurfaceEvaluator, surface_evaluator
from ..machine import MachineSettings, RasterSpec, Tool
from . import chordal
from .dropcutter import drop_cutter
from .filter import filter_rows
from .pattern import raster_pattern, scallop_stepover, tool_reach, within_reach

__all__ = ["Toolpath", "plan_toolpath", "MAX_PLAN_POINTS"]

MAX_PLAN_POINTS = 20_000_000  # fine drop-cutter samples of one plan by default: about 2 GB of arrays


@dataclass(frozen=True)
class Toolpath:
    """A planned zig-zag: cutter locations (tool tip) in machine millimetres, in cutting order.

    Attributes
    ----------
    points_mm : ndarray, shape (N, 3)
        Programmed tip positions X, Y, Z in mm, work offset and stock included;
        read-only.
    rows : ndarray, shape (N,)
        Row number of each point; read-only.
    exact_mm : ndarray, shape (N,)
        The drop-cutter height at each point before the lift for chordal
        error; ``points_mm[:, 2] - exact_mm`` is that lift (0 or more).
    tool : Tool
    raster : RasterSpec
    stepover_mm, step_mm : float
        The side step and forward step actually used (with a chordal
        tolerance, ``step_mm`` is the sampling step the filter started from).
    bounds_mm : tuple of float
        The control points' box on the machine, ``(x0, x1, y0, y1)``.  The
        tool positions stay inside it (``raster.boundary`` ``centre``), the
        tool radius inside it (``inside``) or within the tool radius of it
        (``past``).
    fine_points : int
        How many cutter locations the filter chose the points from (the
        blocks a program would have without filtering).
    """

    points_mm: np.ndarray
    rows: np.ndarray
    exact_mm: np.ndarray
    tool: Tool
    raster: RasterSpec
    stepover_mm: float
    step_mm: float
    bounds_mm: tuple[float, float, float, float] = field(default=(0.0, 0.0, 0.0, 0.0))
    fine_points: int = 0

    def __post_init__(self):
        freeze_fields(self, ("points_mm", "rows", "exact_mm"))

    def __len__(self) -> int:
        return len(self.points_mm)

    @property
    def lift_mm(self) -> np.ndarray:
        """How far each point was raised above its drop-cutter value to keep the moves above the cutter path."""
        return self.points_mm[:, 2] - self.exact_mm


def plan_toolpath(surface, tool: Tool, raster: RasterSpec, settings: MachineSettings,
                  evaluator: SurfaceEvaluator | None = None, max_points: int | None = MAX_PLAN_POINTS) -> Toolpath:
    """Plan a zig-zag raster of gouge-free cutter locations over the surface.

    Parameters
    ----------
    surface : LagrangeSurface
        The exact surface; lengths in its units become mm by ``settings.mm_per_unit``.
    tool : Tool
        Cutter shape and diameter (mm).
    raster : RasterSpec
        Direction and steps (mm), or scallop height and chordal tolerance.
    settings : MachineSettings
        Scale, work offset and stock to leave.
    evaluator : SurfaceEvaluator, optional
        The surface's evaluator (by default :func:`lagsym.evaluate.surface_evaluator`).
    max_points : int or None
        Refuse, before any work, a plan of more fine drop-cutter samples than
        this (``--max-points``); None for no limit.

    Returns
    -------
    Toolpath

    Examples
    --------
    >>> from lagsym.grid import grid_from_points
    >>> from lagsym.lagrange import lagrange_surface
    >>> s = lagrange_surface(grid_from_points([(0, 0, 1), (0, 1, 1), (1, 0, 1), (1, 1, 1)]))
    >>> tp = plan_toolpath(s, Tool("ball", 0.0), RasterSpec("x", 0.5, 0.5), MachineSettings(mm_per_unit=1.0))
    >>> tp.points_mm[:, :2].tolist()  # zig-zag: along x, up the edge, back
    [[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [1.0, 0.5], [0.5, 0.5], [0.0, 0.5], [0.0, 1.0], [0.5, 1.0], [1.0, 1.0]]
    >>> bool((tp.points_mm[:, 2] == 1.0).all()), tp.rows.tolist()
    (True, [0, 0, 0, 1, 1, 1, 2, 2, 2])
    """
    ev = evaluator or surface_evaluator(surface)
    mm_per_unit = settings.mm_per_unit
    tol = raster.chordal_tolerance_mm
    cl = _Cutter.of(surface, ev, tool, settings)
    # Two units of the program's last decimal short of the radius: moved to the grid, a position stays within it.
    past = min(_past_reach(ev, tool.shape, cl.radius), cl.radius - 2 * cl.grid) if raster.boundary == "past" else None
    reach = tool_reach(ev.bounds, cl.radius, raster.boundary, past)
    stepover = _side_step(tool, raster)
    step, fine = _forward_steps(raster, ev, mm_per_unit)
    _check_size(reach, raster.direction, stepover, fine, mm_per_unit, max_points)
    levels, along = raster_pattern(reach, raster.direction, stepover / mm_per_unit, fine / mm_per_unit)
    path = _fine_path(cl, levels, along, raster.direction, fine, past)
    kappa = ev.curvature_bound() / mm_per_unit
    bend = np.concatenate([chordal.bends(path.z[lo:hi + 1])[:-1] for lo, hi, _ in path.pieces] + [[0.0]])
    kept = _emitted(path, tol, np.maximum(bend, chordal.semi_convex_sag(path.s_mm, kappa)), raster.step_mm)
    sag, seen = chordal.move_sags(path.s_mm, path.z, kept, bend, kappa)
    vx, vy, vz, vrow = path.x[kept], path.y[kept], path.z[kept], path.row[kept]
    # Where the tool meets a box edge the path may bend between samples; where it does not bend near
    # a move, the samples show its sag.  A move whose estimated sag exceeds the tolerance is split too.
    # Beyond a corner the rows follow an arc around it, and a move's chord passes nearer the corner than the
    # samples on the arc: checked too.
    x0, x1, y0, y1 = ev.bounds
    corner = ((vx < x0) | (vx > x1)) & ((vy < y0) | (vy > y1))
    dense = ((chordal.crosses_box_edge(vx, vy, ev.bounds, cl.radius) & chordal.bent_moves(kept, bend))
             | corner[:-1] | corner[1:] | (sag > tol))
    vx, vy, vz, vrow, sag = chordal.check_moves(cl, vx, vy, vz, vrow, sag, seen, dense, tol, cl.radius)
    b = ev.bounds
    bx, by, _ = _place(settings, np.array(b[:2]), np.array(b[2:]), 0.0)
    return Toolpath(
        **_without_repeats(np.stack(_place(settings, vx, vy, vz + chordal.lift(sag)), axis=1), vrow,
                           _place(settings, vx, vy, vz)[2], cl.grid * mm_per_unit),
        tool=tool,
        raster=raster,
        stepover_mm=float((levels[1] - levels[0]) * mm_per_unit) if len(levels) > 1 else float(stepover),
        step_mm=float(step),
        bounds_mm=(float(bx[0]), float(bx[1]), float(by[0]), float(by[1])),
        fine_points=len(path.x),
    )


def _without_repeats(points_mm, rows, exact_mm, unit_mm: float) -> dict:
    """The points without those at the same X and Y as the one before and within a unit of its Z.

    Beyond a box corner several samples can land on one point of the
    program's grid; the program would write no block for the repeat.  The
    point kept takes the higher of the two heights.
    """
    same = np.zeros(len(points_mm), dtype=bool)
    same[1:] = ((points_mm[1:, 0] == points_mm[:-1, 0]) & (points_mm[1:, 1] == points_mm[:-1, 1])
                & (np.abs(np.diff(points_mm[:, 2])) < unit_mm))
    if not same.any():
        return dict(points_mm=points_mm, rows=rows, exact_mm=exact_mm)
    first = np.cumsum(~same) - 1  # the kept point each one merges into
    keep = np.flatnonzero(~same)
    z, e = np.full(len(keep), -np.inf), np.full(len(keep), -np.inf)
    np.maximum.at(z, first, points_mm[:, 2])
    np.maximum.at(e, first, exact_mm)
    p = points_mm[keep].copy()
    p[:, 2] = z
    return dict(points_mm=p, rows=rows[keep], exact_mm=e)


def _place(settings: MachineSettings, x, y, z_mm):
    """Surface positions ``x, y`` (surface units) and tip heights ``z_mm`` (mm) on the machine.

    The heights are already in mm because the chordal tolerances apply to
    them; only the work offset is added.
    """
    place = settings.placement
    x_mm, y_mm = place.to_machine(x, y)
    return x_mm, y_mm, np.asarray(z_mm) + place.origin_mm[2]


def _check_size(bounds, direction: str, stepover: float, fine: float, scale: float, max_points: int | None) -> None:
    """Refuse a plan whose fine samples (rows times samples per row) would exceed ``max_points``."""
    if max_points is None:
        return
    x0, x1, y0, y1 = (float(v) for v in bounds)
    length, cross = (x1 - x0, y1 - y0) if direction == "x" else (y1 - y0, x1 - x0)
    rows = math.ceil(cross * scale / stepover) + 1
    per_row = math.ceil(length * scale / fine) + 1
    if rows * per_row > max_points:
        raise ToolpathError(
            f"{rows} rows of {per_row} fine samples is {rows * per_row:.3g} drop-cutter points, more than the limit "
            f"of {max_points:.3g} (side step {stepover:g} mm, sampling step {fine:g} mm); use larger steps "
            f"or raise the limit (--max-points)")


_SLOPE_SAMPLES = 257  # points along each box edge where the steepest slope is measured


def _past_reach(ev: SurfaceEvaluator, shape: str, radius: float) -> float:
    """How far beyond the box the tool axis goes with ``--boundary past`` (surface units).

    A flat end touches the box edge up to its radius beyond it.  A ball
    touches a slope of angle ``a`` at ``radius * sin(a)`` from its axis, so
    beyond ``radius * sin(a)`` for the steepest slope ``a`` on the box edges
    it reaches nothing the positions nearer the box have not; further out it
    would touch the part's edge only near its equator, where a sideways
    rounding of the position moves the tool a long way down the edge.
    """
    if shape != "ball" or radius == 0:
        return radius
    x0, x1, y0, y1 = ev.bounds
    t = np.linspace(0.0, 1.0, _SLOPE_SAMPLES)
    ex = np.concatenate([x0 + t * (x1 - x0), x0 + t * (x1 - x0), np.full_like(t, x0), np.full_like(t, x1)])
    ey = np.concatenate([np.full_like(t, y0), np.full_like(t, y1), y0 + t * (y1 - y0), y0 + t * (y1 - y0)])
    slope = float(np.hypot(ev.fast_points(ex, ey, dx=1), ev.fast_points(ex, ey, dy=1)).max())
    # A little further than the samples show, for the slope between them.
    return min(radius, 1.02 * radius * slope / math.hypot(1.0, slope))


def _side_step(tool: Tool, raster: RasterSpec) -> float:
    """The side step asked for (mm), or the one a ball leaves the scallop height with."""
    if raster.stepover_mm is not None:
        return raster.stepover_mm
    if tool.shape != "ball":
        raise ToolpathError("a scallop height (--scallop) needs a ball-end cutter; give --stepover for a flat end")
    return scallop_stepover(tool.radius_mm, raster.scallop_mm)


def _forward_steps(raster: RasterSpec, ev: SurfaceEvaluator, mm_per_unit: float) -> tuple[float, float]:
    """The longest move (mm) and the finer sampling step the filter chooses points from (mm).

    The sampling step is one whose own chordal error on the surface is a
    quarter of the tolerance, and with a fixed step at most half of it.
    """
    fine = chordal.tolerance_step(ev, raster.chordal_tolerance_mm, mm_per_unit)
    if raster.step_mm is None:
        return fine, fine
    return raster.step_mm, min(raster.step_mm / 2.0, fine)


@dataclass(frozen=True)
class _Cutter:
    """Tool-tip heights (mm) over surface positions, as the planner computes them.

    The radius (surface units) includes the stock to leave for a ball, which
    then rides that much higher; a flat end is lifted by the stock instead.
    :meth:`on_grid` moves the points to emit beyond the box (``--boundary
    past``) to the program's grid (their X and Y as the program writes them),
    before their cutter locations are computed: there the tool touches the
    part's edges with its side, where rounding X or Y by half a unit of the
    last decimal would lower it against the edge by many units.
    """

    surface: object
    ev: SurfaceEvaluator
    radius: float
    shape: str
    lift_tip: float
    mm_per_unit: float
    settings: MachineSettings | None = None

    @classmethod
    def of(cls, surface, ev: SurfaceEvaluator, tool: Tool, settings: MachineSettings) -> _Cutter:
        r_mm, stock, mm_per_unit = tool.radius_mm, settings.stock_to_leave_mm, settings.mm_per_unit
        r = (r_mm + (stock if tool.shape == "ball" else 0.0)) / mm_per_unit
        lift_tip = r - r_mm / mm_per_unit if tool.shape == "ball" else stock / mm_per_unit
        return cls(surface, ev, r, tool.shape, lift_tip, mm_per_unit, settings)

    @property
    def grid(self) -> float:
        """The program's unit of the last decimal, in surface units."""
        s = self.settings
        return 10.0 ** -s.digits / s.unit_factor / self.mm_per_unit if s is not None else 0.0

    def on_grid(self, x, y):
        """The positions beyond the box moved to the program's grid; those over the box as they are."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        x0, x1, y0, y1 = self.ev.bounds
        out = (x < x0) | (x > x1) | (y < y0) | (y > y1)
        if self.settings is None or not out.any():
            return x, y
        place, k = self.settings.placement, self.settings.unit_factor * 10 ** self.settings.digits
        mx, my = place.to_machine(x[out], y[out])
        sx, sy = place.to_surface(np.rint(np.asarray(mx) * k) / k, np.rint(np.asarray(my) * k) / k)
        x, y = x.copy(), y.copy()
        x[out], y[out] = sx, sy
        return x, y

    def __call__(self, x, y, **search) -> np.ndarray:
        z = drop_cutter(self.surface, x, y, self.radius, self.shape, evaluator=self.ev, **search)
        return (z + self.lift_tip) * self.mm_per_unit


@dataclass(frozen=True)
class _FinePath:
    """One fine polyline through all rows and the links between them, with its cutter locations.

    ``x, y`` in surface units, ``z`` tip heights in mm, ``s_mm`` arc length
    along the polyline, ``row`` the row of each sample; ``pieces`` the rows
    and links in order as ``(first, last, is_row)`` sample indices, each
    piece starting where the one before ends.
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    row: np.ndarray
    s_mm: np.ndarray
    pieces: tuple[tuple[int, int, bool], ...]


def _fine_path(cl: _Cutter, levels, along, direction: str, fine: float, past: float | None) -> _FinePath:
    """Drop the tool over every fine sample of every row and of the links between rows, in cutting order.

    With the tool ``past`` the boundary (that far, surface units), positions
    further than that from a box corner are brought back onto the arc around
    it (the rows round the corners).
    """
    gap = (levels[1] - levels[0]) if len(levels) > 1 else 0.0
    link_n = max(2, 2 * int(math.ceil(gap * cl.mm_per_unit / fine / 2)))
    u = np.linspace(0.0, 1.0, link_n + 1)[1:-1]
    fa, fl, frow, pieces = [], [], [], []
    count = 0
    for i in range(len(levels)):
        t = along if i % 2 == 0 else along[::-1]
        fa += [t]
        fl += [np.full_like(t, levels[i])]
        frow += [np.full(len(t), i)]
        row_end = count + len(t) - 1
        pieces.append((count, row_end, True))
        count = row_end + 1
        if i + 1 < len(levels):
            # The link runs along the row's end to the next row's start.
            fa += [np.full_like(u, t[-1])]
            fl += [levels[i] + u * gap]
            frow += [np.full(len(u), i)]
            pieces.append((row_end, row_end + len(u) + 1, False))
            count += len(u)
    fa, fl, frow = (np.concatenate(v) for v in (fa, fl, frow))
    fx, fy = (fa, fl) if direction == "x" else (fl, fa)
    if past is not None:
        fx, fy = cl.on_grid(*within_reach(fx, fy, cl.ev.bounds, past))
    fz = cl(fx, fy)
    s_mm = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(fx), np.diff(fy)))]) * cl.mm_per_unit
    return _FinePath(fx, fy, fz, frow, s_mm, tuple(pieces))


def _emitted(path: _FinePath, tol: float, extra: np.ndarray, longest_mm: float | None) -> np.ndarray:
    """Indices of the fine samples to emit.

    With a chordal tolerance alone, the filter keeps the moves within it.
    With a fixed step (the longest move), every fine sample a step apart is
    kept (the samples are at most half a step apart) and, where a move's sag
    exceeds the tolerance, the samples inside it too: points are added where
    the path bends.  ``extra`` is the sag between samples added to what the
    samples show.
    """
    s_mm, z = path.s_mm, path.z
    if longest_mm is None:
        kept = [0]
        for lo, hi, _ in path.pieces:
            k = filter_rows(s_mm[lo:hi + 1] - s_mm[lo], z[lo:hi + 1], tol, extra[lo:hi + 1]) + lo
            kept.extend(int(v) for v in k[1:])
        return np.array(kept, dtype=int)
    every = []
    for lo, hi, _ in path.pieces:
        widest = float(np.diff(s_mm[lo:hi + 1]).max()) if hi > lo else longest_mm
        e = max(1, int(longest_mm * (1 + 1e-9) // widest))
        every.append(np.append(np.arange(lo, hi, e), hi))
    kept = np.unique(np.concatenate(every))
    sag, _ = chordal.move_sags(s_mm, z, kept, extra, 0.0)
    split = np.flatnonzero((sag > tol) & (np.diff(kept) > 1))
    if not split.size:
        return kept
    inner = np.concatenate([np.arange(kept[m] + 1, kept[m + 1]) for m in split])
    return np.union1d(kept, inner)


