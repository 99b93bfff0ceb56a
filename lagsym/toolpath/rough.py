"""Z-level roughing from a rectangular block: gouge-free by construction, every level entered from the air.

At each level ``z_k`` (the block's top down by the step-down, the last one no
lower than the lowest cutter location) the tool runs a raster over the block,
its tip at

    max(z_k, CL(x, y) + stock + sag)

where ``CL`` is the exact drop-cutter height of that cutter
(:func:`~lagsym.toolpath.dropcutter.drop_cutter`), ``stock`` the material left
for finishing and ``sag`` the most a straight move between two samples may
dip below a path that bends no more than the surface does (twice the sampled
curvature bound, ``2 kappa h**2 / 8``).  So no move goes below ``CL + stock``,
and after a level the block is cut down to ``z_k`` wherever the tool fits
that low: the material left is at most one step-down above what the cutter
can reach, plus the stock.

Beyond the control points' box there is no part: a tool centred outside it
but within its radius rests on what lies under it inside the box
(:func:`floor_at`).

Every row starts and ends outside the block by the tool radius plus a
clearance, so the tool goes down to each level in the air beside the block
(a flat end that does not cut at its centre is never plunged into solid
stock) and feeds into the material from the side.  Inside a level no
descent into material is steeper than the tool's ramp angle
(:attr:`~lagsym.cutter.Cutter.max_ramp_deg`): the level before bounds the
material under each sample, and steeper descents ramp, their wedges cleared
back and forth (:func:`~lagsym.toolpath.roughmoves.ramped`).  Links that stay outside
the block stay down; a one-way (climb or conventional) raster goes back over
the block above its top, the only way back that is clear of uncut material.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._arrays import freeze_fields
from ..errors import ToolpathError
from ..evaluate import SurfaceEvaluator
from ..machine import DIRECTIONS, MachineSettings, Tool
from ..progress import Progress, Tally
from ..values import choice, finite, positive
from .chordal import check_moves, crosses_box_edge, lift
from .dropcutter import drop_cutter, evaluator_of, telling_compiles
from .pattern import levels as spaced
from .plan import MAX_PLAN_POINTS
from .plansize import check_points
from .roughmoves import FEED, PATTERNS, PLUNGE, RAPID, along_samples, assemble_offset, assemble_raster, offset_line

__all__ = ["PATTERNS", "Stock", "RoughSpec", "RoughPath", "rough_toolpath", "MILLING", "FEED", "RAPID", "PLUNGE", "stock_around",
           "MAX_ROUGH_SAMPLES", "check_rough_request", "check_points", "raster_samples", "rough_levels", "ramp_slope",
           "ramp_note"]

MAX_ROUGH_SAMPLES = 100_000  # drop-cutter samples of one level, each checked exactly (the slow part): minutes at most

MILLING = ("zigzag", "climb", "conventional")
_SPLIT_TOL_MM = 1e-3  # a checked move dipping more than this below the floor is split at its worst point
_PIECE = 1 << 12  # drop-cutter positions between progress reports (the drop's own chunk)


@dataclass(frozen=True)
class Stock:
    """A rectangular block on the machine: ``x0..x1``, ``y0..y1`` and its top ``top_mm``, all machine mm."""

    x0: float
    x1: float
    y0: float
    y1: float
    top_mm: float

    def __post_init__(self):
        for name in ("x0", "x1", "y0", "y1", "top_mm"):
            object.__setattr__(self, name, finite(getattr(self, name), f"stock {name}"))
        if not (self.x0 < self.x1 and self.y0 < self.y1):
            raise ToolpathError(f"stock block x {self.x0:g}..{self.x1:g}, y {self.y0:g}..{self.y1:g} is empty")

    @property
    def box(self) -> tuple[float, float, float, float]:
        """``(x0, x1, y0, y1)``."""
        return (self.x0, self.x1, self.y0, self.y1)


def stock_around(box_mm, top_mm: float, margin_mm: float = 0.0) -> Stock:
    """The block over the box ``(x0, x1, y0, y1)`` (mm) grown by ``margin_mm`` on every side."""
    m = positive(margin_mm, "stock margin", allow_zero=True)
    x0, x1, y0, y1 = box_mm
    return Stock(x0 - m, x1 + m, y0 - m, y1 + m, top_mm)


@dataclass(frozen=True)
class RoughSpec:
    """How to rough: step-down, side step, forward step, stock to leave and the cutting direction (all mm).

    ``milling`` is ``zigzag`` (both directions, the tool stays down),
    ``climb`` or ``conventional`` (one way, for a spindle turning clockwise,
    M03).  ``pattern`` is ``raster`` (rows along ``direction``) or ``offset``
    (concentric rectangles from the block's outline inwards, one way:
    climb or conventional; ``direction`` does not apply).  ``flute_length_mm`` and ``reach_mm`` (length below the holder),
    when given, are checked against the step-down and the depth of the cut.
    """

    stepdown_mm: float = 2.0
    stepover_mm: float = 5.0
    step_mm: float = 0.5
    stock_to_leave_mm: float = 0.3
    direction: str = "x"
    milling: str = "zigzag"
    clearance_mm: float = 2.0
    flute_length_mm: float | None = None
    reach_mm: float | None = None
    pattern: str = "raster"

    def __post_init__(self):
        for name in ("stepdown_mm", "stepover_mm", "step_mm", "clearance_mm"):
            positive(getattr(self, name), name[:-3].replace("_", "-"))
        positive(self.stock_to_leave_mm, "stock to leave", allow_zero=True)
        choice(self.direction, DIRECTIONS, "raster direction")
        choice(self.milling, MILLING, "milling")
        choice(self.pattern, PATTERNS, "clearing pattern")
        if self.pattern == "offset" and self.milling == "zigzag":
            raise ToolpathError("offset clearing cuts every rectangle one way: milling climb or conventional, "
                                "not zigzag")
        for name in ("flute_length_mm", "reach_mm"):
            if getattr(self, name) is not None:
                positive(getattr(self, name), name[:-3].replace("_", " "))
        if self.flute_length_mm is not None and self.stepdown_mm > self.flute_length_mm:
            raise ToolpathError(f"step-down {self.stepdown_mm:g} mm is larger than the flute length "
                                f"{self.flute_length_mm:g} mm")


@dataclass(frozen=True)
class RoughPath:
    """A roughing path: tip positions in machine mm, how the tool moves into each, and the floor under each.

    Attributes
    ----------
    points_mm : ndarray, shape (N, 3)
        Tip positions, work offset included; read-only.
    kinds : ndarray, shape (N,)
        :data:`FEED`, :data:`RAPID` or :data:`PLUNGE` for the move into each point.
    floor_mm : ndarray, shape (N,)
        The drop-cutter height plus the stock to leave at each point
        (``-inf`` where the tool is clear of the part); ``points_mm[:, 2]``
        is never below it.
    levels_mm : ndarray
        The Z levels, from the top down.
    tool : Tool
    stock : Stock
    spec : RoughSpec
    """

    points_mm: np.ndarray
    kinds: np.ndarray
    floor_mm: np.ndarray
    levels_mm: np.ndarray
    tool: Tool
    stock: Stock
    spec: RoughSpec

    def __post_init__(self):
        freeze_fields(self, ("points_mm", "kinds", "floor_mm", "levels_mm"))

    def __len__(self) -> int:
        return len(self.points_mm)


def rough_toolpath(surface, tool: Tool, stock: Stock, spec: RoughSpec, settings: MachineSettings, *,
                   evaluator: SurfaceEvaluator | None = None, max_points: int | None = MAX_PLAN_POINTS,
                   max_samples: int | None = MAX_ROUGH_SAMPLES, progress: Progress | None = None) -> RoughPath:
    """Plan z-level roughing of ``stock`` down to the surface plus the stock to leave.

    Parameters
    ----------
    surface : LagrangeSurface or PiecewiseSurface
        One polynomial, or C1 bicubic pieces (:mod:`lagsym.surfaces.piecewise`):
        drop-cutter rests the tool on every piece within its reach.
    tool : Tool
        Flat, ball (or any shape drop-cutter knows) end mill.
    stock : Stock
        The block, in machine mm; it must cover the control points' box.
    spec : RoughSpec
    settings : MachineSettings
        Scale and work offset (its stock to leave is not used: ``spec`` has the roughing one).
    max_points : int or None
        Refuse a path of more points than this (rows times samples per row,
        times the levels) before it is assembled; None: no limit.
    max_samples : int or None
        Refuse, before any drop-cutter work, more samples than this in one
        level (rows times samples per row: the slow part); None: no limit.
    progress : Progress, optional
        Told the samples dropped, then the rows checked (:mod:`lagsym.progress`).

    Examples
    --------
    >>> from lagsym.grid import grid_from_points
    >>> from lagsym.lagrange import lagrange_surface
    >>> s = lagrange_surface(grid_from_points([(0, 0, 1), (0, 4, 1), (4, 0, 1), (4, 4, 1)]))
    >>> rp = rough_toolpath(s, Tool("flat", 2.0), Stock(0, 4, 0, 4, 4.0), RoughSpec(1.5, 1.5, 1.0, 0.5),
    ...                     MachineSettings())
    >>> [round(float(z), 6) for z in rp.levels_mm]
    [2.5, 1.5]
    >>> bool((rp.points_mm[:, 2] >= rp.floor_mm).all()), round(float(rp.points_mm[:, 2].min()), 6)
    (True, 1.5)
    """
    if spec.pattern == "offset":
        drop, sigma = _dropper(surface, tool, stock, spec, settings, evaluator=evaluator, max_samples=max_samples,
                               progress=progress)
        x, y = offset_line(stock, drop.box, tool.radius_mm, spec)
        floors = floor_at(drop, [x], [y], progress=progress)
        x, y, floor, up = checked_line(drop, x, y, floors[0], sigma)
        floors, lifts = [floor], [up]
    else:
        rows, floors, lifts, sigma = raster_samples(surface, tool, stock, spec, settings, evaluator=evaluator,
                                                    max_samples=max_samples, progress=progress)
    z_levels = rough_levels(floors, sigma, stock, (tool, spec), max_points)
    ramp = dict(radius=tool.radius_mm, tan_a=ramp_slope(tool))
    if spec.pattern == "offset":
        pts, kinds, floor = assemble_offset(x, y, floors[0], lifts[0], z_levels, stock=stock, spec=spec, **ramp)
    else:
        pts, kinds, floor = assemble_raster(rows, floors, lifts, z_levels, stock, spec, **ramp)
    if max_points is not None and len(pts) > max_points:  # the ramps' sweeps back over their wedges add points
        raise ToolpathError(f"the roughing with its ramps at {tool.max_ramp_deg:g} degrees is {len(pts):.3g} "
                            f"points, more than the limit of {max_points:.3g}; use larger steps, a steeper "
                            "--plunge-angle or raise the limit (--max-points)")
    return RoughPath(np.array(pts), np.array(kinds, dtype=np.int8), np.array(floor), z_levels, tool, stock, spec)


def _dropper(surface, tool: Tool, stock: Stock, spec: RoughSpec, settings: MachineSettings, *, evaluator,
             max_samples: int | None, progress):
    """The request checked, the drop-cutter of this cutter (its kernel loaded) and the sag bound ``sigma``."""
    ev = evaluator or evaluator_of(surface)
    place = settings.placement
    box = place.box_mm(ev.bounds)
    check_rough_request(tool, stock, spec, ev, place, max_points=max_samples, option="--max-samples")
    sigma = 2.0 * ev.curvature_bound() / place.mm_per_unit * spec.step_mm ** 2 / 8.0
    drop = _Drop(surface, ev, place, tool, box, spec.stock_to_leave_mm)
    with telling_compiles(progress):  # the kernel loaded (the first time, compiled) before any stage reports
        floor_at(drop, [np.array([box[0]])], [np.array([box[2]])])
    return drop, sigma


def raster_samples(surface, tool: Tool, stock: Stock, spec: RoughSpec, settings: MachineSettings, *,
                   evaluator: SurfaceEvaluator | None = None, max_samples: int | None = MAX_ROUGH_SAMPLES,
                   progress: Progress | None = None):
    """The raster rows (``.cross``, ``.along`` increasing), each sample's floor (``CL + stock``, mm; ``-inf``
    where the tool touches nothing) and lift (keeping the moves between samples above the floor), and ``sigma``."""
    drop, sigma = _dropper(surface, tool, stock, spec, settings, evaluator=evaluator, max_samples=max_samples,
                           progress=progress)
    rows = _rows(stock, drop.box, tool.radius_mm, spec)
    return (*_checked(rows, _floors(drop, rows, spec, progress), drop, spec, sigma, progress), sigma)


def rough_levels(floors, sigma: float, stock: Stock, cut: tuple, max_points: int | None) -> np.ndarray:
    """The z levels (mm): the block's top down by the step-down to the lowest floor plus ``sigma``; a path of
    more than ``max_points`` and a cut deeper than the reach of ``cut = (tool, spec)`` refused."""
    tool, spec = cut
    reachable = np.concatenate(list(floors))
    low = float(reachable[np.isfinite(reachable)].min()) + sigma
    if low >= stock.top_mm:
        raise ToolpathError(f"nothing to rough: the lowest the tool goes, {low:.3f} mm with the stock to leave "
                            f"({spec.stock_to_leave_mm:g} mm), is at or above the stock top {stock.top_mm:g} mm")
    count = max(int(math.ceil((stock.top_mm - low) / spec.stepdown_mm - 1e-9)), 1)
    check_points(stock, tool, spec, count, max_points, "--max-points")
    z_levels = np.maximum(stock.top_mm - spec.stepdown_mm * np.arange(1, count + 1), low)
    depth = stock.top_mm - float(z_levels[-1])
    if spec.reach_mm is not None and depth > spec.reach_mm:
        raise ToolpathError(f"the tool cannot reach: the cut goes {depth:.3f} mm below the stock top, "
                            f"the tool reaches {spec.reach_mm:g} mm below its holder")
    return z_levels


def ramp_slope(tool: Tool) -> float:
    """The steepest descent into material the tool makes, as a rise per mm (``inf`` for a plunge at 90 degrees)."""
    deg = tool.max_ramp_deg
    return math.inf if deg >= 90.0 else math.tan(math.radians(deg))


def ramp_note(tool: Tool) -> str:
    """The header's statement of the steepest descent into material, for a point list and a macro alike."""
    return f"RAMP INTO MATERIAL AT MOST {tool.max_ramp_deg:g} DEG"


def check_rough_request(tool: Tool, stock: Stock, spec: RoughSpec, ev: SurfaceEvaluator, place, *,
                        max_points: int | None, option: str) -> None:
    """What every roughing refuses before any work: the cutter, the side step, the block, one level's size."""
    if tool.diameter_mm <= 0:
        raise ToolpathError("roughing needs a cutter with a diameter above 0")
    if spec.stepover_mm > tool.diameter_mm:
        raise ToolpathError(f"side step {spec.stepover_mm:g} mm is wider than the tool ({tool.diameter_mm:g} mm): "
                            "ridges would stand between the rows")
    _check_stock(stock, place.box_mm(ev.bounds), ev, place)
    check_points(stock, tool, spec, 1, max_points, option)


def _check_stock(stock: Stock, box, ev: SurfaceEvaluator, place) -> None:
    """The block must cover the box and stand above the highest point of the surface."""
    x0, x1, y0, y1 = box
    tol = 1e-9 * max(x1 - x0, y1 - y0)
    if stock.x0 > x0 + tol or stock.x1 < x1 - tol or stock.y0 > y0 + tol or stock.y1 < y1 - tol:
        raise ToolpathError(f"stock block x {stock.x0:g}..{stock.x1:g}, y {stock.y0:g}..{stock.y1:g} mm does not "
                            f"cover the surface's box x {x0:g}..{x1:g}, y {y0:g}..{y1:g} mm")
    b = ev.bounds
    u, v = np.meshgrid(np.linspace(b[0], b[1], 101), np.linspace(b[2], b[3], 101))
    top = float(place.height_mm(ev.fast_points(u.ravel(), v.ravel())).max())
    if stock.top_mm < top:
        raise ToolpathError(f"stock top {stock.top_mm:g} mm is below the surface's highest point {top:.3f} mm")


@dataclass(frozen=True)
class _Row:
    """One raster row: its cross coordinate and its along positions (mm, increasing), outside the block at both ends."""

    cross: float
    along: np.ndarray


def _rows(stock: Stock, box, radius: float, spec: RoughSpec) -> list[_Row]:
    """The rows over the block, each sampled at the forward step plus the box edges and where the tool meets them."""
    along_x = spec.direction == "x"
    c0, c1 = (stock.y0, stock.y1) if along_x else (stock.x0, stock.x1)
    a0, a1 = (stock.x0, stock.x1) if along_x else (stock.y0, stock.y1)
    b_along, b_cross = (box[:2], box[2:]) if along_x else (box[2:], box[:2])
    out = spec.clearance_mm + radius
    return [_Row(float(c), along_samples(a0 - out, a1 + out, float(c), b_along, b_cross, radius=radius,
                                         step=spec.step_mm))
            for c in spaced(c0, c1, spec.stepover_mm)]


@dataclass(frozen=True)
class _Drop:
    """What roughing drops its tool with, the same from the first samples to each row's check.

    The surface, its evaluator and placement, the tool, the surface's box
    on the machine (mm) and the stock to leave (mm).
    """

    surface: object
    ev: SurfaceEvaluator
    place: object
    tool: Tool
    box: tuple
    stock_mm: float

    def line(self, x, y, **search) -> np.ndarray:
        """``CL + stock`` (mm) along one polyline (:func:`floor_at`)."""
        return floor_at(self, [np.asarray(x, float)], [np.asarray(y, float)], **search)[0]


def _floors(drop: _Drop, rows, spec: RoughSpec, progress=None) -> list[np.ndarray]:
    """``CL + stock`` (mm) at every sample of every row, ``-inf`` where the tool does not touch the box."""
    along_x = spec.direction == "x"
    xs, ys = [], []
    for r in rows:
        xs.append(r.along if along_x else np.full(len(r.along), r.cross))
        ys.append(np.full(len(r.along), r.cross) if along_x else r.along)
    return floor_at(drop, xs, ys, progress=progress)


def floor_at(drop: _Drop, xs, ys, progress: Progress | None = None, **search) -> list[np.ndarray]:
    """``CL + stock`` (mm) at tool positions ``xs, ys`` (lists of mm arrays) anywhere on the machine.

    A position outside the box but within the tool radius of it takes the
    exact drop-cutter height there, the tool resting on what lies under it
    inside the box (the height at the nearest point of the box is never
    lower, but leaves material where the surface rises from an edge);
    farther out the tool touches nothing (``-inf``).  ``search`` goes to
    :func:`~lagsym.toolpath.dropcutter.drop_cutter` (``lattice``, ``starts``); ``progress`` is
    told the positions dropped (stage ``dropping the tool``).
    """
    surface, ev, place, tool, box, stock_mm = drop.surface, drop.ev, drop.place, drop.tool, drop.box, drop.stock_mm
    x, y = np.concatenate(xs), np.concatenate(ys)
    px, py = np.clip(x, box[0], box[1]), np.clip(y, box[2], box[3])
    touch = np.hypot(x - px, y - py) <= tool.radius_mm * (1 + 1e-12)
    out = np.full(x.size, -np.inf)
    if touch.any():
        u, v = place.to_surface(x[touch], y[touch])
        radius, corner = tool.radius_mm / place.mm_per_unit, tool.corner_mm / place.mm_per_unit
        z = Tally(progress, "dropping the tool", len(u)).whole(
            lambda pu, pv: drop_cutter(surface, pu, pv, radius, corner=corner, evaluator=ev, **search), (u, v), _PIECE)
        out[touch] = place.height_mm(z) + stock_mm
    return np.split(out, np.cumsum([len(a) for a in xs])[:-1])


def checked_line(drop: _Drop, vx, vy, f, sigma: float):
    """One polyline's samples checked where the tool meets a box edge (see :func:`_checked`).

    Returns the points (the check's own added), their floors and their lifts.
    """
    cl, box, radius = drop.line, drop.box, drop.tool.radius_mm
    live = np.isfinite(f)
    dense = crosses_box_edge(vx, vy, box, radius) & live[:-1] & live[1:]
    vz = np.where(live, f, 0.0) + sigma
    zeros = np.zeros(len(f) - 1)
    nx, ny, nz, _, sag = check_moves(cl, vx, vy, vz, np.zeros(len(f)), zeros, seen=zeros.copy(), dense=dense,
                                     tol=_SPLIT_TOL_MM, radius=radius)
    floor = nz.copy()  # a point the check added has its floor there, without sigma
    k = 0
    for i in range(len(nx)):  # the first points are a subsequence of the checked ones
        if k < len(vx) and nx[i] == vx[k] and ny[i] == vy[k]:
            floor[i] = f[k]
            k += 1
    return nx, ny, floor, sigma + lift(sag)


def _checked(rows, floors, drop: _Drop, spec: RoughSpec, sigma: float, progress=None):
    """Rows whose moves are checked against the true floor where the tool meets a box edge, and each sample's lift.

    Away from the box edges the flat or ball end's height is semi-convex and
    ``sigma`` bounds how far it rises above a move.  Where the disc under
    the tool starts to meet an edge or a corner across the move, the height
    can rise like a square root between two samples; there every move is
    checked against dense drop-cutter samples
    (:func:`~lagsym.toolpath.chordal.check_moves`), split where it dips more
    than :data:`_SPLIT_TOL_MM` below the floor plus ``sigma``, and raised at
    both ends by what is left.  A move with an end where the tool touches
    nothing lies wholly in the air (the samples include where the tool
    starts to touch the box), so it needs no check.  Returns the rows, their
    floors and ``sigma`` plus the lift at every sample.
    """
    along_x = spec.direction == "x"
    out_rows, out_floors, lifts = [], [], []
    checks = Tally(progress, "checking rows", len(rows))
    checks.start()
    for r, f in zip(rows, floors):
        cross = np.full(len(r.along), r.cross)
        vx, vy = (r.along, cross) if along_x else (cross, r.along)
        vx, vy, floor, up = checked_line(drop, vx, vy, f, sigma)
        out_rows.append(_Row(r.cross, vx if along_x else vy))
        out_floors.append(floor)
        lifts.append(up)
        checks.add(1)
    checks.finish()
    return out_rows, out_floors, lifts
