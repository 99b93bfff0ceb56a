"""Cutter locations: the tool dropped onto the exact surface until it touches it anywhere under it.

For a ball of radius ``R`` centred over ``c = (cx, cy)`` the tip height is

    CL(c) = max over p in D(c, R) ∩ B of  F(p) + sqrt(R**2 - |p - c|**2) - R,

for a flat end ``max F(p)`` over the same set, and for a bull-nose end mill of
corner radius ``r`` the same maximum of ``F(p) - P(|p - c|)``, ``P`` its profile
(0 across the flat, ``r - sqrt(r**2 - (d - R + r)**2)`` on the corner; the ball
and the flat end are its limits ``r = R`` and ``r = 0``,
:func:`lagsym.machine.cutter_profile`); ``D`` is the disc under the
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

The surface is evaluated by :meth:`lagsym.evaluate.SurfaceEvaluator.fast_points`.
"""

from __future__ import annotations

import functools
import math
import weakref

import numpy as np
from numpy.polynomial import chebyshev as C

from ..errors import ToolpathError
from ..evaluate import SurfaceEvaluator, surface_evaluator
from ..machine import TOOL_SHAPES, cutter_profile
from ..values import choice, positive
from .newton import newton_ball
from .region import edge_points, project
from .workers import Workers

__all__ = ["CL_MARGIN", "drop_cutter"]

CL_MARGIN = 1e-7
"""Relative margin (of the surface's height span plus tool radius) added to every drop-cutter value."""

_CHUNK = 1 << 12  # positions per pass: about 30 MB of candidates
_DIRS = np.array([(1, 0), (-1, 0), (0, 1), (0, -1)], dtype=float)
_SIGNS = np.array([1.0, -1.0])[None, :, None]
_HALF = math.sqrt(0.5)


def drop_cutter(surface, x, y, radius: float, shape: str = "ball", *, corner: float | None = None, lattice: int = 8,
                starts: int = 3, margin: bool = True, evaluator: SurfaceEvaluator | None = None,
                workers: Workers | None = None) -> np.ndarray:
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
    shape : {"ball", "flat", "bull"}
        Cutter shape.
    corner : float, optional
        Corner radius of a bull-nose cutter (``shape="bull"``), in surface
        units, more than 0 and less than ``radius``; not given for the others.
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
    corner = _corner(shape, radius, corner)
    ev = evaluator or surface_evaluator(surface)
    x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    shape_out = x.shape
    box = ev.bounds
    cx, cy = _inside_box(x.ravel(), y.ravel(), box, radius)
    if radius == 0:
        return ev.fast_points(cx, cy).reshape(shape_out)
    x0, x1, y0, y1 = box
    deg = max(*ev.shape, 2)
    feature = min(x1 - x0, y1 - y0) / (2 * deg)
    spacing = min(radius / lattice, feature / 2)
    spacing = max(spacing, radius / 40)  # bounded work for a tool far larger than the box
    offsets, inside, nearest = _lattice(radius, spacing)
    span = _height_scale(ev) + radius + 1.0
    parallel = workers is not None and workers.parallel and workers.evaluator is ev
    # Each position's value is independent of the chunk it is computed in.
    chunk = max(256, min(_CHUNK, -(-cx.size // (4 * workers.processes)))) if parallel else _CHUNK
    tasks = [(cx[s:s + chunk], cy[s:s + chunk], radius, corner, offsets, (inside, nearest), spacing, starts, box,
              0.01 * CL_MARGIN * span) for s in range(0, cx.size, chunk)]
    parts = workers.map(_drop_chunk, tasks) if parallel else [_drop_chunk(ev, *t) for t in tasks]
    out = np.concatenate(parts) if parts else np.empty(0)
    return (out + (CL_MARGIN * span if margin else 0.0)).reshape(shape_out)


def _corner(shape: str, radius: float, corner: float | None) -> float:
    """The corner radius of the cutter: ``radius`` for a ball, 0 for a flat end, checked for a bull nose."""
    choice(shape, TOOL_SHAPES, "tool shape")
    if shape != "bull":
        if corner is not None:
            raise ToolpathError(f"a corner radius ({corner!r}) is for a bull-nose cutter, not a {shape} end")
        return radius if shape == "ball" else 0.0
    if corner is None or not 0.0 < float(corner) < radius:
        raise ToolpathError(f"a bull-nose cutter of radius {radius:g} needs a corner radius more than 0 and less "
                            f"than {radius:g}, not {corner!r}")
    return float(corner)


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
    f = np.where(d > radius, radius / np.where(d > 0, d, 1.0), 1.0)
    return nx + (cx - nx) * f, ny + (cy - ny) * f


_HEIGHT_SCALES: weakref.WeakKeyDictionary[SurfaceEvaluator, float] = weakref.WeakKeyDictionary()


def _height_scale(ev: SurfaceEvaluator) -> float:
    """Spread of the surface's coefficients in the power basis of the normalized coordinates.

    The scale :data:`CL_MARGIN` and the search's settling threshold were set
    against; the Chebyshev coefficients are converted back (in floats) only
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
def _lattice(radius: float, spacing: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Offsets of a square lattice inside the disc, plus points on its rim (for a flat end).

    Also returns the lattice's mask of points inside the disc (its square
    ``2 k + 1`` by ``2 k + 1``, in the order of the offsets), and for each rim
    point the index of the lattice point nearest to it.
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
    out = (np.concatenate([pts, rim]), inside, nearest)
    for v in out:
        v.setflags(write=False)
    return out


def _peaks(val, inside, nearest):
    """Which candidates are local maxima of the sampled heights: no neighbour on the lattice (or rim) higher.

    The corners of the region under the tool, after the lattice and rim, always count.
    """
    n, m, w = val.shape[0], int(inside.sum()), inside.shape[0]
    g = np.full((n, w + 2, w + 2), -np.inf)
    g[:, 1:-1, 1:-1][:, inside] = val[:, :m]
    c = g[:, 1:-1, 1:-1]
    # No neighbour higher: as high as the largest of the 3 x 3 block around it (a separable maximum).
    across = np.maximum(np.maximum(g[:, :, :-2], g[:, :, 1:-1]), g[:, :, 2:])
    top = c >= np.maximum(np.maximum(across[:, :-2], across[:, 1:-1]), across[:, 2:])
    peak = np.ones(val.shape, dtype=bool)
    peak[:, :m] = top[:, inside]
    rim = val[:, m:m + len(nearest)]
    peak[:, m:m + len(nearest)] = ((rim >= np.roll(rim, 1, axis=1)) & (rim >= np.roll(rim, -1, axis=1))
                                   & (rim >= val[:, nearest]))
    return peak


def _height(ev, px, py, d2, radius, corner):
    """Tip height of the tool in contact at ``(px, py)``, ``d2`` the squared distance from its axis."""
    z = ev.fast_points(px, py)
    if corner > 0.0:
        z = z - cutter_profile(d2, radius, corner)
    return z


def _drop_chunk(ev, cx, cy, radius, corner, offsets, lattice, spacing, starts, box, settle):
    """Drop-cutter over one chunk of positions: dense candidates, then a local search from the best of each basin."""
    val, px, py = _candidates(ev, cx, cy, radius, corner, offsets, box, int(lattice[0].sum()))
    order = _starts(val, px, py, cx, cy, offsets, lattice, spacing, starts)
    rows = np.arange(cx.size)[:, None]
    sx, sy, sv = px[rows, order].ravel(), py[rows, order].ravel(), val[rows, order].ravel()
    scx, scy = np.repeat(cx, order.shape[1]), np.repeat(cy, order.shape[1])
    # A ball's starts first climb by Newton steps, which leave the pattern search a short way to settle.
    h, done = newton_ball(ev, sx, sy, sv, scx, scy, radius, box, spacing, settle) if corner == radius \
        else (spacing, None)
    found = _refine(ev, sx, sy, sv, scx, scy, radius, corner, box, h, settle, done)
    return np.maximum(found.reshape(cx.size, -1).max(axis=1), val.max(axis=1))


def _candidates(ev, cx, cy, radius, corner, offsets, box, m):
    """Heights and contact points of the lattice and rim under each tool, then of the corners of the region under it.

    The corners are the box corners and where the rim crosses a box edge.
    The first ``m`` offsets are the lattice's, inside the disc.
    Returns arrays of shape ``(positions, candidates)``.
    """
    n, k = cx.size, len(offsets)
    # Dense candidates, a block of offsets at a time to bound memory; the lattice apart from the rim, which
    # rounding puts just outside the disc, so the lattice's points need no more than the box.
    block = max(1, (1 << 22) // max(n, 1))
    ex, ey = edge_points(cx, cy, radius, box)
    w = k + ex.shape[1]
    val, px, py = np.empty((n, w)), np.empty((n, w)), np.empty((n, w))
    cuts = sorted(set(range(0, k, block)) | {m, k})
    # The lattice and rim lie under the tool already (the rim to rounding: its distance is taken as the
    # radius).  Only a tool over a box edge needs them moved: into the box, which with the axis inside it
    # keeps them in the disc; with the axis beyond the box, onto the disc too (:func:`.region.project`).
    x0, x1, y0, y1 = box
    beyond = (cx < x0) | (cx > x1) | (cy < y0) | (cy > y1)
    edge = np.flatnonzero(~beyond & ((cx - radius < x0) | (cx + radius > x1) | (cy - radius < y0)
                                     | (cy + radius > y1)))
    beyond = np.flatnonzero(beyond)
    reach2 = np.minimum(offsets[:, 0] ** 2 + offsets[:, 1] ** 2, radius * radius)
    for s, e in zip(cuts[:-1], cuts[1:]):
        ox, oy = offsets[s:e, 0], offsets[s:e, 1]
        qx, qy = cx[:, None] + ox, cy[:, None] + oy
        d2 = np.repeat(reach2[None, s:e], n, axis=0)
        if edge.size:
            ex_, ey_ = np.clip(qx[edge], x0, x1), np.clip(qy[edge], y0, y1)
            qx[edge], qy[edge] = ex_, ey_
            d2[edge] = np.minimum((ex_ - cx[edge, None]) ** 2 + (ey_ - cy[edge, None]) ** 2, d2[edge])
        if beyond.size:
            qx[beyond], qy[beyond], d2[beyond] = project(qx[beyond], qy[beyond], cx[beyond, None],
                                                          cy[beyond, None], radius, box)
        val[:, s:e] = _height(ev, qx, qy, d2, radius, corner)
        px[:, s:e], py[:, s:e] = qx, qy
    qx, qy, d2 = project(ex, ey, cx[:, None], cy[:, None], radius, box)
    val[:, k:], px[:, k:], py[:, k:] = _height(ev, qx, qy, d2, radius, corner), qx, qy
    return val, px, py


def _starts(val, px, py, cx, cy, offsets, lattice, spacing, starts):
    """For each position, the candidates the local search starts from: the best candidates of distinct basins.

    Only a local maximum of the sampled heights (no lattice neighbour higher;
    the region's corners always count) heads a basin of its own: the best few
    candidates overall may all lie on the slopes of one or two peaks, and a
    narrow peak elsewhere, its samples all below them, would never be refined.
    A lattice or rim point the box moved is a copy of a point on its edge,
    maybe one of many: its peaks come after the others.  The best candidate of
    all comes first in any case.
    """
    n, k = cx.size, len(offsets)
    moved = np.zeros(val.shape, dtype=bool)
    moved[:, :k] = (px[:, :k] != cx[:, None] + offsets[:, 0]) | (py[:, :k] != cy[:, None] + offsets[:, 1])
    rank = np.where(_peaks(val, *lattice), np.where(moved, 1, 0), 2)
    rank[np.arange(n), np.argmax(val, axis=1)] = 0
    return _spread_starts(val, px, py, starts, 2.5 * spacing, rank)


def _refine(ev, px, py, val, ccx, ccy, radius, corner, box, step, settle, poll=None):
    """Pattern search from each start, in place: the best contact height found from each.

    Eight steps a round, along the axes and along and across the radius,
    from ``step`` (one for all, or one for each start);
    the step halves where none climbs, down to ``1e-9`` of the radius.
    A start marked in ``poll`` (a maximum Newton's method converged to) is
    done when its first round does not climb; where it does, the search
    goes on from there as for any start.
    """
    h = np.array(np.broadcast_to(step, px.shape), dtype=float)
    stop = radius * 1e-9
    for rnd in range(120):
        active = h > stop
        if not active.any():
            break
        ia = np.flatnonzero(active)
        # Axis steps follow the box edges; radial and tangential steps follow the rim of the disc.
        ox, oy = px[ia] - ccx[ia], py[ia] - ccy[ia]
        norm = np.hypot(ox, oy)
        at_centre = norm <= stop
        norm = np.where(at_centre, 1.0, norm)
        # At the centre there is no radius to follow: step along the diagonals instead.
        er = np.stack([np.where(at_centre, _HALF, ox / norm), np.where(at_centre, _HALF, oy / norm)], axis=1)
        et = np.stack([-er[:, 1], er[:, 0]], axis=1)
        dirs = np.concatenate([np.broadcast_to(_DIRS[None, :, :], (ia.size, 4, 2)),
                               er[:, None, :] * _SIGNS, et[:, None, :] * _SIGNS], axis=1)
        qx = px[ia, None] + h[ia, None] * dirs[:, :, 0]
        qy = py[ia, None] + h[ia, None] * dirs[:, :, 1]
        qx, qy, d2 = project(qx, qy, ccx[ia, None], ccy[ia, None], radius, box)
        qv = _height(ev, qx, qy, d2, radius, corner)
        j = np.argmax(qv, axis=1)
        bv = qv[np.arange(ia.size), j]
        up = bv > val[ia]
        iu = ia[up]
        nx, ny = qx[up, j[up]], qy[up, j[up]]
        # A step the projection shortened to a creep along a constraint counts as a failure too:
        # shrinking lets the steps along the rim or edge stop overshooting the maximum.
        creep = np.hypot(nx - px[iu], ny - py[iu]) < 0.25 * h[iu]
        px[iu], py[iu], val[iu] = nx, ny, bv[up]
        h[ia[~up]] *= 0.5
        h[iu[creep]] *= 0.5
        # Where no neighbour differs by more than a hundredth of the margin, the value has settled.
        settled = ~up & (np.max(np.abs(np.where(np.isfinite(qv), qv, val[ia, None]) - val[ia, None]), axis=1) < settle)
        if rnd == 0 and poll is not None:
            settled |= ~up & poll[ia]
        h[ia[settled]] = 0.0
    return val


def _spread_starts(val, px, py, starts, apart, rank=None):
    """For each row, the best candidate and then the best ones at least ``apart`` from those already chosen.

    Two nearly equal peaks under the tool are then both refined, instead of
    two neighbours on the slope of one of them.  Where ``rank`` is given, the
    candidates of rank 0 (the local maxima) come first, best first, then those
    of rank 1, then those of rank 2.
    """
    n, k = val.shape
    key = val if rank is None else val - rank * (np.ptp(val, axis=1, keepdims=True) + 1.0)
    many = min(k, 8 * starts + 32)
    # The best ``many`` of each row, best first: partitioned out, then only those sorted.
    top = np.argpartition(-key, many - 1, axis=1)[:, :many] if many < k else np.tile(np.arange(k), (n, 1))
    top = np.take_along_axis(top, np.argsort(-np.take_along_axis(key, top, axis=1), axis=1), axis=1)
    rows = np.arange(n)[:, None]
    tx, ty = px[rows, top], py[rows, top]
    chosen = [top[:, 0]]
    far = np.ones(top.shape, dtype=bool)
    for _ in range(1, starts):
        last = chosen[-1]
        lx, ly = px[np.arange(n), last], py[np.arange(n), last]
        far &= np.hypot(tx - lx[:, None], ty - ly[:, None]) >= apart
        j = np.argmax(far, axis=1)  # the first (best) far candidate, or 0 if none is far
        chosen.append(np.where(far[np.arange(n), j], top[np.arange(n), j], top[:, min(len(chosen), top.shape[1] - 1)]))
    return np.stack(chosen, axis=1)
