"""Each operation of a job planned as moves: roughing from the block, then the finishing rasters.

A finishing raster (semi-finish, finish, cross-finish) is
:func:`~lagsym.toolpath.plan_toolpath`'s zig-zag; the tool comes down to it
at rapid to just above the block and at the plunge feed from there.  A
cross-finish runs across the finish (rows along y unless its direction is
given).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import freeze_fields
from ..errors import InputError, LagsymError, ToolpathError
from ..export.piecewisejson import read_piecewise_file
from ..exactsize import MAX_EXACT_MB
from ..io import read_points
from ..lagrange import lagrange_surface
from ..machine import MM_PER, MachineSettings, RasterSpec
from ..macro import DEFAULT_PRECISION
from ..macro.roughing import piecewise_macro_refusal, rough_macro
from ..progress import Progress, Tally, prefixed
from ..surfaces.piecewise import PiecewiseSurface
from ..toolpath import plan_toolpath
from ..toolpath.dropcutter import evaluator_of
from ..toolpath.plan import MAX_PLAN_POINTS
from ..toolpath.rest import rest_toolpath
from ..toolpath.restfinish import REST_ABOVE_MM, rest_finish
from ..toolpath.rough import FEED, MAX_ROUGH_SAMPLES, PLUNGE, RAPID, RoughSpec, Stock, rough_toolpath, stock_around
from .rest import Engagement, engagement, stock_left
from .spec import JobSpec, OperationSpec, ToolSpec

__all__ = ["Operation", "plan_job", "job_stock", "job_surface", "PlannedJob"]


@dataclass(frozen=True)
class Operation:
    """One planned operation: what it is, its tool, and its moves (tip positions, machine mm).

    ``kinds`` says how the tool moves into each point (FEED, RAPID or PLUNGE
    of :mod:`lagsym.toolpath.rough`); ``path`` is the planner's own result
    (a :class:`~lagsym.toolpath.rough.RoughPath` or a :class:`~lagsym.toolpath.Toolpath`).
    """

    spec: OperationSpec
    tool: ToolSpec
    points_mm: np.ndarray
    kinds: np.ndarray
    path: object
    engagement: Engagement | None = None  # what a finish with max_engagement takes at most

    def __post_init__(self):
        freeze_fields(self, ("points_mm", "kinds"))

    @property
    def label(self) -> str:
        """``rough T1``, ``rough rest T3`` and so on."""
        return f"{self.spec.kind}{' rest' if self.spec.options.get('rest') else ''} T{self.tool.number}"


@dataclass(frozen=True)
class PlannedJob:
    """A job planned: its spec, the surface, the block and the operations in order."""

    spec: JobSpec
    surface: object
    stock: Stock
    operations: tuple


def job_surface(spec: JobSpec, max_exact_mb: float = MAX_EXACT_MB):
    """The job's exact surface: its fitted measurement's polynomial, the pieces of a ``lagsym piecewise`` file
    (:mod:`lagsym.surfaces.piecewise`), or the polynomial through its points file."""
    if spec.grid is not None:
        return lagrange_surface(spec.grid, max_mb=max_exact_mb)
    pieces = read_piecewise_file(spec.points)
    return pieces if pieces is not None else lagrange_surface(read_points(spec.points), max_mb=max_exact_mb)


def job_stock(spec: JobSpec, surface, evaluator=None) -> Stock:
    """The block the job file describes, in machine mm."""
    ev = evaluator or evaluator_of(surface)
    place = _settings(spec).placement
    st = spec.stock
    box = place.box_mm(ev.bounds)
    if "top" in st:
        top = float(st["top"])
    else:
        b = ev.bounds
        u, v = np.meshgrid(np.linspace(b[0], b[1], 201), np.linspace(b[2], b[3], 201))
        top = float(place.height_mm(ev.fast_points(u.ravel(), v.ravel())).max()) + float(st["top_above"])
    if "block" in st:
        x0, x1, y0, y1 = (float(v) for v in st["block"])
        return Stock(x0, x1, y0, y1, top)
    return stock_around(box, top, float(st.get("margin", 0.0)))


def _settings(spec: JobSpec, op: OperationSpec | None = None, stock_mm: float = 0.0) -> MachineSettings:
    kw = {} if op is None else dict(feed_mm_min=op.feed_mm_min, plunge_feed_mm_min=op.plunge_feed_mm_min,
                                    spindle_rpm=op.spindle_rpm)
    return MachineSettings(dialect=spec.dialect, mm_per_unit=spec.mm_per_unit, origin_mm=spec.origin_mm,
                           units=spec.units, safe_z_mm=spec.safe_z_mm, stock_to_leave_mm=stock_mm,
                           program_number=spec.program_number, work_offset=spec.work_offset, **kw)


def plan_job(spec: JobSpec, max_points: int | None = MAX_PLAN_POINTS,
             max_samples: int | None = MAX_ROUGH_SAMPLES, *, progress: Progress | None = None,
             max_exact_mb: float | None = MAX_EXACT_MB, surface=None) -> PlannedJob:
    """Read the points, build the block and plan every operation in order.

    Each operation is estimated before it is planned: at most ``max_points``
    points, and a roughing level at most ``max_samples`` drop-cutter samples;
    the exact surface at most ``max_exact_mb`` (:mod:`lagsym.exactsize`);
    ``surface``, when given, is the job's surface already made (:func:`job_surface`).
    ``progress`` is told the operations planned (stage ``operations``) and
    each planner's own stages after the operation's label
    (``rough T1: dropping the tool``; :mod:`lagsym.progress`).
    """
    if spec.grid is None and spec.points is None:
        raise InputError(f"{spec.source}: the job's surface is measured: fit the measurement first (--measured)")
    if surface is None:
        surface = job_surface(spec, max_exact_mb)
    ev = evaluator_of(surface)
    stock = job_stock(spec, surface, ev)
    if spec.safe_z_mm <= stock.top_mm:
        inch = float(MM_PER["inch"])
        both = (lambda mm: f"{mm / inch:.4f} in ({mm:g} mm)") if spec.units == "inch" else (lambda mm: f"{mm:g} mm")
        raise InputError(f"{spec.source}: safe_z = {both(spec.safe_z_mm)} is not above the stock top "
                         f"{both(stock.top_mm)}")
    ops = []
    planned = Tally(progress, "operations", len(spec.operations))
    planned.start()
    for i, op in enumerate(spec.operations):
        tool = spec.tools[op.tool]
        try:
            ops.append(_plan(spec, op, tool, surface, ev, stock, limits=(max_points, max_samples), done=tuple(ops),
                             progress=prefixed(progress, f"{op.kind}{' rest' if op.options.get('rest') else ''} "
                                                         f"T{tool.number}")))
        except ToolpathError as e:
            raise InputError(f"{spec.source}: operations[{i}] ({op.kind}): {e}") from None
        planned.add(1)
    planned.finish()
    return PlannedJob(spec, surface, stock, tuple(ops))


def _plan(spec: JobSpec, op: OperationSpec, tool: ToolSpec, surface, ev, stock: Stock, *, limits: tuple,
          done: tuple = (), progress: Progress | None = None) -> Operation:
    o = op.options
    if op.kind == "rough":
        rs = RoughSpec(stepdown_mm=o.get("stepdown", 2.0), stepover_mm=o.get("stepover", tool.tool.diameter_mm / 2),
                       step_mm=o.get("step", 0.5), stock_to_leave_mm=o.get("stock_to_leave", 0.3),
                       direction=o.get("direction", "x"), pattern=o.get("pattern", "raster"),
                       milling=o.get("milling", "climb" if o.get("pattern") == "offset" else "zigzag"),
                       flute_length_mm=tool.flute_length_mm, reach_mm=tool.reach_mm)
        if o.get("macro"):
            if isinstance(surface, PiecewiseSurface):
                raise ToolpathError(piecewise_macro_refusal(surface, "a roughing macro (macro = true)"))
            precision = o.get("precision", DEFAULT_PRECISION[spec.dialect])
            rm = rough_macro(surface, tool.tool, stock, rs, _settings(spec, op), precision=precision, evaluator=ev,
                             max_points=limits[0])
            kinds = np.full(len(rm.points_mm), FEED, dtype=np.int8)
            kinds[0] = PLUNGE
            return Operation(op, tool, rm.points_mm, kinds, rm)
        if o.get("rest"):  # the stock the operations before leave, not the block
            rp = rest_toolpath(surface, tool.tool, stock, stock_left(done, stock), rs, _settings(spec, op),
                               evaluator=ev, max_points=limits[0], max_samples=limits[1], progress=progress)
            return Operation(op, tool, rp.points_mm, rp.kinds, rp)
        rp = rough_toolpath(surface, tool.tool, stock, rs, _settings(spec, op), evaluator=ev, max_points=limits[0],
                            max_samples=limits[1], progress=progress)
        return Operation(op, tool, rp.points_mm, rp.kinds, rp)
    default_dir = "y" if op.kind == "cross-finish" else "x"
    stepover = o.get("stepover", None if "scallop" in o else 0.5)
    step = o.get("step", None if "tolerance" in o else 0.2)
    try:
        raster = RasterSpec(o.get("direction", default_dir), stepover, step, o.get("scallop"), o.get("tolerance"))
    except LagsymError as e:
        raise ToolpathError(str(e)) from None
    s = _settings(spec, op, o.get("stock_to_leave", 0.0))
    left = stock_left(done, stock) if o.get("rest") or "max_engagement" in o else None
    took = None
    if "max_engagement" in o:  # before planning: refused with the figure, or stated in the report and header
        took = engagement(left, ev, s.placement, s.stock_to_leave_mm)
        if took.most_mm > o["max_engagement"]:
            raise ToolpathError(
                f"{tool.name} would take up to {took.stated} mm normal to the surface at X{took.x_mm:.3f} "
                f"Y{took.y_mm:.3f}, more than max_engagement = {o['max_engagement']:g} mm: rough what stands there "
                f"first (an operation with rest = true and a smaller tool before this one) or raise max_engagement")
    tp = plan_toolpath(surface, tool.tool, raster, s.placement, s.program, evaluator=ev, max_points=limits[0],
                       stock_to_leave_mm=s.stock_to_leave_mm, progress=progress)
    _check_reach(tool, stock, tp.points_mm[:, 2].min())
    if o.get("rest"):  # only where the operations before left material above what this ball reaches
        rf = rest_finish(tp, left, stock.top_mm + 2.0, above_mm=o.get("rest_above", REST_ABOVE_MM))
        return Operation(op, tool, rf.points_mm, rf.kinds, rf, took)
    p = tp.points_mm
    above = stock.top_mm + 2.0
    pts = np.vstack([[p[0, 0], p[0, 1], above], p, [p[-1, 0], p[-1, 1], above]])
    kinds = np.concatenate([[RAPID, PLUNGE], np.full(len(p) - 1, FEED), [RAPID]])
    return Operation(op, tool, pts, kinds, tp, took)


def _check_reach(tool: ToolSpec, stock: Stock, lowest_mm: float) -> None:
    depth = stock.top_mm - float(lowest_mm)
    if tool.reach_mm is not None and depth > tool.reach_mm:
        raise ToolpathError(f"tool {tool.name} cannot reach: the cut goes {depth:.3f} mm below the stock top, "
                            f"the tool reaches {tool.reach_mm:g} mm below its holder")
