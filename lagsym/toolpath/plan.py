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
from .pattern import levels as _levels
from .pattern import raster_pattern, scallop_stepover

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
        The control points' box on the machine, ``(x0, x1, y0, y1)``: the
        envelope of the tool positions.
    """

    points_mm: np.ndarray
    rows: np.ndarray
    exact_mm: np.ndarray
    tool: Tool
    raster: RasterSpec
    stepover_mm: float
    step_mm: float
    bounds_mm: tuple[float, float, float, float] = field(default=(0.0, 0.0, 0.0, 0.0))

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
    tol = raster.tolerance_mm
    stepover = _side_step(tool, raster)
    step, fine = _forward_steps(raster, ev, mm_per_unit)
    _check_size(ev.bounds, raster.direction, stepover, fine, mm_per_unit, max_points)
    levels, along = raster_pattern(ev.bounds, raster.direction, stepover / mm_per_unit, fine / mm_per_unit)
    if tol is None:
        along = _fixed_step_samples(along, step / mm_per_unit)
    cl = _Cutter.of(surface, ev, tool, settings)
    path = _fine_path(cl, levels, along, raster.direction, fine)
    kappa = ev.curvature_bound() / mm_per_unit
    bend = np.concatenate([chordal.bends(path.z[lo:hi + 1])[:-1] for lo, hi, _ in path.pieces] + [[0.0]])
    kept = _emitted(path, tol, np.maximum(bend, chordal.semi_convex_sag(path.s_mm, kappa)))
    sag, seen = chordal.move_sags(path.s_mm, path.z, kept, bend, kappa)
    vx, vy, vz, vrow = path.x[kept], path.y[kept], path.z[kept], path.row[kept]
    dense = chordal.crosses_box_edge(vx, vy, ev.bounds, cl.radius)
    vx, vy, vz, vrow, sag = chordal.check_moves(cl, vx, vy, vz, vrow, sag, seen, dense, tol, cl.radius)
    b = ev.bounds
    bx, by, _ = _place(settings, np.array(b[:2]), np.array(b[2:]), 0.0)
    return Toolpath(
        points_mm=np.stack(_place(settings, vx, vy, vz + chordal.lift(sag)), axis=1),
        rows=vrow,
        exact_mm=_place(settings, vx, vy, vz)[2],
        tool=tool,
        raster=raster,
        stepover_mm=float((levels[1] - levels[0]) * mm_per_unit) if len(levels) > 1 else float(stepover),
        step_mm=float(step),
        bounds_mm=(float(bx[0]), float(bx[1]), float(by[0]), float(by[1])),
    )


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


def _side_step(tool: Tool, raster: RasterSpec) -> float:
    """The side step asked for (mm), or the one a ball leaves the scallop height with."""
    if raster.stepover_mm is not None:
        return raster.stepover_mm
    if tool.shape != "ball":
        raise ToolpathError("a scallop height (--scallop) needs a ball-end cutter; give --stepover for a flat end")
    return scallop_stepover(tool.radius_mm, raster.scallop_mm)


def _forward_steps(raster: RasterSpec, ev: SurfaceEvaluator, mm_per_unit: float) -> tuple[float, float]:
    """The forward step (mm) and the finer sampling step it is checked at (mm).

    A fixed step is sampled four times finer; a chordal tolerance chooses a
    sampling step whose own chordal error on the surface is a quarter of it.
    """
    tol = raster.tolerance_mm
    if raster.step_mm is None:
        fine = chordal.tolerance_step(ev, tol, mm_per_unit)
        return fine, fine
    step = raster.step_mm
    return step, step / 4.0 if tol is None else min(step, chordal.tolerance_step(ev, tol, mm_per_unit))


_EMIT_EVERY = 2  # with a fixed forward step, a fine sample halfway along each move measures its sag


def _fixed_step_samples(along: np.ndarray, step: float) -> np.ndarray:
    """Positions along a row for a fixed forward step: the emitted points and one sample halfway between each two."""
    n = len(_levels(along[0], along[-1], step)) - 1
    return np.linspace(along[0], along[-1], n * _EMIT_EVERY + 1)


@dataclass(frozen=True)
class _Cutter:
    """Tool-tip heights (mm) over surface positions, as the planner computes them.

    The radius (surface units) includes the stock to leave for a ball or a
    bull nose (whose corner grows by it too), which then rides that much
    higher; a flat end is lifted by the stock instead.
    """

    surface: object
    ev: SurfaceEvaluator
    radius: float
    shape: str
    corner: float | None
    lift_tip: float
    mm_per_unit: float

    @classmethod
    def of(cls, surface, ev: SurfaceEvaluator, tool: Tool, settings: MachineSettings) -> _Cutter:
        r_mm, stock, mm_per_unit = tool.radius_mm, settings.stock_to_leave_mm, settings.mm_per_unit
        if tool.shape == "flat":
            return cls(surface, ev, r_mm / mm_per_unit, "flat", None, stock / mm_per_unit, mm_per_unit)
        # The tool grown by the stock all round touches the part where the tool touches the part grown by it.
        r = (r_mm + stock) / mm_per_unit
        corner = (tool.corner_mm + stock) / mm_per_unit if tool.shape == "bull" else None
        return cls(surface, ev, r, tool.shape, corner, stock / mm_per_unit, mm_per_unit)

    def __call__(self, x, y, **search) -> np.ndarray:
        z = drop_cutter(self.surface, x, y, self.radius, self.shape, corner=self.corner, evaluator=self.ev, **search)
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


def _fine_path(cl: _Cutter, levels, along, direction: str, fine: float) -> _FinePath:
    """Drop the tool over every fine sample of every row and of the links between rows, in cutting order."""
    a_grid, l_grid = np.meshgrid(along, levels, indexing="xy")  # (rows, along)
    z_rows = cl(*((a_grid, l_grid) if direction == "x" else (l_grid, a_grid)))
    gap = (levels[1] - levels[0]) if len(levels) > 1 else 0.0
    link_n = max(2, 2 * int(math.ceil(gap * cl.mm_per_unit / fine / 2)))
    u = np.linspace(0.0, 1.0, link_n + 1)[1:-1]
    ends = np.where(np.arange(len(levels) - 1) % 2 == 0, along[-1], along[0])
    link_a = np.repeat(ends, len(u))
    link_l = (levels[:-1, None] + u[None, :] * gap).ravel()
    z_links = (cl(*((link_a, link_l) if direction == "x" else (link_l, link_a)))
               if len(link_a) else np.zeros(0)).reshape(len(levels) - 1, len(u))
    fa, fl, fz, frow, pieces = [], [], [], [], []
    count = 0
    for i in range(len(levels)):
        fwd = i % 2 == 0
        t = along if fwd else along[::-1]
        piece = [(t, np.full_like(t, levels[i]), z_rows[i] if fwd else z_rows[i][::-1])]
        if i + 1 < len(levels):
            piece.append((np.full_like(u, t[-1]), levels[i] + u * gap, z_links[i]))
        for pa, pl, pz in piece:
            fa.append(pa)
            fl.append(pl)
            fz.append(pz)
            frow.append(np.full(len(pa), i))
        # The row runs over fine indices [count, count + len(t)), the link after it up to the next row's start.
        row_end = count + len(t) - 1
        pieces.append((count, row_end, True))
        if i + 1 < len(levels):
            pieces.append((row_end, row_end + len(u) + 1, False))
        count = row_end + len(u) + 1 if i + 1 < len(levels) else row_end + 1
    fa, fl, fz, frow = (np.concatenate(v) for v in (fa, fl, fz, frow))
    fx, fy = (fa, fl) if direction == "x" else (fl, fa)
    s_mm = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(fx), np.diff(fy)))]) * cl.mm_per_unit
    return _FinePath(fx, fy, fz, frow, s_mm, tuple(pieces))


def _emitted(path: _FinePath, tol: float | None, extra: np.ndarray) -> np.ndarray:
    """Indices of the fine samples to emit: filtered to the tolerance, or every other one of a row for a fixed step.

    A link between rows is one move with a fixed step.  ``extra`` is the
    sag between samples the filter adds to what the samples show.
    """
    kept = [0]
    s_mm, z = path.s_mm, path.z
    for lo, hi, is_row in path.pieces:
        if tol is not None:
            k = filter_rows(s_mm[lo:hi + 1] - s_mm[lo], z[lo:hi + 1], tol, extra[lo:hi + 1]) + lo
        elif is_row:
            k = np.arange(lo, hi + 1, _EMIT_EVERY)
        else:
            k = np.array([lo, hi])
        kept.extend(int(v) for v in k[1:])
    return np.array(kept, dtype=int)
