"""The part a whole job machines from its block: every tool's moves pressed into a height map of the stock.

The block (machine millimetres) is covered by a grid of cells, each at the
block's top to begin with.  The program is split at its tool changes
(``M06``); each part is one stage, run with the cutter its ``T`` number
names, and its moves (feed and rapid alike) are pressed into the height map
as :func:`lagsym.verify.press_moves` does for a single tool.  After each
stage the map says how much material it removed; a rapid that removes
material is a crash, named as such.  At the end the map is compared with the
exact surface inside the box of the control points (beyond it lies no part):

* **gouge**: the deepest cut below the surface;
* **material left**: the highest material above the surface, where, and a
  histogram of the whole box, so a machinist sees what the last tool left.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._arrays import freeze_fields
from .errors import InputError
from .gcode import Moves, first_line_with, is_macro, macro_uses, parse_moves, program_blocks, tool_changes
from .job.operations import job_stock, job_surface
from .machine import Placement, Tool, mm_per_program_unit
from .progress import Progress, Tally
from .toolpath.dropcutter import evaluator_of
from .verify import MAX_CELLS, height_map_axes, press_moves
from .verify.heightmap import segments, tool_grid

__all__ = ["Stage", "MachinedPart", "machine_part", "machine_job", "LEFT_BINS_MM"]

LEFT_BINS_MM = (0.01, 0.05, 0.1, 0.5, 1.0, 2.0, 5.0)
"""Upper edges (mm) of the material-left histogram; the last bin holds everything above 5 mm."""


@dataclass(frozen=True)
class Stage:
    """One tool's part of the program, simulated.

    ``cut_mm`` is the height map after it (read-only); ``removed_mm3`` the
    volume it removed; ``rapid_cut_mm`` the deepest material a rapid move went
    through (0 for a safe program) and where; ``left_mm`` the most material
    left above the surface in the box after it.
    """

    tool_number: int
    tool: Tool
    first_line: int
    moves: int
    removed_mm3: float
    rapid_cut_mm: float
    rapid_cut_at: tuple[float, float]
    left_mm: float
    cut_mm: np.ndarray

    def __post_init__(self):
        freeze_fields(self, ("cut_mm",), dtype=float)


@dataclass(frozen=True)
class MachinedPart:
    """A whole job simulated from the block (lengths in mm, cells over the block).

    ``surface_mm`` is the exact surface at the cell centres inside the box of
    the control points and NaN beyond it; ``left_share[k]`` the share of the
    box's cells with material left up to ``LEFT_BINS_MM[k]`` (the last entry:
    above the last edge).
    """

    xs_mm: np.ndarray
    ys_mm: np.ndarray
    top_mm: float
    surface_mm: np.ndarray
    stages: tuple[Stage, ...]
    gouge_mm: float
    gouge_at: tuple[float, float]
    gouge_limit_mm: float
    left_mm: float
    left_at: tuple[float, float]
    left_share: tuple[float, ...]
    resolution_mm: float

    def __post_init__(self):
        freeze_fields(self, ("xs_mm", "ys_mm", "surface_mm"), dtype=float)

    @property
    def final_mm(self) -> np.ndarray:
        """The height map after the last stage."""
        return self.stages[-1].cut_mm

    @property
    def gouges(self) -> bool:
        """True when the job cuts below the surface by more than the limit."""
        return self.gouge_mm > self.gouge_limit_mm

    @property
    def crashes(self) -> tuple[Stage, ...]:
        """The stages in which a rapid move went through material (deeper than the resolution)."""
        return tuple(s for s in self.stages if s.rapid_cut_mm > self.resolution_mm)

    def summary(self) -> list[str]:
        """The report as lines of text."""
        hx, hy = float(self.xs_mm[1] - self.xs_mm[0]), float(self.ys_mm[1] - self.ys_mm[0])
        out = [f"simulated the block {self.xs_mm[0]:g}..{self.xs_mm[-1]:g} x {self.ys_mm[0]:g}..{self.ys_mm[-1]:g} mm "
               f"from its top Z{self.top_mm:g} in {len(self.xs_mm)} x {len(self.ys_mm)} cells of {hx:.3f} x {hy:.3f} mm"]
        for s in self.stages:
            crash = (f", RAPID INTO MATERIAL {s.rapid_cut_mm:.3f} mm deep at X{s.rapid_cut_at[0]:.3f} "
                     f"Y{s.rapid_cut_at[1]:.3f}" if s.rapid_cut_mm > self.resolution_mm else "")
            out.append(f"T{s.tool_number} {s.tool.label} from line {s.first_line}: {s.moves} moves, removed "
                       f"{s.removed_mm3 / 1000:.1f} cm3, most left {s.left_mm:.3f} mm{crash}")
        out.append(f"worst gouge       {self.gouge_mm:.4f} mm at X{self.gouge_at[0]:.3f} Y{self.gouge_at[1]:.3f} "
                   f"(limit {self.gouge_limit_mm:.4f} mm): {'GOUGE' if self.gouges else 'none'}")
        out.append(f"material left     {self.left_mm:.4f} mm at most, at X{self.left_at[0]:.3f} Y{self.left_at[1]:.3f}")
        edges = ("0",) + tuple(f"{e:g}" for e in LEFT_BINS_MM)
        shares = [f"{lo}-{hi} mm {100 * v:.1f} %" for lo, hi, v in zip(edges, edges[1:], self.left_share)]
        shares.append(f"over {edges[-1]} mm {100 * self.left_share[-1]:.1f} %")
        out.append("left (share of the box): " + ", ".join(shares))
        return out


def machine_part(surface, moves: Moves, changes: list[tuple[int, int]], tools: dict[int, Tool], block,
                 placement: Placement = Placement(), *, cell_mm: float | None = None,
                 program_resolution_mm: float = 0.0005, gouge_limit_mm: float | None = None,
                 max_cells: int | None = MAX_CELLS, progress: Progress | None = None) -> MachinedPart:
    """Simulate a whole job's program from the block ``(x0, x1, y0, y1, top_mm)`` (machine mm).

    Parameters
    ----------
    surface : LagrangeSurface or PiecewiseSurface
        The exact surface; ``placement`` puts it on the machine.
    moves : Moves
        The program's moves (:func:`lagsym.gcode.parse_moves`).
    changes : list of (line, tool number)
        Its tool changes (:func:`lagsym.gcode.tool_changes`); moves before the first are refused.
    tools : dict
        The cutter of each tool number.
    cell_mm : float, optional
        Cell size (default: the longer block side / 400).
    gouge_limit_mm : float, optional
        Depth from which a cut counts as a gouge (default: the program's
        rounding plus the finest stage's resolution).
    progress : Progress, optional
        Told the segments swept, stage ``T1: sweeping moves`` and so on for each tool (:mod:`lagsym.progress`).
    """
    x0, x1, y0, y1, top = (float(v) for v in block)
    xs, ys = height_map_axes((x0, x1, y0, y1), cell_mm, max_cells)
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    surf = _surface_on(surface, placement, xs, ys)
    inside = np.isfinite(surf)
    if not inside.any():
        raise InputError("the box of the control points lies outside the block: nothing to compare")
    cut = np.full((len(xs), len(ys)), top)
    stages, resolutions = [], []
    for number, first, a, b, rapid in _stages(moves, changes):
        if number not in tools:
            raise InputError(f"the program changes to tool T{number} (line {first}), which the job does not name; "
                             f"its tools: {', '.join(f'T{k}' for k in sorted(tools))}")
        before = cut.copy()
        swept = Tally(progress, f"T{number}: sweeping moves",
                      None if progress is None else segments(a, b, tool_grid(tools[number], xs, ys)[2]))
        crash, at, res = _run(cut, xs, ys, a, b, rapid, tool=tools[number], tally=swept)
        resolutions.append(res)
        left = cut - surf
        stages.append(Stage(number, tools[number], first, len(a), float((before - cut).sum() * hx * hy), crash, at,
                            float(np.max(left[inside])), cut.copy()))
    diff = np.where(inside, cut - surf, np.nan)
    gi, li = int(np.nanargmin(diff)), int(np.nanargmax(diff))
    limit = program_resolution_mm + max(resolutions) if gouge_limit_mm is None else float(gouge_limit_mm)
    left = diff[inside]
    counts = np.histogram(np.maximum(left, 0.0), bins=(0.0,) + LEFT_BINS_MM + (math.inf,))[0]
    return MachinedPart(xs, ys, top, surf, tuple(stages), max(0.0, -float(diff.flat[gi])), _at(xs, ys, gi), limit,
                        max(0.0, float(diff.flat[li])), _at(xs, ys, li), tuple(float(c) for c in counts / left.size),
                        max(resolutions))


def machine_job(spec, text: str, source: str = "<program>", **options) -> MachinedPart:
    """Simulate a job's program ``text`` from the block of the job ``spec`` (:func:`lagsym.job.read_job`).

    The surface is read from the job's points file, the block and the
    placement are the job's, each tool number its cutter; ``options`` go to
    :func:`machine_part` (``cell_mm``, ``gouge_limit_mm``, ``max_cells``, ``progress``), which for a
    macro program is told the blocks executed too (:func:`lagsym.simulate.simulate`).
    """
    surface = job_surface(spec)
    stock = job_stock(spec, surface)
    moves = job_moves(spec, text, source, options.get("progress"))
    if is_macro(text, _SIMULATED):
        # the macro statements are blanked (the lines kept): the program's tool changes are plain words
        statements = {no for no, _, block in program_blocks(text) if macro_uses(block)}
        text = "\n".join("" if no in statements else line for no, line in enumerate(text.splitlines(), start=1))
    return machine_part(surface, moves, tool_changes(text, source=source),
                        {t.number: t.tool for t in spec.tools.values()}, stock.box + (stock.top_mm,),
                        Placement(spec.mm_per_unit, spec.origin_mm), **options)


# What the point-list reader cannot run and the simulator can (calls and returns neither runs).
_SIMULATED = ("variable", "expression", "loop", "jump", "condition")


def job_moves(spec, text: str, source: str = "<program>", progress: Progress | None = None) -> Moves:
    """The moves of a job's program: read as a point list or, where it holds macro statements (a roughing macro,
    ``macro = true``), as lagsym's simulator runs it at the precision of the job's macros."""
    if not is_macro(text, _SIMULATED):
        return parse_moves(text, source=source)
    from .macro import DEFAULT_PRECISION
    from .simulate import simulate

    precision = max(op.options.get("precision", DEFAULT_PRECISION[spec.dialect]) for op in spec.operations
                    if op.options.get("macro")) if any(op.options.get("macro") for op in spec.operations) \
        else DEFAULT_PRECISION.get(spec.dialect, 15)
    sim = simulate(text, spec.dialect, precision, progress=progress)
    return sim.moves.to_moves(mm_per_program_unit(spec.units), first_line_with(text, "Z"))


def _surface_on(surface, placement: Placement, xs, ys) -> np.ndarray:
    """The exact surface (machine mm) at the cell centres inside the box, NaN beyond it."""
    bx0, bx1, by0, by1 = placement.box_mm(surface.grid.bounds)
    ix = (xs >= bx0 - 1e-9) & (xs <= bx1 + 1e-9)
    iy = (ys >= by0 - 1e-9) & (ys <= by1 + 1e-9)
    out = np.full((len(xs), len(ys)), np.nan)
    if ix.any() and iy.any():
        sx, sy = placement.to_surface(np.clip(xs[ix], bx0, bx1), np.clip(ys[iy], by0, by1))
        out[np.ix_(ix, iy)] = placement.height_mm(evaluator_of(surface).grid(sx, sy))
    return out


def _stages(moves: Moves, changes):
    """For each tool change: its tool, its line, and the moves up to the next (ends a, b and which are rapids)."""
    if not changes:
        raise InputError("the program has no tool change (T.. M06): a job's program names its tools")
    lines = np.asarray(moves.line)
    path = moves.path_mm
    known = np.asarray(moves.z_known, dtype=bool)
    use = known & np.concatenate([[False], known[:-1]]) if len(moves) else known
    if np.any(lines[use] < changes[0][0]):
        raise InputError(f"the program moves before its first tool change (line {changes[0][0]}): "
                         "which tool would that be?")
    bounds = [c[0] for c in changes] + [math.inf]
    for (first, number), end in zip(changes, bounds[1:]):
        k = use & (lines > first) & (lines < end)
        yield number, first, path[:-1][k], path[1:][k], np.asarray(moves.rapid, dtype=bool)[k]


def _run(cut, xs, ys, a, b, rapid, *, tool: Tool, tally: Tally):
    """Press one stage's moves in order (their segments counted in ``tally``); the deepest material a rapid went
    through, where, and the resolution."""
    tally.start()
    deepest, at, res = 0.0, (float(xs[0]), float(ys[0])), 0.0
    # Runs of feed moves and of rapids, in program order: a rapid's cut is measured against the map before it.
    edges = np.flatnonzero(np.diff(rapid.astype(np.int8))) + 1
    for s, e in zip(np.r_[0, edges], np.r_[edges, len(a)]):
        if e <= s:
            continue
        base = tally.done  # each run's segments swept, counted on from the runs before

        def swept(done, total, stage, base=base):
            tally.add(base + done - tally.done)

        if not rapid[s]:
            res = press_moves(cut, xs, ys, a[s:e], b[s:e], tool, progress=swept if tally.live else None)[1]
            continue
        before = cut.copy()
        res = press_moves(cut, xs, ys, a[s:e], b[s:e], tool, progress=swept if tally.live else None)[1]
        drop = before - cut
        k = int(np.argmax(drop))
        if drop.flat[k] > deepest:
            deepest, at = float(drop.flat[k]), _at(xs, ys, k)
    tally.finish()
    return deepest, at, res


def _at(xs, ys, k):
    i, j = np.unravel_index(k, (len(xs), len(ys)))
    return float(xs[i]), float(ys[j])
