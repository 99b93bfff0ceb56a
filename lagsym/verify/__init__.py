"""Checking a program by simulating the cut on a height map of the stock.

The box of the control points, in machine millimetres, is covered by a grid
of cells; each cell keeps the lowest height any part of the tool reached over
its centre.  Every straight move of the program lowers every cell centre its
tool passes over to the lowest point the exact lower surface of the tool
(:func:`lagsym.cutter.cutter_profile`: ball, flat or bull nose) reaches
there anywhere along the move, in closed form (:mod:`lagsym.verify.swept`);
feed moves and rapids (``G00``) go into two maps.  The
part is the surface over the box and ends at the box edges (the cells on the
edges are its top edges).  The result is compared with the exact surface at
the same cell centres:

* **gouge**: how far the feed moves cut below the surface (0 for a good program);
* **rapid into the part**: how far a rapid went below the surface, a crash, and on which line;
* **material left**: the most material left above the surface anywhere on the
  part, its edges included (all of it where the tool never passed), and where,
  measured normal to the surface (the height above it times the cosine of its
  slope angle), and the height above it there;
* **scallop**: the cusps between passes, measured normal to the surface, over
  the cells a tool radius or more from the box edges;
* **not reached**: cells no part of the tool passed over.

The simulation never invents a cut: every height it keeps is one the tool
reached at a real position on a move.  For the ball and the flat end it is
the lowest there is over the cell centre (``resolution_mm`` 0: floating-point
rounding apart); for the bull nose, whose lowest point along a move has no
closed form, the tool sweeps at most ``resolution_mm`` lower
(:func:`lagsym.verify.swept.bull_resolution`, below 1e-4 mm).  The figures are
not read off the cell centres alone (:mod:`lagsym.verify.bounds`, docs/verify.md):
material left and the scallop are upper bounds over every triangle of
centres (the swept tool is convex over each move), and the gouge and the
rapid's depth are evaluated exactly at the critical points found from every
centre, so neither is understated whatever the cell.  A gouge reported is
real, and the depth from which a cut counts as a gouge needs no room for the
simulation: by default it is what the program's rounding can cause,
:func:`gouge_limit` (half a unit of the last decimal, and that much sideways
on each axis times the steepest slope of the surface).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._arrays import freeze_fields
from ..errors import InputError
from ..evaluate import surface_evaluator
from ..gcode import Moves, numeric_words, program_blocks, program_units
from ..gcode.words import plain_move
from ..machine import MAX_LEFT_MM, Placement, Tool, mm_per_program_unit
from ..progress import Progress
from ..surfaces.piecewise import PiecewiseSurface
from .bounds import curvature_limits, deepest_cut, left_bound
from .heightmap import MAX_CELLS, MAX_CONTACTS, check_work, height_map_axes, press_moves, sweep, tool_grid
from .swept import lowest_along

__all__ = ["CutReport", "simulate_cut", "press_moves", "height_map_axes", "gouge_limit", "program_resolution_mm",
           "MAX_CELLS", "MAX_CONTACTS", "MAX_LEFT_MM"]


@dataclass(frozen=True)
class CutReport:
    """What a simulated cut left, against the exact surface (all lengths in mm).

    Attributes
    ----------
    xs_mm, ys_mm : ndarray
        Cell centres; ``cut_mm[i, j]`` and ``surface_mm[i, j]`` are at
        ``(xs_mm[i], ys_mm[j])``.  Read-only.
    cut_mm : ndarray
        Lowest height the feed moves' tool reached over each cell (``inf`` where it never passed).
    surface_mm : ndarray
        The exact surface in machine coordinates.
    gouge_mm, gouge_at : float, tuple
        Deepest feed cut below the surface (0 if none) and where.
    rapid_mm, rapid_at, rapid_line : float, tuple, int
        Deepest rapid below the surface (0 if none), where, and the line of that rapid (0 if none).
    left_mm, left_at, left_height_mm : float, tuple, float
        Most material left above the surface anywhere on the part, measured
        normal to it (``inf`` where the tool never passed), where, and its
        height above the surface there.
    scallop_mm, scallop_at : float, tuple
        Highest cusp between passes, normal to the surface, over the cells a
        tool radius or more from the box edges, and where.
    unreached_mm2 : float
        Area of the cells the tool never passed over.
    resolution_mm, gouge_limit_mm : float
        The simulation's vertical resolution and the depth from which a cut counts as a gouge.
    max_left_mm, max_scallop_mm : float
        Material left and scallop above which the program fails (``inf``: not checked).
    segments : int
        Number of straight segments swept (the moves, split at most 8 cells long sideways).
    """

    xs_mm: np.ndarray
    ys_mm: np.ndarray
    cut_mm: np.ndarray
    surface_mm: np.ndarray
    gouge_mm: float
    gouge_at: tuple[float, float]
    rapid_mm: float
    rapid_at: tuple[float, float]
    rapid_line: int
    left_mm: float
    left_at: tuple[float, float]
    left_height_mm: float
    scallop_mm: float
    scallop_at: tuple[float, float]
    unreached_mm2: float
    resolution_mm: float
    gouge_limit_mm: float
    max_left_mm: float
    max_scallop_mm: float
    segments: int

    def __post_init__(self):
        freeze_fields(self, ("xs_mm", "ys_mm", "cut_mm", "surface_mm"), dtype=float)

    @property
    def gouges(self) -> bool:
        """True when the feed moves cut below the surface by more than the limit."""
        return self.gouge_mm > self.gouge_limit_mm

    @property
    def crashes(self) -> bool:
        """True when a rapid goes below the surface by more than the gouge limit."""
        return self.rapid_mm > self.gouge_limit_mm

    @property
    def leaves_material(self) -> bool:
        """True when more than ``max_left_mm`` is left anywhere, or the scallop exceeds ``max_scallop_mm``."""
        return self.left_mm > self.max_left_mm or self.scallop_mm > self.max_scallop_mm

    @property
    def fails(self) -> bool:
        """A gouge, a rapid into the part, or material left beyond the limits."""
        return self.gouges or self.crashes or self.leaves_material

    @property
    def cell_mm(self) -> tuple[float, float]:
        """Cell size in X and Y."""
        return (float(self.xs_mm[1] - self.xs_mm[0]) if len(self.xs_mm) > 1 else 0.0,
                float(self.ys_mm[1] - self.ys_mm[0]) if len(self.ys_mm) > 1 else 0.0)

    @property
    def unreached_fraction(self) -> float:
        """Share of the box the tool never passed over."""
        return float(np.mean(~np.isfinite(self.cut_mm)))

    def summary(self) -> list[str]:
        """The report as lines of text."""
        cx, cy = self.cell_mm

        def at(p):
            return f"X{p[0]:.3f} Y{p[1]:.3f}"

        def limit(v):
            return "not checked" if math.isinf(v) else f"limit {v:.4f} mm"

        left = "all of it (not reached)" if math.isinf(self.left_mm) else f"{self.left_mm:.4f} mm"
        return [
            f"simulated {len(self.xs_mm)} x {len(self.ys_mm)} cells of {cx:.3f} x {cy:.3f} mm, "
            f"{self.segments} segments swept, resolution {self.resolution_mm:.4f} mm"
            + (" (exact)" if self.resolution_mm == 0.0 else ""),
            f"worst gouge       {self.gouge_mm:.4f} mm at {at(self.gouge_at)} "
            f"(limit {self.gouge_limit_mm:.4f} mm): {'GOUGE' if self.gouges else 'none'}",
            f"rapid into part   {self.rapid_mm:.4f} mm at {at(self.rapid_at)}"
            + (f" (line {self.rapid_line})" if self.rapid_line else "")
            + f": {'RAPID CRASH' if self.crashes else 'none'}",
            f"material left     {left} normal to the surface ({self.left_height_mm:.4f} mm above it) at "
            f"{at(self.left_at)}, edges included ({limit(self.max_left_mm)})"
            + (": TOO MUCH" if self.left_mm > self.max_left_mm else ""),
            f"scallop (normal)  {self.scallop_mm:.4f} mm at {at(self.scallop_at)} between passes, a tool radius "
            f"or more from the edges ({limit(self.max_scallop_mm)})"
            + (": TOO HIGH" if self.scallop_mm > self.max_scallop_mm else ""),
            f"area not reached  {self.unreached_mm2:.2f} mm2 ({100 * self.unreached_fraction:.2f} % of the box)",
        ]


def gouge_limit(program_resolution_mm: float, steepest_slope: float) -> float:
    """The deepest below the surface a correct program rounded to its resolution can put the tool (mm).

    Z rounded by up to ``program_resolution_mm``, and X and Y each by as much,
    which on a slope ``steepest_slope`` lowers the tool against the surface by
    up to ``sqrt(2)`` times the resolution times the slope.

    Examples
    --------
    >>> round(gouge_limit(0.0005, 0.0), 6), round(gouge_limit(0.0005, 1.0), 6)
    (0.0005, 0.001207)
    """
    return program_resolution_mm * (1.0 + math.sqrt(2.0) * steepest_slope)


def program_resolution_mm(text: str) -> float:
    r"""Half a unit of the last decimal of the program's X, Y and Z words, in mm (G20: in inches).

    The words and the units are read as every reader of a program reads them
    (:func:`lagsym.gcode.program_blocks`, :func:`lagsym.gcode.program_units`).

    Examples
    --------
    >>> program_resolution_mm("G21\nG01 X1.000 Y2.000 Z-0.125\n")
    0.0005
    >>> round(program_resolution_mm("G20\nG01 X1.0000 Y2.0000\n"), 8)
    0.00127
    """
    digits = 0
    for _, _, block in program_blocks(text):
        plain = plain_move(block)
        values = plain[1:4] if plain is not None else [v for k, v in numeric_words(block, strict=False) if k in "XYZ"]
        for v in values:
            if v and "." in v:
                digits = max(digits, len(v) - v.index(".") - 1)
    unit = mm_per_program_unit(program_units(text) or "mm")
    return 0.5 * 10.0 ** -digits * unit


def simulate_cut(surface, moves: Moves, tool: Tool, placement: Placement = Placement(), *,
                 cell_mm: float | None = None, program_resolution_mm: float = 0.0005,
                 gouge_limit_mm: float | None = None, max_cells: int | None = MAX_CELLS,
                 max_contacts: int | None = MAX_CONTACTS, max_left_mm: float = MAX_LEFT_MM,
                 max_scallop_mm: float | None = None, progress: Progress | None = None) -> CutReport:
    """Simulate the moves with the tool on a height map over the surface's box and compare with the surface.

    Parameters
    ----------
    surface : LagrangeSurface or PiecewiseSurface
        The exact surface: one polynomial, or C1 bicubic pieces
        (:mod:`lagsym.surfaces.piecewise`), each point of the map from the
        piece whose cell holds it and the curvature bounded piece by piece.
    moves : Moves
        The program's moves (:func:`lagsym.gcode.parse_moves`).
    tool : Tool
        The cutter; a diameter of 0 is simulated as a flat end one cell wide.
    placement : Placement
        Where it sits on the machine (``MachineSettings.placement``).
    cell_mm : float, optional
        Cell size; by default the box's longer side over 400.
    program_resolution_mm : float
        How far the program's rounding may put a point from the planned one
        (:func:`program_resolution_mm` of its text).
    gouge_limit_mm : float, optional
        Depth from which a cut counts as a gouge; by default
        :func:`gouge_limit` of the program resolution and the surface's steepest slope.
    max_cells, max_contacts : int or None
        Refuse, before any work, more cells (``--max-cells``) or tool
        segments swept times cells under the tool (``--max-contacts``); None: no limit.
    max_left_mm : float
        Material left anywhere above which the program fails (:data:`MAX_LEFT_MM`; ``inf``: not checked).
    max_scallop_mm : float, optional
        Scallop (normal to the surface) above which the program fails; by default not checked.
    progress : Progress, optional
        Told the segments of the feed moves swept (:mod:`lagsym.progress`).
    """
    xs, ys = height_map_axes(placement.box_mm(surface.grid.bounds), cell_mm, max_cells)
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    sx, sy = placement.to_surface(xs, ys)
    ev = _evaluator(surface)
    surf = placement.height_mm(ev.grid(sx, sy))
    slope = _slopes(ev, sx, sy)
    limit = gouge_limit(program_resolution_mm, float(slope.max())) if gouge_limit_mm is None else float(gouge_limit_mm)
    # Moves before the program's first Z run at the machine's height, which the program does not say: skip them.
    known = np.asarray(moves.z_known, dtype=bool)
    path = moves.path_mm
    use = known & np.concatenate([[False], known[:-1]]) if len(moves) else known
    if not use.any():
        raise InputError("the program has no move with a known Z to simulate (no G00/G01 after the first Z)")
    r, corner, piece, resolution = tool_grid(tool, xs, ys)
    check_work(path[:-1][use], path[1:][use], piece, r, hx, hy, max_contacts=max_contacts)
    rapid = np.asarray(moves.rapid, dtype=bool)
    cut = np.full((len(xs), len(ys)), np.inf)
    feed = np.flatnonzero(use & ~rapid)
    winner = np.full(cut.shape, -1, dtype=np.int64)
    segments, _ = press_moves(cut, xs, ys, path[feed], path[feed + 1], tool, max_contacts=None, progress=progress,
                              winner=winner)
    curvature = curvature_limits(ev, sx, sy, placement.mm_per_unit)
    if isinstance(surface, PiecewiseSurface):
        # The Hessian jumps at the borders, where a cell centre rarely falls: each piece's certified bound too.
        certified = ev.curvature_limits()
        curvature = tuple(max(c, v / placement.mm_per_unit) for c, v in zip(curvature, certified))
    grid = (xs, ys, r, corner)
    gouge, gouge_at, _ = deepest_cut(ev, placement, cut, surf, winner, moves=(path[feed], path[feed + 1]), grid=grid)
    crash, crash_segments = _rapids(ev, placement, surf, path, use & rapid, lines=np.asarray(moves.line), grid=grid)
    left = _left(cut, surf, slope, winner, moves=(path[feed], path[feed + 1]), grid=grid, curvature=curvature,
                 ev=ev, placement=placement)
    return CutReport(xs_mm=xs, ys_mm=ys, cut_mm=cut, surface_mm=surf, gouge_mm=max(gouge, 0.0), gouge_at=gouge_at,
                     **left, rapid_mm=crash[0], rapid_at=crash[1], rapid_line=crash[2],
                     unreached_mm2=float((~np.isfinite(cut)).sum() * hx * hy), resolution_mm=resolution,
                     gouge_limit_mm=limit, max_left_mm=float(max_left_mm),
                     max_scallop_mm=math.inf if max_scallop_mm is None else float(max_scallop_mm),
                     segments=segments + crash_segments)


def _cosine(slope):
    """The cosine of the slope angle of a slope: the share of a height that lies normal to the surface."""
    return 1.0 / np.sqrt(1.0 + slope * slope)


def _left(cut, surf, slope, winner, *, moves, grid, curvature, ev, placement) -> dict:
    """Material left (normal to the surface, and its height) and scallop, bounded from above, and where.

    At the cell centres the cut is compared with the surface; between them
    every triangle of centres gets the bound of :func:`lagsym.verify.bounds.left_bound`.
    """
    xs, ys, r, _ = grid
    reached = np.isfinite(cut)
    above = np.where(reached, np.maximum(cut - surf, 0.0), np.inf)
    left = above * _cosine(slope)
    x0, x1, y0, y1 = xs[0], xs[-1], ys[0], ys[-1]
    inner = (xs[:, None] >= x0 + r) & (xs[:, None] <= x1 - r) & (ys[None, :] >= y0 + r) & (ys[None, :] <= y1 - r)
    normal = np.where(inner & reached, left, 0.0)
    li, si = int(np.argmax(left)), int(np.argmax(normal))

    def at(k):
        i, j = np.unravel_index(k, cut.shape)
        return float(xs[i]), float(ys[j])

    best = dict(left_mm=float(left.flat[li]), left_at=at(li), left_height_mm=float(above.flat[li]),
                scallop_mm=float(normal.flat[si]), scallop_at=at(si))
    m_top, m_abs = curvature

    def surface_at(x_mm, y_mm):
        sx, sy = placement.to_surface(x_mm, y_mm)
        return (placement.height_mm(ev.fast_points(sx, sy)),
                np.hypot(ev.fast_points(sx, sy, dx=1), ev.fast_points(sx, sy, dy=1)))

    norm, height, px, py, ti, tj = left_bound(cut, surf, winner, moves, grid, curvature=(slope, m_top, m_abs),
                                              cosine=_cosine, skip_below=best["scallop_mm"], surface_at=surface_at,
                                              inner=inner)
    if len(norm):
        k = int(np.argmax(norm))
        if norm[k] > best["left_mm"]:
            best.update(left_mm=float(norm[k]), left_at=(float(px[k]), float(py[k])),
                        left_height_mm=float(height[k]))
        square_inner = inner[ti, tj] & inner[ti + 1, tj] & inner[ti, tj + 1] & inner[ti + 1, tj + 1]
        if square_inner.any():
            k = int(np.argmax(np.where(square_inner, norm, -np.inf)))
            if norm[k] > best["scallop_mm"]:
                best.update(scallop_mm=float(norm[k]), scallop_at=(float(px[k]), float(py[k])))
    return best


def _evaluator(surface):
    """The numeric evaluator of the surface: a piecewise surface's own, else the polynomial's."""
    return surface.evaluator if isinstance(surface, PiecewiseSurface) else surface_evaluator(surface)


def _slopes(ev, sx, sy) -> np.ndarray:
    """The surface's slope ``|grad F|`` at every cell centre (the scale cancels)."""
    gx, gy = np.meshgrid(sx, sy, indexing="ij")
    fx, fy = ev.fast_points(gx.ravel(), gy.ravel(), dx=1), ev.fast_points(gx.ravel(), gy.ravel(), dy=1)
    return np.hypot(fx, fy).reshape(gx.shape)


def _rapids(ev, placement, surf, path, use, *, lines, grid):
    """The deepest a rapid goes below the surface, where and on which line; and the segments swept.

    All rapids are pressed into one map; the depth is searched between the
    cell centres as for the feed moves (:func:`lagsym.verify.bounds.deepest_cut`),
    and the line is that of the first rapid that reaches the deepest point.
    """
    xs, ys, r, corner = grid
    none = (0.0, (float(xs[0]), float(ys[0])), 0)
    k = np.flatnonzero(use)
    if not k.size:
        return none, 0
    cut = np.full(surf.shape, np.inf)
    winner = np.full(surf.shape, -1, dtype=np.int64)
    segments = sweep(cut, path[k], path[k + 1], xs, ys, r=r, corner=corner, winner=winner)
    depth, where, move = deepest_cut(ev, placement, cut, surf, winner, moves=(path[k], path[k + 1]), grid=grid)
    if not depth > 0.0:
        return none, segments
    # The first rapid that reaches the deepest point (a retract from it reaches it too).
    low = lowest_along(path[k], path[k + 1], where[0], where[1], r, corner)
    first = int(np.flatnonzero(low <= np.nanmin(low) + 1e-9)[0]) if np.isfinite(low).any() else move
    return (float(depth), where, int(lines[k[first]])), segments
