"""Cutter locations: the tool dropped onto the exact surface until it touches it anywhere under it.

For a ball of radius ``R`` centred over ``c = (cx, cy)`` the tip height is

    CL(c) = max over p in D(c, R) ∩ B of  F(p) + sqrt(R**2 - |p - c|**2) - R,

for a flat end ``max F(p)`` over the same set, and for a bull-nose end mill of
corner radius ``r`` the same maximum of ``F(p) - P(|p - c|)``, ``P`` its profile
(0 across the flat, ``r - sqrt(r**2 - (d - R + r)**2)`` on the corner; the ball
and the flat end are its limits ``r = R`` and ``r = 0``,
:func:`lagsym.cutter.cutter_profile`); ``D`` is the disc under the
tool and ``B`` the box spanned by the control points.  Only the surface inside
the box counts: the polynomial is never evaluated outside it (beyond the box
lies no part, not a cliff and not an extrapolated surface), so near an edge the
tool rests on what lies inside.  The maximum is found by a dense lattice of
candidate contact points in the disc, then a pattern search from the best few
candidates that shrinks to ``1e-9`` of the tool radius (where the maximum lies on
the rim or on a box edge the height converges only as fast as the step).  Every value found is
the height of a real contact, so it can only err low; :data:`CL_MARGIN` (a
relative ``1e-7``, far below any program's resolution) is added to absorb
that error.  No normal offset is
involved, so concave regions tighter than the tool are handled: the tool rests
on the two walls instead of cutting into them.

The search runs in drop-cutter's compiled kernel (:mod:`.kernel`), a tool
position at a time, with the float64 arithmetic of
:meth:`lagsym.evaluate.SurfaceEvaluator.fast_points`; this module checks the
input, lays out the lattice and shares the positions out in chunks.
"""

from __future__ import annotations

import contextlib
import functools
import math
import weakref
from typing import NamedTuple

import numpy as np
from numpy.polynomial import chebyshev as C

from ..cutter import corner_radius
from ..errors import ToolpathError
from ..evaluate import SurfaceEvaluator, surface_evaluator
from ..progress import COMPILING, Progress
from ..surfaces.piecewise import PiecewiseEvaluator, PiecewiseSurface
from ..values import positive
from .newton import jet_coefficients, kernel_geometry
from .workers import Workers

__all__ = ["CL_MARGIN", "drop_cutter", "evaluator_of", "telling_compiles"]

CL_MARGIN = 1e-7
"""Relative margin (of the surface's height span plus tool radius) added to every drop-cutter value."""

_CHUNK = 1 << 12  # positions per call of the kernel, and per worker's task


def drop_cutter(surface, x, y, radius: float, shape: str | None = None, *, corner: float | None = None,
                lattice: int = 8, starts: int = 3, margin: bool = True, evaluator: SurfaceEvaluator | None = None,
                workers: Workers | None = None, feature: float | None = None) -> np.ndarray:
    """Tool-tip heights of a cutter dropped onto the exact surface at ``(x, y)``.

    Parameters
    ----------
    surface : LagrangeSurface
        The exact surface; only its part inside the control points' box counts.
    x, y : array_like
        Tool axis positions in surface units, no further than ``radius``
        from the box.
    radius : float
        Tool radius in surface units (0: a point, the surface itself).
    shape : {"ball", "flat", "bull"}, optional
        Cutter shape (:data:`lagsym.cutter.SHAPES`); without one, ``corner``
        says the shape (:func:`lagsym.cutter.corner_radius`), and without
        either the cutter is a ball.
    corner : float, optional
        Corner radius in surface units: of a bull-nose cutter
        (``shape="bull"``), more than 0 and less than ``radius``; without a
        shape, 0 (a flat end) to ``radius`` (a ball).  A cutter's own is
        :meth:`lagsym.cutter.Cutter.grown_mm` scaled to surface units.
    lattice : int
        Candidate contact points per tool radius in the first, dense search.
    starts : int
        How many of the best candidates the local search refines.
    margin : bool
        Add :data:`CL_MARGIN`; without it the value is the best contact found,
        a lower bound of the exact one.
    evaluator : SurfaceEvaluator, optional
        The surface's evaluator (by default :func:`lagsym.evaluate.surface_evaluator`).
    workers : Workers, optional
        Worker processes for this evaluator (:mod:`.workers`) that share the
        positions out in chunks; the values are the same as without.
    feature : float, optional
        The smallest feature the lattice resolves (spacing at most half of it): by default the box over
        twice the degree; on a piecewise surface, half its narrowest cell.

    Returns
    -------
    numpy.ndarray
        Tip heights, shape of ``x`` broadcast with ``y``; never below the exact
        drop-cutter value, above it by at most :data:`CL_MARGIN` relative.

    Examples
    --------
    >>> from lagsym.grid import grid_from_points
    >>> from lagsym.lagrange import lagrange_surface
    >>> s = lagrange_surface(grid_from_points([(0, 0, 0), (0, 2, 0), (2, 0, 0), (2, 2, 0)]))
    >>> round(float(drop_cutter(s, 1.0, 1.0, 0.5)), 6)
    0.0
    """
    radius = positive(radius, "tool radius", allow_zero=True)
    corner = corner_radius(shape, radius, corner)
    ev = evaluator or evaluator_of(surface)
    if isinstance(ev, PiecewiseEvaluator):
        return _drop_piecewise(ev, x, y, radius, corner, lattice=lattice, starts=starts, margin=margin,
                               workers=workers)
    return _drop_polynomial(ev, x, y, radius, corner, lattice=lattice, starts=starts, margin=margin, workers=workers,
                            feature=feature)


def _drop_polynomial(ev: SurfaceEvaluator, x, y, radius: float, corner: float, *, lattice: int, starts: int,
                     margin: bool, workers: Workers | None = None, feature: float | None = None) -> np.ndarray:
    """:func:`drop_cutter` on one polynomial's evaluator."""
    x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    shape_out = x.shape
    box = ev.bounds
    cx, cy = _inside_box(x.ravel(), y.ravel(), box, radius)
    if radius == 0:
        return ev.fast_points(cx, cy).reshape(shape_out)
    x0, x1, y0, y1 = box
    if feature is None:
        deg = max(*ev.shape, 2)
        feature = min(x1 - x0, y1 - y0) / (2 * deg)
    spacing = max(min(radius / lattice, feature / 2), radius / 40)  # bounded work for a tool far larger than the box
    lattice_ = _lattice(radius, spacing)
    span = _height_scale(ev) + radius + 1.0
    parallel = workers is not None and workers.parallel and workers.evaluator is ev
    # Each position's value is independent of the chunk it is computed in.
    chunk = max(256, min(_CHUNK, -(-cx.size // (4 * workers.processes)))) if parallel else _CHUNK
    tasks = [(cx[s:s + chunk], cy[s:s + chunk], radius, corner, lattice_, spacing, starts, 0.01 * CL_MARGIN * span)
             for s in range(0, cx.size, chunk)]
    parts = workers.map(_drop_chunk, tasks) if parallel else [_drop_chunk(ev, *t) for t in tasks]
    out = np.concatenate(parts) if parts else np.empty(0)
    return (out + (CL_MARGIN * span if margin else 0.0)).reshape(shape_out)


def evaluator_of(surface):
    """The numeric evaluator drop-cutter and the planner use: a piecewise surface's own, else the polynomial's."""
    if isinstance(surface, PiecewiseSurface):
        return surface.evaluator
    return surface_evaluator(surface)


def _drop_piecewise(ev: PiecewiseEvaluator, x, y, radius: float, corner: float, *, lattice: int, starts: int,
                    margin: bool, workers: Workers | None = None) -> np.ndarray:
    """Drop-cutter on a piecewise surface: the highest of the drops onto every piece within the tool's reach.

    The box is the union of the cells, so the maximum over the disc and the
    box is the largest of the maxima over the disc and each cell; each is
    drop-cutter on the piece (a polynomial) restricted to its own cell, with
    the same search and lattice as on one polynomial.  A piece is searched
    only where it could rise above the height found: each position takes
    its pieces in the order of a bound no contact on them exceeds (from the
    Bezier control points of the parts of the piece, :func:`_piecewise_chunk`)
    and stops where the next bound is not above the height found.  The
    margin is :data:`CL_MARGIN` of the largest height scale of any piece, the
    same at every position.  With ``workers``, the positions are shared out
    among them in large chunks; the values are the same as without.
    """
    x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    shape_out = x.shape
    cx, cy = _inside_box(x.ravel(), y.ravel(), ev.bounds, radius)
    if radius == 0:
        return ev.fast_points(cx, cy).reshape(shape_out)
    parallel = workers is not None and workers.parallel and workers.evaluator is ev
    for parts in (_PARTS, _fine_parts(ev)):  # made here once, not in each worker
        ev.part_upper_heights(parts)
    # Each position's value is independent of the chunk it is computed in; a chunk takes its pieces in rounds
    # from Python, so chunks are large.
    chunk = max(_PIECEWISE_CHUNK, -(-cx.size // (2 * workers.processes))) if parallel else cx.size
    tasks = [(cx[s:s + chunk], cy[s:s + chunk], (radius, corner), (lattice, starts)) for s in range(0, cx.size, chunk)]
    parts = workers.map(_piecewise_chunk, tasks) if parallel else [_piecewise_chunk(ev, *t) for t in tasks]
    out = np.concatenate(parts) if parts else np.empty(0)
    span = _piecewise_height_scale(ev) + radius + 1.0
    return (out + (CL_MARGIN * span if margin else 0.0)).reshape(shape_out)


_PIECEWISE_CHUNK = 2048  # positions per worker's task on a piecewise surface, at least


def _piecewise_chunk(ev: PiecewiseEvaluator, cx, cy, cutter: tuple[float, float],
                     search: tuple[int, int]) -> np.ndarray:
    """The highest drop onto any piece at each of the positions ``cx, cy`` (inside the box's reach), no margin;
    ``cutter`` is ``(radius, corner)``, ``search`` ``(lattice, starts)`` as :func:`drop_cutter` takes them.

    Each piece within reach of a position has a bound no contact on it
    exceeds (:mod:`.piecekernel`), from :data:`_PARTS` x :data:`_PARTS` parts
    of its cell.  In rounds, each position drops onto its piece of highest
    bound not yet dropped on, while that bound is above the height found; so
    the piece the tool rests on usually comes first.  After the first round,
    the pieces still in question get the closer bound of
    :func:`_fine_parts` parts, which rules out most of them.
    """
    (radius, corner), (lattice, starts) = cutter, search
    bx, by = ev.breaks_x, ev.breaks_y
    # The pieces' joins are where the surface's nodes are, as a polynomial's features are its nodes' spacing.
    feature = 0.5 * min(np.diff(bx).min(), np.diff(by).min())
    scale = _piecewise_height_scale(ev)
    # Drop-cutter on each piece as on one polynomial (_drop_polynomial), its arguments made once per piece.
    from .kernel import drop_chunk

    spacing = max(min(radius / lattice, feature / 2), radius / 40)
    grid = [np.require(a, requirements="W") for a in _lattice(radius, spacing)]
    settle = 0.01 * CL_MARGIN * (scale + radius + 1.0)  # one settling threshold for every piece, the whole surface's
    surfaces = {}
    pos, i, k = _piece_pairs(ev, cx, cy, radius)
    bound = _piece_bounds(ev, cx, cy, (pos, i, k), radius, corner, parts=_PARTS)
    near = bound > -np.inf
    pos, piece, bound = pos[near], (i * (len(by) - 1) + k)[near], bound[near]
    out = np.full(cx.shape, -np.inf)
    columns = len(by) - 1
    fine = _fine_parts(ev)
    while pos.size:
        # The first pair of each position, by highest bound: its next piece to drop on.
        order = np.lexsort((-bound, pos))
        pos, piece, bound = pos[order], piece[order], bound[order]
        first = np.ones(pos.size, dtype=bool)
        first[1:] = pos[1:] != pos[:-1]
        now_pos, now_piece = pos[first], piece[first]
        by_piece = np.argsort(now_piece, kind="stable")
        now_pos, now_piece = now_pos[by_piece], now_piece[by_piece]
        cuts = np.flatnonzero(np.diff(now_piece)) + 1
        for group, p in zip(np.split(now_pos, cuts), now_piece[np.r_[0, cuts]]):
            i, k = divmod(int(p), columns)
            found = surfaces.get(p)
            if found is None:
                found = surfaces[p] = _kernel_surface(ev.piece_evaluator(i, k), radius, corner, spacing, settle)
            gx, gy = cx[group], cy[group]
            nx, ny = np.clip(gx, bx[i], bx[i + 1]), np.clip(gy, by[k], by[k + 1])
            gx, gy = _kept_within(gx, gy, nx, ny, np.hypot(gx - nx, gy - ny), radius)
            z = drop_chunk(*found, gx, gy, *grid, int(starts), corner == radius)
            out[group] = np.maximum(out[group], z)
        keep = ~first & (bound > out[pos])
        pos, piece, bound = pos[keep], piece[keep], bound[keep]
        if fine > _PARTS and pos.size:
            bound = _piece_bounds(ev, cx, cy, (pos, *np.divmod(piece, columns)), radius, corner, parts=fine)
            keep = bound > out[pos]
            pos, piece, bound = pos[keep], piece[keep], bound[keep]
            fine = _PARTS
    return out


_PARTS = 4  # parts of a piece's cell each way, for the bounds of what the piece can lift the tool to


def _fine_parts(ev: PiecewiseEvaluator) -> int:
    """Parts each way of the closer bounds: 16 (256 bounds a piece kept) while the pieces are few enough for
    them to take tens of megabytes at most, fewer for more pieces."""
    pieces = (len(ev.breaks_x) - 1) * (len(ev.breaks_y) - 1)
    return 16 if pieces <= 20_000 else 8 if pieces <= 80_000 else _PARTS


def _piece_pairs(ev: PiecewiseEvaluator, cx, cy, radius: float):
    """``(position, i, k)`` for every piece ``(i, k)`` whose cell's bounding columns and rows come within the
    tool's reach of each position."""
    bx, by = ev.breaks_x, ev.breaks_y
    reach = radius + _piece_eps(ev, radius)
    ni, nk = len(bx) - 1, len(by) - 1
    # The columns and rows of cells within reach of each position: lo..hi.
    i_lo = np.clip(np.searchsorted(bx[1:], cx - reach, "left"), 0, ni - 1)
    i_hi = np.clip(np.searchsorted(bx[:-1], cx + reach, "right") - 1, 0, ni - 1)
    k_lo = np.clip(np.searchsorted(by[1:], cy - reach, "left"), 0, nk - 1)
    k_hi = np.clip(np.searchsorted(by[:-1], cy + reach, "right") - 1, 0, nk - 1)
    wi, wk = int((i_hi - i_lo).max()) + 1, int((k_hi - k_lo).max()) + 1
    pos = np.repeat(np.arange(cx.size), wi * wk)
    di, dk = np.divmod(np.tile(np.arange(wi * wk), cx.size), wk)
    i, k = i_lo[pos] + di, k_lo[pos] + dk
    inside = (i <= i_hi[pos]) & (k <= k_hi[pos])
    return pos[inside], i[inside], k[inside]


def _piece_eps(ev: PiecewiseEvaluator, radius: float) -> float:
    """Rounding allowed in reach and height, as the box's own reach allows."""
    bx, by = ev.breaks_x, ev.breaks_y
    return 1e-9 * max(bx[-1] - bx[0], by[-1] - by[0], radius)


def _piece_bounds(ev: PiecewiseEvaluator, cx, cy, pairs, radius: float, corner: float, *, parts: int) -> np.ndarray:
    """For each pair ``(position, i, k)`` of ``pairs``, a height no contact on piece ``(i, k)`` puts the tool
    tip above at that position, from ``parts`` x ``parts`` parts of its cell (:mod:`.piecekernel`); ``-inf``
    where no part is within reach."""
    from .piecekernel import part_bounds

    pos, i, k = (np.ascontiguousarray(a, dtype=np.int64) for a in pairs)
    eps = _piece_eps(ev, radius)
    tops = ev.part_upper_heights(parts)
    return part_bounds(np.ascontiguousarray(cx, dtype=float), np.ascontiguousarray(cy, dtype=float), pos, i, k,
                       np.ascontiguousarray(ev.breaks_x), np.ascontiguousarray(ev.breaks_y),
                       np.ascontiguousarray(tops), float(radius), float(corner), (radius + eps) ** 2) + eps


def _piecewise_height_scale(ev: PiecewiseEvaluator) -> float:
    found = _HEIGHT_SCALES.get(ev)
    if found is None:
        # Each piece's power-basis spread on its normalized cell, as for one polynomial.
        found = _HEIGHT_SCALES[ev] = float(np.ptp(ev.local, axis=(2, 3)).max())
    return found


def _inside_box(cx, cy, box, radius=0.0):
    """The tool positions, refused if further than ``radius`` from the box (beyond rounding).

    A position within reach of the box keeps the box under part of the tool;
    those beyond the box are kept within ``radius`` of it.
    """
    x0, x1, y0, y1 = box
    eps_box = 1e-9 * max(x1 - x0, y1 - y0, radius)
    nx, ny = np.clip(cx, x0, x1), np.clip(cy, y0, y1)
    d = np.hypot(cx - nx, cy - ny)
    outside = d > radius + eps_box
    if np.any(outside):
        bad = int(np.flatnonzero(outside)[0])
        reach = f" by more than the tool radius {radius:g}" if radius > 0 else ""
        raise ToolpathError(f"tool position ({cx[bad]:g}, {cy[bad]:g}) lies outside the control points' box "
                            f"x {x0:g}..{x1:g}, y {y0:g}..{y1:g}{reach}")
    if radius == 0:
        return nx, ny
    return _kept_within(cx, cy, nx, ny, d, radius)


def _kept_within(cx, cy, nx, ny, d, radius: float):
    """Positions ``d`` from their nearest box points ``nx, ny`` moved towards them to at most ``radius``."""
    f = np.where(d > radius, radius / np.where(d > 0, d, 1.0), 1.0)
    return nx + (cx - nx) * f, ny + (cy - ny) * f


_HEIGHT_SCALES: weakref.WeakKeyDictionary[SurfaceEvaluator | PiecewiseEvaluator, float] = weakref.WeakKeyDictionary()


def _height_scale(ev: SurfaceEvaluator) -> float:
    """Spread of the surface's coefficients in the power basis of the normalized coordinates.

    The scale :data:`CL_MARGIN` and the search's settling threshold are
    relative to; the Chebyshev coefficients are converted back (in floats) only
    to measure it, once per evaluator.
    """
    found = _HEIGHT_SCALES.get(ev)
    if found is None:
        found = _HEIGHT_SCALES[ev] = _power_spread(ev.coefficients)
    return found


def _power_spread(coefficients: np.ndarray) -> float:
    n, m = coefficients.shape
    to_power_x = np.array([np.pad(C.cheb2poly(np.eye(n)[k]), (0, n))[:n] for k in range(n)]).T
    to_power_y = np.array([np.pad(C.cheb2poly(np.eye(m)[k]), (0, m))[:m] for k in range(m)]).T
    return float(np.ptp(to_power_x @ coefficients @ to_power_y.T))


@functools.lru_cache(maxsize=16)
def _lattice(radius: float, spacing: float) -> _Lattice:
    """A square lattice inside the disc, plus points on its rim (for a flat end), laid out for the kernel.

    The offsets of the lattice points inside the disc (row by row) and then
    of the rim; their squared distances from the axis (the rim's the radius
    squared, which rounding would put just past); each lattice point's eight
    neighbours (-1 where none is inside); and for each rim point the
    lattice point nearest to it.
    """
    k = max(int(math.ceil(radius / spacing)), 1)
    t = np.linspace(-radius, radius, 2 * k + 1)
    gx, gy = np.meshgrid(t, t, indexing="ij")
    inside = gx**2 + gy**2 <= radius**2 * (1 + 1e-12)
    rim_n = max(8 * k, 16)
    a = np.linspace(0.0, 2 * math.pi, rim_n, endpoint=False)
    rim = radius * np.stack([np.cos(a), np.sin(a)], axis=1)
    pts = np.stack([gx[inside], gy[inside]], axis=1)
    nearest = np.argmin(((rim[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2), axis=1)
    index = np.full((2 * k + 3, 2 * k + 3), -1)
    index[1:-1, 1:-1][inside] = np.arange(len(pts))
    li, lj = np.nonzero(inside)
    nb = np.stack([index[li + 1 + di, lj + 1 + dj] for di in (-1, 0, 1) for dj in (-1, 0, 1) if di or dj], axis=1)
    reach2 = np.concatenate([np.minimum((pts**2).sum(axis=1), radius * radius), np.full(rim_n, radius * radius)])
    out = _Lattice(np.concatenate([pts, rim]), reach2, nb.astype(np.int64), nearest.astype(np.int64))
    for v in out:
        v.setflags(write=False)
    return out


class _Lattice(NamedTuple):
    offsets: np.ndarray
    reach2: np.ndarray
    neighbours: np.ndarray
    nearest: np.ndarray


@contextlib.contextmanager
def telling_compiles(progress: Progress | None):
    """A block in which a compilation of the kernel that keeps the caller waiting over two seconds is reported to
    ``progress`` as the stage :data:`~lagsym.progress.COMPILING` (a first run after an install); numba is loaded.
    Where the background process started after the install is compiling it, the block waits for it first.

    Keep the block to one small drop: the report comes from a timer thread,
    and no other report may be made meanwhile.
    """
    from .compiling import told_if_compiling
    from .kernelahead import compile_ahead
    from .kernelcache import cache_folder, hold_planning_lock, kernel_cached, wait_for_background

    told = []

    def tell() -> None:
        if not told and progress is not None:
            progress(0, None, COMPILING)
        told.append(True)

    hold_planning_lock()  # the background compile leaves the evaluation kernels until this process ends
    wait_for_background(tell)  # a plan just after an install: the kernel is being compiled in the background
    with told_if_compiling(tell):
        if cache_folder() is not None and not kernel_cached():  # compiled here: its heaviest callees on two cores
            compile_ahead()
        yield
    if told and progress is not None:
        progress(1, 1, COMPILING)


def _drop_chunk(ev, cx, cy, radius, corner, lattice, spacing, starts, settle):
    """Drop-cutter over one chunk of positions (no margin), in the compiled kernel; numba is imported here, on
    first use, so that importing lagsym loads no compiler."""
    from .kernel import drop_chunk

    c, jet, geo = _kernel_surface(ev, radius, corner, spacing, settle)
    # Writable arrays everywhere, as a worker process receives them: Numba compiles one version per kind of array,
    # and a read-only lattice here would leave the workers to compile their own.
    lattice = [np.require(a, requirements="W") for a in lattice]
    cx, cy = np.require(cx, float, "CW"), np.require(cy, float, "CW")
    return drop_chunk(c, jet, geo, cx, cy, *lattice, int(starts), corner == radius)


def _kernel_surface(ev, radius, corner, spacing, settle):
    """The kernel's surface arguments: the coefficients, the ball's jet coefficients and the geometry."""
    c = np.ascontiguousarray(ev.coefficients, dtype=float)
    jet = jet_coefficients(ev) if corner == radius else np.zeros((6 * c.shape[1], c.shape[0]))
    return c, jet, kernel_geometry(ev, ev.bounds, radius, corner, spacing, settle)
