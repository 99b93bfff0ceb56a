"""The plan: pattern, cutter locations, filtering and chordal checks put together into a :class:`Toolpath`.

:func:`plan_toolpath` runs the steps in order, each a function of its own
below: choose the steps, sample every row and the links between rows finely
with drop-cutter, keep the points the filter (or the fixed step) emits, bound
and check the sag of each move, lift the moves by it, and place the result on
the machine.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .._arrays import freeze_fields
from ..errors import ToolpathError
from ..evaluate import SurfaceEvaluator
from ..machine import Placement, ProgramFormat, RasterSpec, Tool
from ..progress import Progress, Tally
from ..values import positive
from . import chordal
from .arcs import Arcs, fit_arcs
from .dropcutter import drop_cutter, evaluator_of, telling_compiles
from .filter import filter_rows
from .pattern import (every_step, fixed_step_samples, past_reach, raster_pattern, reach_levels, scallop_stepover,
                      tool_reach, within_reach)
from .resolution import ResolutionGrid, without_repeats
from .plansize import check_size, scallop_rows
from .scallop import row_cusps
from .workers import MIN_POINTS, Workers

__all__ = ["Toolpath", "plan_toolpath", "MAX_PLAN_POINTS"]

MAX_PLAN_POINTS = 5_000_000  # fine drop-cutter samples of one plan by default: some 300 bytes each at the peak
_ROW_BLOCK = 1 << 15  # fine samples dropped at a time, whole rows


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
        The side step and forward step actually used (with a scallop height,
        ``stepover_mm`` is the widest gap between rows; with a chordal
        tolerance, ``step_mm`` is the sampling step the filter started from).
    bounds_mm : tuple of float
        The control points' box on the machine, ``(x0, x1, y0, y1)``.  The
        tool positions stay inside it (``raster.boundary`` ``centre``), the
        tool radius inside it (``inside``) or within the tool radius of it
        (``past``).
    fine_points : int
        How many cutter locations the filter chose the points from (the
        blocks a program would have without filtering).
    cusp_mm : float or None
        For a ball end, the worst cusp predicted between the rows, measured
        normal to the surface (mm), outside hollows tighter than the ball
        (:mod:`lagsym.toolpath.scallop`); None for other cutters.
    cusp_at_mm : tuple of float or None
        Where that cusp is, ``(x, y)`` on the machine.
    hollow_share : float or None
        The share of the box (of the prediction's samples) in hollows
        tighter than the ball, whose bottom it cannot reach: there the cusp
        prediction does not hold.
    note, threshold_deg, levels : str, float, int or None
        Of waterline finishing (:mod:`.waterline`): header note, slope of the contours, levels.
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
    cusp_mm: float | None = None
    cusp_at_mm: tuple[float, float] | None = None
    arcs: Arcs | None = None
    hollow_share: float | None = None
    note: str | None = None
    threshold_deg: float | None = None
    levels: int | None = None

    def __post_init__(self):
        freeze_fields(self, ("points_mm", "rows", "exact_mm"))

    def __len__(self) -> int:
        return len(self.points_mm)

    @property
    def lift_mm(self) -> np.ndarray:
        """How far each point was raised above its drop-cutter value to keep the moves above the cutter path."""
        return self.points_mm[:, 2] - self.exact_mm


def plan_toolpath(surface, tool: Tool, raster: RasterSpec, placement: Placement = Placement(),
                  program: ProgramFormat = ProgramFormat(), *, evaluator: SurfaceEvaluator | None = None,
                  max_points: int | None = MAX_PLAN_POINTS, stock_to_leave_mm: float = 0.0,
                  progress: Progress | None = None) -> Toolpath:
    """Plan a zig-zag raster of gouge-free cutter locations over the surface.

    Parameters
    ----------
    surface : LagrangeSurface or PiecewiseSurface
        The exact surface, one polynomial or C1 pieces (:mod:`lagsym.surfaces.piecewise`); lengths in its
        units become mm by ``placement.mm_per_unit``.
    tool : Cutter
        Cutter shape and diameter (mm).
    raster : RasterSpec
        Direction and steps (mm), or scallop height and chordal tolerance.
    placement : Placement
        Where the surface sits on the machine: scale and work offset.
    program : ProgramFormat
        How the program is written: its units and decimals are the positions
        the plan may use (its resolution), its control the chordal limit of arcs.
    evaluator : SurfaceEvaluator, optional
        The surface's evaluator (by default :func:`lagsym.evaluate.surface_evaluator`).
    max_points : int or None
        Refuse, before any work, a plan of more fine drop-cutter samples than
        this (``--max-points``); None for no limit.
    stock_to_leave_mm : float
        Material left above the surface, mm: the cutter is grown by it.
    progress : Progress, optional
        Told the fine samples dropped, then the checks' (:mod:`lagsym.progress`).

    Returns
    -------
    Toolpath

    Examples
    --------
    >>> from lagsym.grid import grid_from_points
    >>> from lagsym.lagrange import lagrange_surface
    >>> s = lagrange_surface(grid_from_points([(0, 0, 1), (0, 1, 1), (1, 0, 1), (1, 1, 1)]))
    >>> tp = plan_toolpath(s, Tool("ball", 0.0), RasterSpec("x", 0.5, 0.5), Placement(1.0))
    >>> tp.points_mm[:, :2].tolist()  # zig-zag: along x, up the edge, back
    [[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [1.0, 0.5], [0.5, 0.5], [0.0, 0.5], [0.0, 1.0], [0.5, 1.0], [1.0, 1.0]]
    >>> bool((tp.points_mm[:, 2] == 1.0).all()), tp.rows.tolist()
    (True, [0, 0, 0, 1, 1, 1, 2, 2, 2])
    """
    ev = evaluator or evaluator_of(surface)
    mm_per_unit = placement.mm_per_unit
    tol = raster.chordal_tolerance_mm
    cl, past, reach = cutter_and_reach(surface, ev, tool, raster, placement, program,
                                       stock_to_leave_mm=stock_to_leave_mm)
    step, fine = chordal.forward_steps(ev, raster.chordal_tolerance_mm, raster.step_mm, mm_per_unit, program)
    scallop, levels, along, every = _pattern(ev, tool, raster, cl, reach, step=step, fine=fine, max_points=max_points)
    if scallop is None and tool.is_ball and tool.radius_mm > 0:  # the cusps a fixed side step leaves
        scallop = row_cusps(ev, raster.direction, levels, tool.radius_mm, mm_per_unit, raster.stepover_mm)
    kappa = ev.curvature_bound() / mm_per_unit
    # Drop-cutter's compiled kernel loaded here (the first time, compiled), before the workers fork: they share it.
    with telling_compiles(progress):
        cl(np.array([ev.bounds[0]]), np.array([ev.bounds[2]]))
    # Worker processes on the other cores where the plan pays for them.
    one = len(levels) * len(along) < MIN_POINTS
    with Workers(ev, 1 if one else None) as workers:
        cl = replace(cl, workers=workers)
        path = _fine_path(cl, levels, along, raster.direction, fine, past=past, progress=progress)
        tp = _checked(ev, cl, path, tol, raster, kappa=kappa, every=every, placement=placement, progress=progress)
    bx, by, _ = _place(placement, np.array(ev.bounds[:2]), np.array(ev.bounds[2:]), 0.0)
    tp = Toolpath(**tp, tool=tool, raster=raster,
                  stepover_mm=float(np.diff(levels).max() * mm_per_unit) if len(levels) > 1
                  else float(_side_step(tool, raster)),
                  step_mm=float(step), bounds_mm=(float(bx[0]), float(bx[1]), float(by[0]), float(by[1])),
                  fine_points=len(path.x), **_cusp(scallop, raster.direction, placement))
    return _with_arcs(tp, path, cl, placement, program, kappa) if raster.arcs else tp


def _checked(ev, cl, path, tol, raster, *, kappa, every, placement, progress=None) -> dict:
    """The emitted points of the fine path, its moves checked and lifted: the point fields of a :class:`Toolpath`."""
    bend = np.concatenate([chordal.bends(path.z[lo:hi + 1])[:-1] for lo, hi, _ in path.pieces] + [[0.0]])
    kept = _emitted(path, tol, np.maximum(bend, chordal.semi_convex_sag(path.s_mm, kappa)), raster.step_mm, every)
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
    with Tally(progress, "checking moves") as checks:
        vx, vy, vz, vrow, sag = chordal.check_moves(checks.counting(cl), vx, vy, vz, vrow, sag, seen=seen,
                                                    dense=dense, tol=tol, radius=cl.radius)
    return without_repeats(np.stack(_place(placement, vx, vy, vz + chordal.lift(sag)), axis=1), vrow,
                           _place(placement, vx, vy, vz)[2], cl.unit * cl.mm_per_unit)


def _with_arcs(tp: Toolpath, path: _FinePath, cl: _Cutter, placement: Placement, program: ProgramFormat,
               kappa: float) -> Toolpath:
    """The toolpath with the arcs fitted along its rows from the fine samples (:func:`.arcs.fit_arcs`)."""
    fine = np.stack(_place(placement, path.x, path.y, path.z), axis=1)
    x0, x1, y0, y1 = tp.bounds_mm
    raster = tp.raster
    return replace(tp, arcs=fit_arcs(tp.points_mm, tp.rows, tp.exact_mm, fine, direction=raster.direction,
                                     kappa=kappa, tol=raster.chordal_tolerance_mm,
                                     unit_factor=program.unit_factor, digits=program.digits, units=program.units,
                                     reach_mm=(x0, x1) if raster.direction == "x" else (y0, y1),
                                     radius_mm=cl.radius * cl.mm_per_unit, chord_mm=program.control.chord_mm))


def _pattern(ev, tool: Tool, raster: RasterSpec, cl: _Cutter, reach, *, step: float, fine: float,
             max_points: int | None):
    """The rows over the reach: ``(scallop, levels, along, every)``, checked for size first.

    ``scallop`` is the rows from a scallop height (None for a side step),
    ``every`` how many samples along a row make one move with a fixed step
    (None with a tolerance alone).
    """
    mm_per_unit = cl.mm_per_unit
    stepover = _side_step(tool, raster)
    scallop = None if raster.stepover_mm is not None else scallop_rows(ev, tool, raster, reach, fine=fine,
                                                                        mm_per_unit=mm_per_unit,
                                                                        max_points=max_points)
    if scallop is not None:  # rows walked across the surface: the size check counts them
        stepover = _span(ev.bounds, raster.direction) * mm_per_unit / max(len(scallop.levels) - 1, 1)
    check_size(reach, raster.direction, stepover, fine, mm_per_unit, max_points)
    levels, along = raster_pattern(reach, raster.direction, stepover / mm_per_unit, fine / mm_per_unit)
    if scallop is not None:  # the rows across the box, then as far as the tool reaches on either side
        levels = reach_levels(scallop.levels, *(reach[2:] if raster.direction == "x" else reach[:2]))
    every = None
    if raster.step_mm is not None:
        along, every = fixed_step_samples(along[0], along[-1], step / mm_per_unit, fine / mm_per_unit,
                                           lambda v: cl.snap_axis(v, 0 if raster.direction == "x" else 1))
    return scallop, levels, along, every


def _span(bounds, direction: str) -> float:
    """The box's extent across the rows (surface units)."""
    x0, x1, y0, y1 = (float(v) for v in bounds)
    return y1 - y0 if direction == "x" else x1 - x0


def _cusp(scallop, direction: str, placement: Placement) -> dict:
    """The worst predicted cusp, where it is on the machine and the share of hollows too tight for the ball."""
    if scallop is None:
        return {}
    p, c = scallop.worst_at
    x, y = placement.to_machine(*((p, c) if direction == "x" else (c, p)))
    return {"cusp_mm": scallop.worst_mm, "cusp_at_mm": (float(x), float(y)),
            "hollow_share": scallop.tight / max(scallop.samples, 1)}


def _place(place: Placement, x, y, z_mm):
    """Surface positions ``x, y`` (surface units) and tip heights ``z_mm`` (mm) on the machine.

    The heights are already in mm because the chordal tolerances apply to
    them; only the work offset is added.
    """
    x_mm, y_mm = place.to_machine(x, y)
    return x_mm, y_mm, np.asarray(z_mm) + place.origin_mm[2]


def _side_step(tool: Tool, raster: RasterSpec) -> float:
    """The side step asked for (mm), or the one a ball leaves the scallop height with."""
    if raster.stepover_mm is not None:
        return raster.stepover_mm
    if not tool.is_ball:
        raise ToolpathError("a scallop height (--scallop) needs a ball-end cutter; give --stepover for a flat end")
    return scallop_stepover(tool.radius_mm, raster.scallop_mm)


def cutter_and_reach(surface, ev: SurfaceEvaluator, tool: Tool, raster: RasterSpec, placement: Placement,
                     program: ProgramFormat, *, stock_to_leave_mm: float):
    """The planner's cutter on the program's grid, how far past the box it may go (None: not past) and the reach
    of its positions (surface units): what every finishing strategy starts from."""
    stock = positive(stock_to_leave_mm, "stock to leave", allow_zero=True)
    cl = _Cutter.of(surface, ev, tool, stock, ResolutionGrid.of(placement, program, ev.bounds))
    # Two units of the program's last decimal short of the radius: moved to the grid, a position stays within it.
    past = max(0.0, min(past_reach(ev, cl.radius, cl.corner), cl.radius - 2 * cl.unit)) \
        if raster.boundary == "past" else None
    return cl, past, tool_reach(ev.bounds, cl.radius, raster.boundary, past)


@dataclass(frozen=True)
class _Cutter:
    """Tool-tip heights (mm) over surface positions, as the planner computes them.

    The radius and corner radius (surface units) are those of the tool grown
    by the stock to leave (:meth:`lagsym.cutter.Cutter.grown_mm`), whose tip
    is then lifted by the stock.
    ``snap`` moves positions onto the program's resolution (``grid``): the
    rows, the samples along them and any point added are put there before
    the tool is dropped, so an emitted height is that of a position the
    program writes.
    """

    surface: object
    ev: SurfaceEvaluator
    radius: float
    corner: float
    lift_tip: float
    mm_per_unit: float
    grid: ResolutionGrid | None = None
    workers: Workers | None = None

    @classmethod
    def of(cls, surface, ev: SurfaceEvaluator, tool: Tool, stock: float, grid: ResolutionGrid) -> _Cutter:
        mm_per_unit = grid.mm_per_unit
        r_mm, corner_mm = tool.grown_mm(stock)
        return cls(surface, ev, r_mm / mm_per_unit, corner_mm / mm_per_unit, stock / mm_per_unit, mm_per_unit, grid)

    def __call__(self, x, y, **search) -> np.ndarray:
        z = drop_cutter(self.surface, x, y, self.radius, corner=self.corner, evaluator=self.ev,
                        workers=self.workers, **search)
        return (z + self.lift_tip) * self.mm_per_unit

    @property
    def unit(self) -> float:
        """One unit of the program's last decimal, in surface units (0 without a program grid)."""
        return 0.0 if self.grid is None else self.grid.unit_mm / self.mm_per_unit

    def snap(self, x, y):
        """The positions the program writes for surface positions ``x, y`` (see :mod:`.resolution`)."""
        return (x, y) if self.grid is None else self.grid.snap(x, y)

    def snap_between(self, x, y, ax, ay, bx, by):
        """:meth:`snap` of points added on moves ``a -> b``, off their ends (see :mod:`.resolution`)."""
        return (x, y) if self.grid is None else self.grid.snap_between(x, y, ax, ay, bx, by)

    def snap_axis(self, v, axis: int):
        """:meth:`snap` of positions on one axis (0: x, 1: y)."""
        return v if self.grid is None else self.grid.snap_axis(v, axis)


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


def _fine_path(cl: _Cutter, levels, along, direction: str, fine: float, *, past: float | None,
               progress=None) -> _FinePath:
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
        fx, fy = within_reach(fx, fy, cl.ev.bounds, past)
    # Every position on the program's resolution before the tool is dropped there (one inside the box stays
    # inside): the written X and Y are then the positions whose heights were computed.
    fx, fy = cl.snap(fx, fy)
    # Whole rows and their links, about _ROW_BLOCK samples at a time, each block counted as it is dropped.
    cuts = [lo for lo, _, row in pieces if row][::max(1, _ROW_BLOCK // len(along))] + [len(fx)]
    with Tally(progress, "dropping the tool", len(fx)) as drops:
        fz = []
        for a, b in zip(cuts[:-1], cuts[1:]):
            fz.append(cl(fx[a:b], fy[a:b]))
            drops.add(b - a)
    fz = np.concatenate(fz)
    s_mm = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(fx), np.diff(fy)))]) * cl.mm_per_unit
    return _FinePath(fx, fy, fz, frow, s_mm, tuple(pieces))


def _emitted(path: _FinePath, tol: float, extra: np.ndarray, longest_mm: float | None,
             every: int | None = None) -> np.ndarray:
    """Indices of the fine samples to emit.

    With a chordal tolerance alone, the filter keeps the moves within it.
    With a fixed step (the longest move), every ``every``-th sample of a
    row is kept (:func:`~lagsym.toolpath.pattern.fixed_step_samples`), and along a link the samples
    a move apart (:func:`~lagsym.toolpath.pattern.every_step`); where a move passes more than the
    tolerance below the path (its sag) or above the samples it skips, the
    samples inside it too: points are added where the path bends.  ``extra`` is the sag between samples added to what the samples
    show.
    """
    s_mm, z = path.s_mm, path.z
    if longest_mm is None:
        kept = [0]
        for lo, hi, _ in path.pieces:
            k = filter_rows(s_mm[lo:hi + 1] - s_mm[lo], z[lo:hi + 1], tol, extra[lo:hi + 1]) + lo
            kept.extend(int(v) for v in k[1:])
        return np.array(kept, dtype=int)
    kept = np.unique(np.concatenate([np.arange(lo, hi + 1, every) if is_row else every_step(s_mm, lo, hi, longest_mm)
                                     for lo, hi, is_row in path.pieces]))
    sag, _ = chordal.move_sags(s_mm, z, kept, extra, 0.0)
    off = np.maximum(sag, chordal.move_rises(s_mm, z, kept))  # either side of the path, as the filter's
    split = np.flatnonzero((off > tol) & (np.diff(kept) > 1))
    if not split.size:
        return kept
    inner = np.concatenate([np.arange(kept[m] + 1, kept[m + 1]) for m in split])
    return np.union1d(kept, inner)
