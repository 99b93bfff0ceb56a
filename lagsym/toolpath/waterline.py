"""Waterline (constant-Z) finishing, and steep-and-shallow: waterline on the steep parts, a raster on the rest.

A raster's rows are a fixed distance apart in plan, so on a flank of slope
``θ`` across them the ball's passes lie ``1 / cos θ`` times further apart on
the surface and leave a cusp many times the floor's.  Contours at constant
heights, a height ``Δz`` apart, lie ``Δz / sin θ`` apart on the surface: on a
steep flank they stay close.  :func:`plan_strategy` plans either, or both in
one program:

* **the cutter-location field**: drop-cutter (:mod:`.dropcutter`) on a grid
  :data:`GRID_MM` apart over the tool's reach; its slope is the slope of the
  surface where the ball touches it (the ball's centre rides the offset
  surface, whose normal is the surface's), its curvature across the contours
  ``k_c`` that of the offset, from which the surface's is
  ``k = k_c / (1 + R k_c)``;
* **levels**: walked down from the top of the steep parts; the step below a
  level is the smallest, over the grid nodes between it and the next, of
  ``d(k) sin θ``, where ``d(k)`` is the largest distance between ball centres
  whose cusp, normal to the surface, is at most the request
  (:func:`.scallop.cusp_height`).  Hollows tighter than the ball (where no
  distance meets the request) do not limit the step, as in the scallop
  raster;
* **contours**: at each level, the grid's cells whose cutter locations lie on
  either side of the level (marching squares), each crossing refined by
  false position and bisection on the exact drop-cutter value along its cell
  edge to a bracket :data:`BISECTIONS` halvings wide, the low end kept (the tool there is at or above
  the exact drop-cutter height); crossings chained into closed loops and open
  pieces (where a contour leaves the steep parts or the reach);
* **moves**: each contour thinned to the points whose chords stay within the
  chordal tolerance of it in plan (Douglas-Peucker), each chord then checked
  by drop-cutter at points a quarter of the grid apart (:data:`EDGE_DENSER`
  times closer across a box edge the tool comes near with the move beyond the
  box), and both its ends
  lifted by the most the cutter path rises above it there plus
  ``κ h² / 8`` (the sag a path bending no faster than the surface's
  curvature bound ``κ`` can hide between samples ``h`` apart), so no move
  cuts below the exact cutter path;
* **direction**: climb (spindle ``M03``): material, uphill, on the right; conventional on the left;
* **links**: from the end of one pass to the start of the next, a straight
  move where the next is within :data:`NEAR_RADII` tool radii and the straight
  move stays above the cutter path; else up to :data:`LINK_CLEARANCE_MM` above
  the highest cutter location under the link, across and down.

**Steep and shallow** splits the box at a threshold slope ``θ_t``: a raster
over the nodes whose slope is at most ``θ_t`` plus :data:`BAND_DEG` (and
wherever the tool axis is beyond the box), waterline where it is at least
``θ_t`` less the band, so the two overlap by a band of slopes and leave no
seam.  The raster's rows are walked as the scallop raster's (the gap after a row the smallest allowed over its
shallow nodes), cut where they cross the steep parts.  ``θ_t`` is chosen from the
requested cusp: the slope, between 10 and 80 degrees, that gives the shortest
estimated path, the raster's length over its region at the rows' spacing ``d(0) cos(θ_t + band)`` plus the
contours' at the level step ``d(0) sin(θ_t - band)``.  The waterline strategy alone plans the contours of
the same steep region (the shallow parts are another program's); the program
header states the threshold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ToolpathError
from ..evaluate import SurfaceEvaluator, surface_evaluator
from ..machine import Placement, ProgramFormat, RasterSpec, Tool
from ..progress import Progress, Tally
from ..surfaces.piecewise import PiecewiseSurface
from ..values import choice
from . import chordal
from .filter import filter_rows
from .pattern import within_reach
from .dropcutter import telling_compiles
from .plan import MAX_PLAN_POINTS, Toolpath, _Cutter, _place, cutter_and_reach, plan_toolpath
from .contours import BISECTIONS, contour_passes
from .plansize import check_strategy_work, nearest_nodes, row_samples
from .movesamples import EDGE_DENSER, move_samples
from .scallop import _TIGHT, _allowed_d
from .workers import MIN_POINTS, Workers

__all__ = ["STRATEGIES", "plan_strategy", "BAND_DEG", "GRID_MM", "LINK_CLEARANCE_MM", "NEAR_RADII", "BISECTIONS",
           "EDGE_DENSER"]

STRATEGIES = ("raster", "waterline", "steep-shallow")
"""The finishing strategies: the zig-zag raster, contours at constant heights, or both split by slope."""

BAND_DEG = 5.0
"""Half the band of slopes both the raster and the contours of steep-and-shallow cover."""

GRID_MM = 0.25
"""Spacing of the grid of cutter locations the contours are found on (mm)."""

LINK_CLEARANCE_MM = 1.0
"""How far above the highest cutter location under it a link between distant passes runs."""

NEAR_RADII = 4.0
"""A next pass within this many tool radii is joined by a straight move where one stays above the cutter path."""
_FAR_LINK_STEPS = 4  # how many times further apart than a move's the samples of a link over the part lie

_DIRECTIONS = ("climb", "conventional")


@dataclass(frozen=True)
class _Field:
    """The cutter-location grid and what the passes are chosen from (all arrays ``(nx, ny)``)."""

    xs: np.ndarray  # surface units
    ys: np.ndarray
    z: np.ndarray  # tip heights, mm
    slope_deg: np.ndarray
    inside: np.ndarray  # the tool axis over the box
    tight: np.ndarray  # a hollow where no step meets the cusp
    dz: np.ndarray  # the largest level step at each node, mm
    across: np.ndarray  # the largest raster gap in plan at each node, mm
    cross_deg: np.ndarray  # the slope across a raster's rows: arccos(sqrt(1 + fp**2) / sqrt(1 + |grad|**2))


def _check_request(surface, tool: Tool, raster: RasterSpec, strategy: str) -> None:
    """Refuse what the waterline and steep-and-shallow strategies cannot plan, naming the way out."""
    if isinstance(surface, PiecewiseSurface):
        raise ToolpathError(f"the {strategy} strategy takes one polynomial: finish a piecewise surface by raster")
    if not tool.is_ball or tool.radius_mm <= 0:
        raise ToolpathError(f"the {strategy} strategy spaces its passes from a ball's cusp: it needs a ball-end "
                            f"cutter with a diameter (--tool-shape ball), not {tool.label}")
    if raster.arcs:
        raise ToolpathError(f"arcs (--arcs) are fitted along a raster's rows, not in the {strategy} strategy")
    if raster.scallop_mm is None:
        raise ToolpathError(f"the {strategy} strategy spaces its passes from a cusp height: give --scallop "
                            f"instead of --stepover {raster.stepover_mm:g}")


def plan_strategy(surface, tool: Tool, raster: RasterSpec, placement: Placement = Placement(),
                  program: ProgramFormat = ProgramFormat(), *, strategy: str = "raster", milling: str = "climb",
                  evaluator: SurfaceEvaluator | None = None, max_points: int | None = MAX_PLAN_POINTS,
                  stock_to_leave_mm: float = 0.0, progress: Progress | None = None) -> Toolpath:
    """Plan a finishing pass: ``"raster"`` (:func:`.plan.plan_toolpath`), ``"waterline"`` or ``"steep-shallow"``.

    Parameters
    ----------
    surface, tool, raster, placement, program, evaluator, max_points, stock_to_leave_mm, progress
        As :func:`.plan.plan_toolpath`; waterline and steep-and-shallow need one polynomial (not a piecewise
        surface), a ball end and ``raster.scallop_mm`` (the cusp normal to the surface their passes keep).
    strategy : {"raster", "waterline", "steep-shallow"}
    milling : {"climb", "conventional"}
        The contours' direction with the spindle turning clockwise.
    """
    choice(strategy, STRATEGIES, "strategy"), choice(milling, _DIRECTIONS, "milling direction")
    if strategy == "raster":
        return plan_toolpath(surface, tool, raster, placement, program, evaluator=evaluator, max_points=max_points,
                             stock_to_leave_mm=stock_to_leave_mm, progress=progress)
    _check_request(surface, tool, raster, strategy)
    ev = evaluator or surface_evaluator(surface)
    mpu = placement.mm_per_unit
    tol = raster.chordal_tolerance_mm
    chordal.check_tolerance(tol, program)
    cl, past, reach = cutter_and_reach(surface, ev, tool, raster, placement, program,
                                       stock_to_leave_mm=stock_to_leave_mm)
    nx, ny = (math.ceil((reach[k + 1] - reach[k]) * mpu / GRID_MM) + 1 for k in (0, 2))
    if max_points is not None and nx * ny > max_points:
        raise ToolpathError(f"a grid of {nx} x {ny} cutter locations ({nx * ny:.3g}) is more than the limit of "
                            f"{max_points:.3g}; raise the limit (--max-points)")
    radius_mm = cl.radius * mpu
    d0 = float(_allowed_d(0.0, radius_mm, raster.scallop_mm))
    kappa = ev.curvature_bound() / mpu
    with telling_compiles(progress):  # the compiled kernel loaded before the workers fork
        cl(np.array([ev.bounds[0]]), np.array([ev.bounds[2]]))
    with Workers(ev, None if nx * ny >= MIN_POINTS else 1) as workers:
        drop = _Drop(replace(cl, workers=workers), past)
        with Tally(progress, "dropping the tool on the grid", nx * ny) as t:
            f = _field(drop, reach, nx, ny, radius_mm, raster.scallop_mm, direction=raster.direction, mpu=mpu)
            t.add(nx * ny)
        # Steep and shallow split by the slope across the rows: a flank the rows run up and down leaves the
        # raster's cusp as on the flat.
        slope = f.cross_deg if strategy == "steep-shallow" else f.slope_deg
        theta = _threshold(f, slope, d0, mpu)
        steep = ~f.tight & (slope >= theta - BAND_DEG)
        shallow = (slope <= theta + BAND_DEG) | ~f.inside if strategy == "steep-shallow" else None
        check_strategy_work(f, steep, shallow, d0, raster, ev=drop.cl.ev, max_points=max_points, strategy=strategy,
                            mpu=mpu)
        passes = []
        if shallow is not None:
            with Tally(progress, "raster rows") as t:
                passes += _raster_passes(drop, f, shallow, raster.direction, d0, tol, kappa=kappa, mpu=mpu, counter=t)
        with Tally(progress, "contours") as t:
            contours, dzs = contour_passes(drop, f, steep, d0, tol, kappa, mpu=mpu, milling=milling, counter=t)
        passes += contours
        passes = _lifted(drop, passes, kappa, mpu)
        if not passes:
            raise ToolpathError(f"no pass to plan: the surface has no part steeper than {theta - BAND_DEG:.1f} "
                                f"degrees for the {strategy} strategy")
        pts, rows = _linked(drop, passes, radius_mm, kappa, mpu)
        sx, sy = cl.snap(pts[:, 0], pts[:, 1])
        exact = drop(sx, sy, snap=False)
    z = np.maximum(pts[:, 2], exact)
    x_mm, y_mm, z_mm = _place(placement, sx, sy, z)
    bx, by, _ = _place(placement, np.array(ev.bounds[:2]), np.array(ev.bounds[2:]), 0.0)
    keep = np.concatenate([[True], np.any(np.diff(np.stack([x_mm, y_mm, z_mm], axis=1), axis=0) != 0, axis=1)])
    return Toolpath(points_mm=np.stack([x_mm, y_mm, z_mm], axis=1)[keep], rows=rows[keep],
                    exact_mm=_place(placement, sx, sy, exact)[2][keep], tool=tool, raster=raster,
                    stepover_mm=float(max(dzs)) if dzs else 0.0, step_mm=GRID_MM,
                    bounds_mm=(float(bx[0]), float(bx[1]), float(by[0]), float(by[1])), fine_points=nx * ny,
                    cusp_mm=float(raster.scallop_mm), hollow_share=float(f.tight.mean()),
                    note=_note(strategy, theta, len(dzs), milling),
                    threshold_deg=float(theta), levels=len(dzs))


def _note(strategy: str, theta: float, levels: int, milling: str) -> str:
    """The header's lines (between ``"; "``), short: some controls cut a comment short."""
    if strategy == "waterline":
        return f"WATERLINE ON SLOPES OVER {theta - BAND_DEG:.0f} DEG; {levels} LEVELS {milling.upper()}"
    return (f"STEEP-SHALLOW THRESHOLD {theta:.0f} DEG; WATERLINE OVER {theta - BAND_DEG:.0f} DEG ACROSS ROWS; "
            f"RASTER UNDER {theta + BAND_DEG:.0f} DEG ACROSS ROWS; {levels} LEVELS {milling.upper()}")


@dataclass(frozen=True)
class _Drop:
    """Tip heights (mm) at surface positions, brought within the reach past the box first."""

    cl: _Cutter
    past: float | None

    def __call__(self, x, y, snap: bool = False) -> np.ndarray:
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        if self.past is not None:
            x, y = within_reach(x, y, self.cl.ev.bounds, self.past)
        if snap:
            x, y = self.cl.snap(x, y)
        if x.size == 0:
            return np.zeros(x.shape)
        return self.cl(x, y)

    def along(self, a: np.ndarray, b: np.ndarray, spacing: float) -> np.ndarray:
        """The most each straight move ``a[k] -> b[k]`` (x, y surface units, z mm) lies below the cutter path.

        :meth:`samples` along each move, each taken with a quarter of its
        downward second difference (:func:`.chordal.bends`: what the path
        may bend below the points between them); 0 or less where the move
        stays above.
        """
        k, _, pz, z, bend = self.samples(a, b, spacing)
        out = np.full(len(a), -np.inf)
        np.maximum.at(out, k, z - pz + bend)
        return out

    def samples(self, a: np.ndarray, b: np.ndarray, spacing: float):
        """Cutter locations along each straight move ``a[k] -> b[k]``: ``(move, t, z on the move, tip height, bend)``
        (:func:`.movesamples.move_samples`)."""
        return move_samples(self, a, b, spacing, self.cl.ev.bounds, self.cl.radius)


def _field(drop: _Drop, reach, nx: int, ny: int, radius_mm: float, scallop_mm: float, *, direction: str,
           mpu: float) -> _Field:
    """The grid of cutter locations over the reach, its slopes and the steps allowed at each node."""
    xs, ys = np.linspace(reach[0], reach[1], nx), np.linspace(reach[2], reach[3], ny)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    z = drop(gx.ravel(), gy.ravel()).reshape(nx, ny)
    hx, hy = (xs[1] - xs[0]) * mpu, (ys[1] - ys[0]) * mpu
    zx, zy = np.gradient(z, hx, hy)
    zxx, zxy = np.gradient(zx, hx, hy)
    _, zyy = np.gradient(zy, hx, hy)
    g2 = zx * zx + zy * zy
    g = np.sqrt(g2)
    with np.errstate(invalid="ignore", divide="ignore"):
        ux, uy = np.where(g > 0, zx / g, 1.0), np.where(g > 0, zy / g, 0.0)
        k_down = (ux * ux * zxx + 2 * ux * uy * zxy + uy * uy * zyy) / (1 + g2) ** 1.5
        # Across a raster's rows: the horizontal direction across them, its normal curvature.
        cx, cy = (0.0, 1.0) if direction == "x" else (1.0, 0.0)
        fc = cx * zx + cy * zy
        fp = cy * zx + cx * zy
        k_across = (cx * cx * zxx + 2 * cx * cy * zxy + cy * cy * zyy) / (np.sqrt(1 + g2) * (1 + fc * fc))
    d_down = _allowed_d(_surface_k(k_down, radius_mm), radius_mm, scallop_mm)
    d_across = _allowed_d(_surface_k(k_across, radius_mm), radius_mm, scallop_mm)
    d0 = float(_allowed_d(0.0, radius_mm, scallop_mm))
    tight = ~np.isfinite(d_down) | (d_down < _TIGHT * d0) | ~np.isfinite(d_across) | (d_across < _TIGHT * d0)
    x0, x1, y0, y1 = drop.cl.ev.bounds
    inside = (gx >= x0) & (gx <= x1) & (gy >= y0) & (gy <= y1)
    sin = np.sqrt(g2 / (1 + g2))
    dz = np.where(tight, np.inf, d_down * sin)
    across = np.where(tight, np.inf, d_across * np.sqrt(1 + fp * fp) / np.sqrt(1 + g2))
    cross = np.degrees(np.arccos(np.clip(np.sqrt((1 + fp * fp) / (1 + g2)), 0.0, 1.0)))
    return _Field(xs, ys, z, np.degrees(np.arctan(g)), inside, tight, dz, across, cross)


def _surface_k(k_offset, radius_mm: float):
    """The surface's normal curvature under a ball whose offset surface has curvature ``k_offset`` (nan: a crease)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        den = 1 + radius_mm * k_offset
        return np.where(np.isfinite(k_offset) & (den > 0), k_offset / den, np.nan)


def _threshold(f: _Field, slope: np.ndarray, d0: float, mpu: float) -> float:
    """The threshold of ``slope`` (degrees) whose raster and contours are estimated shortest together."""
    cell = float((f.xs[1] - f.xs[0]) * (f.ys[1] - f.ys[0])) * mpu * mpu
    tan = np.tan(np.radians(np.minimum(f.slope_deg, 89.0)))
    ok = ~f.tight
    best, best_len = 45.0, math.inf
    for theta in np.arange(10.0, 80.5, 1.0):
        shallow = ((slope <= theta + BAND_DEG) | ~f.inside) & ok
        steep = (slope >= theta - BAND_DEG) & f.inside & ok
        gap = d0 * math.cos(math.radians(theta + BAND_DEG))
        step = d0 * math.sin(math.radians(theta - BAND_DEG))
        length = shallow.sum() * cell / gap + float(tan[steep].sum()) * cell / step
        if length < best_len:
            best, best_len = float(theta), length
    return best


def _lifted(drop: _Drop, passes, kappa: float, mpu: float):
    """The passes on the program's resolution, each move's ends raised by the most the cutter path rises above it."""
    if not passes:
        return []
    spacing = 0.25 * GRID_MM / mpu
    pts = np.vstack([p for p, _, _ in passes])
    # On the program's resolution first: the moves checked are the moves written.
    pts[:, 0], pts[:, 1] = drop.cl.snap(pts[:, 0], pts[:, 1])
    pts[:, 2] = np.maximum(pts[:, 2], drop(pts[:, 0], pts[:, 1]))
    ends = np.cumsum([len(p) for p, _, _ in passes])
    starts = ends - np.array([len(p) for p, _, _ in passes])
    moves = np.ones(len(pts) - 1, dtype=bool)
    moves[ends[:-1] - 1] = False  # no move from one pass to the next
    rise = np.zeros(len(pts) - 1)
    k = np.flatnonzero(moves)
    rise[k] = np.maximum(drop.along(pts[k], pts[k + 1], spacing) + kappa * (spacing * mpu) ** 2 / 8, 0.0)
    out = []
    for (_, closed, group), a, b in zip(passes, starts, ends):
        q = pts[a:b].copy()
        q[:, 2] += chordal.lift(rise[a:b - 1])
        out.append((q, closed, group))
    return out


def _raster_passes(drop: _Drop, f: _Field, shallow: np.ndarray, direction: str, d0: float, tol: float, *,
                   kappa: float, mpu: float, counter=None):
    """Raster rows over the shallow region, walked across like the scallop raster's, cut where they leave it."""
    xs, ys = f.xs, f.ys
    a_axis, c_axis = (xs, ys) if direction == "x" else (ys, xs)
    across = f.across if direction == "x" else f.across.T
    region = shallow if direction == "x" else shallow.T
    # Beyond the box the tool rolls off its edge: steep there, but no surface to leave a cusp on.
    ok = region & np.isfinite(across) & (f.inside if direction == "x" else f.inside.T)
    c0, c1 = c_axis[0], c_axis[-1]
    rows, c = [], c0
    while True:
        rows.append(c)
        if c >= c1:
            break
        step = d0
        for _ in range(64):
            band = (c_axis >= c) & (c_axis <= c + step / mpu)
            new = float(np.min(across[:, band][ok[:, band]], initial=np.inf))
            if new >= step:
                break
            step = new
        c = min(c + step / mpu, c1)
    along = row_samples(a_axis, chordal.tolerance_step(drop.cl.ev, tol, mpu) / mpu)
    ia = nearest_nodes(a_axis, along.size)
    pieces = []
    for r, c in enumerate(rows):
        ic = int(np.clip(np.rint((c - c_axis[0]) / (c_axis[1] - c_axis[0])), 0, len(c_axis) - 1))
        inside = region[ia, ic]
        t = along if r % 2 == 0 else along[::-1]
        inside = inside if r % 2 == 0 else inside[::-1]
        edges = np.flatnonzero(np.diff(np.concatenate([[0], inside.astype(int), [0]])))
        for lo, hi in zip(edges[::2], edges[1::2]):
            if hi - lo >= 2:
                pieces.append((t[lo:hi], c))
    if not pieces:
        return []
    sizes = [len(t) for t, _ in pieces]
    pa = np.concatenate([t for t, _ in pieces])
    pc = np.concatenate([np.full(len(t), c) for t, c in pieces])
    px, py = (pa, pc) if direction == "x" else (pc, pa)
    pz = drop(px, py)
    if counter is not None:
        counter.add(len(pz))
    out, start = [], 0
    for n in sizes:
        x, y, z = px[start:start + n], py[start:start + n], pz[start:start + n]
        start += n
        s_mm = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y)))]) * mpu
        extra = np.maximum(chordal.bends(z), chordal.semi_convex_sag(s_mm, kappa))
        kept = filter_rows(s_mm, z, tol, extra)
        sag, _ = chordal.move_sags(s_mm, z, kept, extra, kappa)
        zk = z[kept] + chordal.lift(sag)
        out.append((np.stack([x[kept], y[kept], zk], axis=1), False, ("raster", len(out))))
    return out


def _linked(drop: _Drop, passes, radius_mm: float, kappa: float, mpu: float):
    """The passes joined in order: points and the pass of each.

    ``passes`` is ``(points, closed, group)``; the groups are taken in order
    (each raster piece its own, the contours of a level one), and within a
    group the pass nearest the current position next, a closed one started
    at its point nearest to it.
    """
    spacing = 0.25 * GRID_MM / mpu
    ordered = []
    cur = None
    groups: dict = {}
    for pts, closed, group in passes:
        groups.setdefault(group, []).append((pts, closed))
    for members in groups.values():
        while members:
            k = 0 if cur is None else min(range(len(members)), key=lambda m: float(np.min(np.hypot(
                *(members[m][0][:-1 if members[m][1] else 1, :2] - cur[:2]).T))))
            pts, closed = members.pop(k)
            if cur is not None and closed:
                i = int(np.argmin(np.hypot(*(pts[:-1, :2] - cur[:2]).T)))
                pts = np.vstack([pts[i:-1], pts[:i + 1]])
            ordered.append(pts)
            cur = pts[-1]
    p = np.array([q[-1] for q in ordered[:-1]]).reshape(-1, 3)
    q = np.array([q[0] for q in ordered[1:]]).reshape(-1, 3)
    links = _links(drop, p, q, radius_mm, spacing, kappa, mpu=mpu)
    out, rows = [ordered[0]], [np.zeros(len(ordered[0]), dtype=int)]
    for k, pts in enumerate(ordered[1:], start=1):
        out += [links[k - 1], pts]
        rows += [np.full(len(links[k - 1]), k - 1), np.full(len(pts), k)]
    return np.vstack(out), np.concatenate(rows)


def _links(drop: _Drop, p: np.ndarray, q: np.ndarray, radius_mm: float, spacing: float, kappa: float, *, mpu: float):
    """The points between the end ``p[k]`` of each pass and the start ``q[k]`` of the next (both left out).

    None where the next pass is near and the straight move to it stays above
    the cutter path; else up to :data:`LINK_CLEARANCE_MM` above the highest
    cutter location under the link, across and down.
    """
    if not len(p):
        return []
    near = np.hypot(q[:, 0] - p[:, 0], q[:, 1] - p[:, 1]) * mpu <= NEAR_RADII * radius_mm
    below, top = np.full(len(p), np.inf), np.maximum(p[:, 2], q[:, 2])
    # The samples under a link give how far the straight move lies below the cutter path and the highest cutter
    # location under it; a link to a pass not near rises 1 mm above that, so needs no finer search than 0.25 mm.
    for pick, step in ((near, spacing), (~near, _FAR_LINK_STEPS * spacing)):
        idx = np.flatnonzero(pick)
        if not len(idx):
            continue
        margin = kappa * (step * mpu) ** 2 / 8
        k, _, pz, z, bend = drop.samples(p[idx], q[idx], step)
        low, high = np.full(len(idx), -np.inf), np.full(len(idx), -np.inf)
        np.maximum.at(low, k, z - pz + bend)
        np.maximum.at(high, k, z + bend)
        below[idx] = low + margin
        top[idx] = np.maximum(top[idx], high + margin)
    clear = near & (below <= 0)
    h = top + LINK_CLEARANCE_MM
    return [np.empty((0, 3)) if c else np.array([[a[0], a[1], z], [b[0], b[1], z]])
            for c, a, b, z in zip(clear, p, q, h)]
