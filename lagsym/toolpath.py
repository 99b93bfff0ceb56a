"""Raster toolpaths with gouge-free cutter locations.

The pipeline follows OpenCAMLib's four steps, each its own function:

1. **path pattern** (:func:`raster_pattern`): a zig-zag of rows along x or y
   over the control points' box, side step and forward step in millimetres;
2. **cutter locations** (:func:`drop_cutter`): at each ``(x, y)`` the tool is
   lowered until it touches the exact surface anywhere under it;
3. **filtering** (:func:`filter_rows`): with a chordal tolerance, points whose
   removal keeps the moves within the tolerance of the true cutter path go;
4. the program text, in :mod:`lagsym.post`.

Terms are used as in CAM: the *cutter location* (CL) is the programmed point,
here the tool tip; the *cutter contact* (CC) point is where the tool touches
the surface.

Drop-cutter
-----------
For a ball of radius ``R`` centred over ``c = (cx, cy)`` the tip height is

    CL(c) = max over p in D(c, R) ∩ B of  F(p) + sqrt(R**2 - |p - c|**2) - R,

and for a flat end ``max F(p)`` over the same set; ``D`` is the disc under the
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

Chordal error
-------------
Between two cutter locations the control moves in a straight line, which cuts
below the true cutter path where the path bends down.  Each row is therefore
sampled more finely than it is emitted, and every move is lifted (both ends)
by how far the true path may rise above it:

* where the tool stays clear of the box edges across the move (an edge along
  the move cuts the same part off the tool all along it), the cutter path is
  *semi-convex*: it is the upper envelope of copies of the surface shifted
  under the tool, so it bends down no faster than the surface, ``K`` (the
  :meth:`SurfaceEvaluator.curvature_bound`).  Between samples ``h`` apart it
  rises at most ``K h**2 / 8`` above their polyline, so the sag the samples
  show plus that bound is a bound of the move's sag.  (A quarter of the
  path's downward second difference at each sample is taken too, when
  larger.)
* where the tool crosses a box edge across the move, it starts to rest on the
  edge or a corner between two samples and the path can bend down sharply
  (a square-root onset, or a bend a few hundredths of a millimetre wide); no
  such bound holds.  Each of these moves is checked against the true path:
  drop-cutter at evenly spaced interior points (at least six, at most a
  sixteenth of the tool radius apart or else 48), then three rounds of
  denser samples around the worst one.  With a tolerance, a move that dips more than the
  tolerance gets the cutter location at its worst point as a new point, and
  both halves are checked again, until every move is within the tolerance.
  The move is then lifted by the dip found.

Emitted points thus lie on or above the exact drop-cutter value and at most the
chordal error (the tolerance, when one is given) above it, and no move passes
below the true cutter path by more than what the checks may miss between their
samples (in the tests, never above ``1e-4`` mm, a tenth of a program's
resolution).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.polynomial import polynomial as P

from ._arrays import freeze_fields
from .errors import ToolpathError
from .machine import MachineSettings, RasterSpec, Tool

__all__ = [
    "Toolpath",
    "SurfaceEvaluator",
    "raster_pattern",
    "drop_cutter",
    "filter_rows",
    "scallop_stepover",
    "plan_toolpath",
    "CL_MARGIN",
]

CL_MARGIN = 1e-7
"""Relative margin (of the surface's height span plus tool radius) added to every drop-cutter value."""

_CHUNK = 1 << 12  # positions per pass: about 30 MB of candidates


class SurfaceEvaluator:
    """Value of a Lagrange surface at scattered points, fast, from its exact coefficients.

    The exact power-basis coefficients are first re-expressed, exactly, in the
    normalised variables ``u, v`` that map the box onto ``[-1, 1]**2``; only
    then are they rounded to floats.  Evaluation in ``u, v`` is well conditioned
    for the degrees lagsym handles, unlike the raw power basis over a box far
    from the origin.
    """

    def __init__(self, surface):
        from fractions import Fraction

        x0, x1, y0, y1 = surface.grid.bounds
        mx, hx = (x0 + x1) / 2, (x1 - x0) / 2
        my, hy = (y0 + y1) / 2, (y1 - y0) / 2
        c = surface.coefficients
        n, m = len(c), len(c[0])

        def shift(mid, half, deg):
            s = [[Fraction(0)] * deg for _ in range(deg)]
            for a in range(deg):
                for k in range(a + 1):
                    s[a][k] = math.comb(a, k) * mid ** (a - k) * half ** k
            return s

        sx, sy = shift(mx, hx, n), shift(my, hy, m)
        # d[k][l] = sum_ab sx[a][k] c[a][b] sy[b][l], exactly.
        t = [[sum(sx[a][k] * c[a][b] for a in range(n)) for b in range(m)] for k in range(n)]
        d = [[sum(t[k][b] * sy[b][l] for b in range(m)) for l in range(m)] for k in range(n)]
        self.coef = np.array([[float(v) for v in row] for row in d])
        self.coef.setflags(write=False)
        self.mid = (float(mx), float(my))
        self.half = (float(hx), float(hy))
        self.bounds = tuple(float(v) for v in surface.grid.bounds)

    def __call__(self, x, y) -> np.ndarray:
        """``F(x, y)``; ``x`` and ``y`` broadcast together."""
        u = (np.asarray(x, dtype=float) - self.mid[0]) / self.half[0]
        v = (np.asarray(y, dtype=float) - self.mid[1]) / self.half[1]
        return P.polyval2d(u, v, self.coef)

    def curvature_bound(self, samples: int = 41) -> float:
        """Largest ``|F_xx|``, ``|F_yy|`` or ``|F_xy|`` seen on a sample grid (per surface unit)."""
        u = np.linspace(-1.0, 1.0, samples)
        uu, vv = np.meshgrid(u, u, indexing="ij")
        hx, hy = self.half
        out = 0.0
        for dx, dy, s in ((2, 0, hx * hx), (0, 2, hy * hy), (1, 1, hx * hy)):
            c = P.polyder(P.polyder(self.coef, dx, axis=0), dy, axis=1) if (dx or dy) else self.coef
            if c.size:
                out = max(out, float(np.abs(P.polyval2d(uu, vv, c)).max()) / s)
        return out


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
    top = np.ones(c.shape, dtype=bool)
    for di in (0, 1, 2):
        for dj in (0, 1, 2):
            if di != 1 or dj != 1:
                top &= c >= g[:, di:di + w, dj:dj + w]
    peak = np.ones(val.shape, dtype=bool)
    peak[:, :m] = top[:, inside]
    rim = val[:, m:m + len(nearest)]
    peak[:, m:m + len(nearest)] = ((rim >= np.roll(rim, 1, axis=1)) & (rim >= np.roll(rim, -1, axis=1))
                                   & (rim >= val[:, nearest]))
    return peak


def _project(px, py, cx, cy, radius, box):
    """Move candidate contact points into the box, then into the disc (the box is convex and holds the centre)."""
    x0, x1, y0, y1 = box
    px = np.clip(px, x0, x1)
    py = np.clip(py, y0, y1)
    dx, dy = px - cx, py - cy
    d2 = dx * dx + dy * dy
    over = d2 > radius * radius
    if np.any(over):
        f = np.where(over, radius / np.sqrt(np.where(over, d2, 1.0)), 1.0)
        px, py = cx + dx * f, cy + dy * f
        dx, dy = px - cx, py - cy
        d2 = dx * dx + dy * dy
    return px, py, d2


def _edge_points(cx, cy, radius, box):
    """Box corners, and for each box edge the foot of the perpendicular from the centre and the rim crossings."""
    x0, x1, y0, y1 = box
    n = cx.size
    xs, ys = [], []
    for a in (x0, x1):
        for b in (y0, y1):
            xs.append(np.full(n, a))
            ys.append(np.full(n, b))
    for a in (x0, x1):  # vertical edges
        w = np.sqrt(np.maximum(radius**2 - (cx - a) ** 2, 0.0))
        for off in (0.0, 1.0, -1.0):
            xs.append(np.full(n, a))
            ys.append(cy + off * w)
    for b in (y0, y1):  # horizontal edges
        w = np.sqrt(np.maximum(radius**2 - (cy - b) ** 2, 0.0))
        for off in (0.0, 1.0, -1.0):
            xs.append(cx + off * w)
            ys.append(np.full(n, b))
    return np.stack(xs, axis=1), np.stack(ys, axis=1)


def _height(ev, px, py, d2, radius, shape):
    z = ev(px, py)
    if shape == "ball":
        z = z + np.sqrt(np.maximum(radius * radius - d2, 0.0)) - radius
    return z


def drop_cutter(surface, x, y, radius: float, shape: str = "ball", *, lattice: int = 8, starts: int = 3,
                margin: bool = True, evaluator: SurfaceEvaluator | None = None) -> np.ndarray:
    """Tool-tip heights of a cutter dropped onto the exact surface at ``(x, y)``.

    Parameters
    ----------
    surface : LagrangeSurface
        The exact surface; only its part inside the control points' box counts.
    x, y : array_like
        Tool axis positions in surface units, inside the box.
    radius : float
        Tool radius in surface units (0: a point, the surface itself).
    shape : {"ball", "flat"}
        Cutter shape.
    lattice : int
        Candidate contact points per tool radius in the first, dense search.
    starts : int
        How many of the best candidates the local search refines.
    margin : bool
        Add :data:`CL_MARGIN`; without it the value is the best contact found,
        a lower bound of the exact one.

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
    ev = evaluator or SurfaceEvaluator(surface)
    x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    shape_out = x.shape
    cx, cy = x.ravel(), y.ravel()
    box = ev.bounds
    x0, x1, y0, y1 = box
    eps_box = 1e-9 * max(x1 - x0, y1 - y0)
    outside = (cx < x0 - eps_box) | (cx > x1 + eps_box) | (cy < y0 - eps_box) | (cy > y1 + eps_box)
    if np.any(outside):
        bad = int(np.flatnonzero(outside)[0])
        raise ToolpathError(f"tool position ({cx[bad]:g}, {cy[bad]:g}) lies outside the control points' box "
                            f"x {x0:g}..{x1:g}, y {y0:g}..{y1:g}")
    cx, cy = np.clip(cx, x0, x1), np.clip(cy, y0, y1)
    radius = float(radius)
    if radius < 0:
        raise ToolpathError(f"tool radius {radius!r} must not be negative")
    if radius == 0:
        return ev(cx, cy).reshape(shape_out)
    if shape not in ("ball", "flat"):
        raise ToolpathError(f"tool shape {shape!r} is not one of ball, flat")
    deg = max(len(ev.coef), len(ev.coef[0]), 2)
    feature = min(x1 - x0, y1 - y0) / (2 * deg)
    spacing = min(radius / lattice, feature / 2)
    spacing = max(spacing, radius / 40)  # bounded work for a tool far larger than the box
    offsets, inside, nearest = _lattice(radius, spacing)
    span = float(np.ptp(ev.coef)) + radius + 1.0
    out = np.empty(cx.size)
    for s in range(0, cx.size, _CHUNK):
        out[s:s + _CHUNK] = _drop_chunk(ev, cx[s:s + _CHUNK], cy[s:s + _CHUNK], radius, shape, offsets,
                                        (inside, nearest), spacing, starts, box, 0.01 * CL_MARGIN * span)
    return (out + (CL_MARGIN * span if margin else 0.0)).reshape(shape_out)


_DIRS = np.array([(1, 0), (-1, 0), (0, 1), (0, -1)], dtype=float)
_SIGNS = np.array([1.0, -1.0])[None, :, None]
_HALF = math.sqrt(0.5)


def _drop_chunk(ev, cx, cy, radius, shape, offsets, lattice, spacing, starts, box, settle):
    n, k = cx.size, len(offsets)
    best_val = np.full(n, -np.inf)
    # Dense candidates, a block of offsets at a time to bound memory.
    block = max(1, (1 << 22) // max(n, 1))
    cand_val = np.empty((n, k))
    cand_px = np.empty((n, k))
    cand_py = np.empty((n, k))
    for s in range(0, k, block):
        ox, oy = offsets[s:s + block, 0], offsets[s:s + block, 1]
        px, py, d2 = _project(cx[:, None] + ox, cy[:, None] + oy, cx[:, None], cy[:, None], radius, box)
        cand_val[:, s:s + block] = _height(ev, px, py, d2, radius, shape)
        cand_px[:, s:s + block], cand_py[:, s:s + block] = px, py
    # The corners of the region under the tool: box corners, and where the rim crosses a box edge.
    ex, ey = _edge_points(cx, cy, radius, box)
    px, py, d2 = _project(ex, ey, cx[:, None], cy[:, None], radius, box)
    cand_val = np.concatenate([cand_val, _height(ev, px, py, d2, radius, shape)], axis=1)
    cand_px = np.concatenate([cand_px, px], axis=1)
    cand_py = np.concatenate([cand_py, py], axis=1)
    # Starts: the best candidates of distinct basins.  Only a local maximum of the sampled heights
    # (no lattice neighbour higher; the region's corners always count) heads a basin of its own:
    # the best few candidates overall may all lie on the slopes of one or two peaks, and a narrow
    # peak elsewhere, its samples all below them, would never be refined.
    # A lattice or rim point the box moved is a copy of a point on its edge, maybe one of many: its peaks
    # come after the others.  The best candidate of all comes first in any case.
    moved = np.zeros(cand_val.shape, dtype=bool)
    moved[:, :k] = (cand_px[:, :k] != cx[:, None] + offsets[:, 0]) | (cand_py[:, :k] != cy[:, None] + offsets[:, 1])
    rank = np.where(_peaks(cand_val, *lattice), np.where(moved, 1, 0), 2)
    rank[np.arange(n), np.argmax(cand_val, axis=1)] = 0
    order = _spread_starts(cand_val, cand_px, cand_py, starts, 2.5 * spacing, rank)
    rows = np.arange(n)[:, None]
    px = cand_px[rows, order].ravel()
    py = cand_py[rows, order].ravel()
    val = cand_val[rows, order].ravel()
    ccx, ccy = np.repeat(cx, order.shape[1]), np.repeat(cy, order.shape[1])
    h = np.full(px.size, spacing)
    stop = radius * 1e-9
    for _ in range(120):
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
        qx, qy, d2 = _project(qx, qy, ccx[ia, None], ccy[ia, None], radius, box)
        qv = _height(ev, qx, qy, d2, radius, shape)
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
        h[ia[settled]] = 0.0
    best_val = np.maximum(best_val, val.reshape(n, -1).max(axis=1))
    return np.maximum(best_val, cand_val.max(axis=1))


def _spread_starts(val, px, py, starts, apart, rank=None):
    """For each row, the best candidate and then the best ones at least ``apart`` from those already chosen.

    Two nearly equal peaks under the tool are then both refined, instead of
    two neighbours on the slope of one of them.  Where ``rank`` is given, the
    candidates of rank 0 (the local maxima) come first, best first, then those
    of rank 1, then those of rank 2.
    """
    n, k = val.shape
    key = val if rank is None else val - rank * (np.ptp(val, axis=1, keepdims=True) + 1.0)
    top = np.argsort(-key, axis=1)[:, :min(k, 8 * starts + 32)]
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


def scallop_stepover(radius_mm: float, scallop_mm: float) -> float:
    """Side step of a ball-end cutter that leaves cusps ``scallop_mm`` high on a flat floor.

    ``2 * sqrt(2 R h - h**2)``, from the circle of the ball over the cusp.

    Examples
    --------
    >>> round(scallop_stepover(3.0, 0.01), 4)
    0.4895
    """
    r, h = float(radius_mm), float(scallop_mm)
    if r <= 0:
        raise ToolpathError("a scallop height needs a ball-end cutter with a diameter above 0")
    if h >= r:
        raise ToolpathError(f"scallop height {h:g} mm must be less than the tool radius {r:g} mm")
    return 2.0 * math.sqrt(2.0 * r * h - h * h)


def _levels(lo: float, hi: float, step: float) -> np.ndarray:
    count = max(int(math.ceil((hi - lo) / step - 1e-9)), 1)
    return np.linspace(lo, hi, count + 1)


def raster_pattern(bounds, direction: str, stepover: float, step: float):
    """A zig-zag over ``bounds`` = ``(x0, x1, y0, y1)``: row levels and along-row positions.

    Rows run along ``direction``; both are evenly spaced, never wider than the
    steps given, and include the box edges.  Odd rows run backwards.

    Returns
    -------
    levels : ndarray
        Cross coordinate of each row.
    along : ndarray
        Positions along a row (forwards).
    """
    x0, x1, y0, y1 = (float(v) for v in bounds)
    if direction == "x":
        return _levels(y0, y1, stepover), _levels(x0, x1, step)
    return _levels(x0, x1, stepover), _levels(y0, y1, step)


def filter_rows(along: np.ndarray, z: np.ndarray, tolerance: float, extra: np.ndarray | None = None) -> np.ndarray:
    """Indices of the points of one row to keep so that straight moves stay within ``tolerance`` of ``z``.

    Greedy, as OpenCAMLib's line filter: from each kept point the move reaches
    as far as every skipped point lies within ``tolerance`` (vertically) of it.
    The first and last points are always kept.  ``extra`` (per point) is added
    to a skipped point's distance below the chord: the part of the true path's
    bend between samples that they do not show.
    """
    n = len(along)
    if extra is None:
        extra = np.zeros(n)
    keep = [0]
    i = 0
    while i < n - 1:
        lo, hi = i + 1, min(n - 1, i + 2)
        # Grow the reach by doubling, then bisect back to the last good end.
        while hi < n - 1 and _within(along, z, i, hi, tolerance, extra):
            lo, hi = hi, min(n - 1, i + 2 * (hi - i))
        if _within(along, z, i, hi, tolerance, extra):
            lo = hi
        else:
            while hi - lo > 1:
                mid = (lo + hi) // 2
                if _within(along, z, i, mid, tolerance, extra):
                    lo = mid
                else:
                    hi = mid
        keep.append(lo)
        i = lo
    return np.array(keep, dtype=int)


def _within(t, z, i, j, tol, extra):
    if j - i < 2:
        return True
    s = (t[i + 1:j] - t[i]) / (t[j] - t[i])
    dev = z[i + 1:j] - (z[i] + s * (z[j] - z[i]))
    return bool(np.all((-dev <= tol) & (dev + extra[i + 1:j] <= tol)))


def _bend(z: np.ndarray) -> np.ndarray:
    """A quarter of each sample's downward second difference: how far the path between samples may bend below them.

    For a parabola this is half the sag of a move over two samples that the
    middle sample shows; for the square-root onset where a ball starts to
    roll over a box edge it covers the part of the sag the samples miss.
    """
    out = np.zeros(len(z))
    if len(z) > 2:
        out[1:-1] = np.maximum(0.0, -(z[:-2] - 2.0 * z[1:-1] + z[2:])) / 4.0
    return out


def _sag(t, z, keep, extra, kappa):
    """How far the cutter path may rise above each kept move (0 where the move lies above it).

    Returns the estimate and the sag the fine samples show alone.  The
    estimate is the larger of the sag the fine samples show plus their
    ``extra`` bend, and the largest sag they show plus ``kappa * h**2 / 8``,
    the bound of the sag between two samples ``h`` apart of a path that bends
    down no faster than ``kappa``.
    """
    sag = np.zeros(len(keep) - 1)
    seen = np.zeros(len(keep) - 1)
    for m, (i, j) in enumerate(zip(keep[:-1], keep[1:])):
        s = (t[i:j + 1] - t[i]) / (t[j] - t[i])
        dev = z[i:j + 1] - (z[i] + s * (z[j] - z[i]))
        seen[m] = max(0.0, float(dev.max()))
        semi = kappa * float(np.diff(t[i:j + 1]).max()) ** 2 / 8.0
        sag[m] = max(float(np.max(dev[1:-1] + extra[i + 1:j], initial=0.0)), seen[m] + semi)
    return sag, seen


def _cl_mm(surface, ev, r, shape, lift_tip, scale, x, y, **search):
    """Tool-tip heights (mm) over surface positions ``x, y``, as the planner computes them."""
    return (drop_cutter(surface, x, y, r, shape, evaluator=ev, **search) + lift_tip) * scale


_CHECK_SAMPLES = 6  # interior samples of a checked move, at least
_CHECK_ZOOM = 6  # rounds of local refinement around the worst sample
_CHECK_SPLITS = 40  # at most this many rounds of splitting


def _move_dips(cl, ax, ay, az, bx, by, bz, length, radius):
    """Largest height of the true cutter path above each straight move ``a -> b``, where, and the path there.

    Samples the path at evenly spaced interior points (at least
    :data:`_CHECK_SAMPLES`, no further apart than a sixteenth of the tool
    radius unless that takes more than eight times as many), then, where the
    path rises above the move, zooms in around the worst sample.  Returns the
    dip (0 or more, mm), the fraction along the move where it was found and
    the cutter location there (mm).
    """
    m = len(ax)
    if m == 0:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    per_radius = np.ceil(np.minimum(length * 16.0 / max(radius, 1e-300), 8 * _CHECK_SAMPLES))
    n_move = np.maximum(_CHECK_SAMPLES, per_radius).astype(int)
    # Ragged samples as one flat vector: move of each sample and its fraction along the move.
    idx = np.repeat(np.arange(m), n_move)
    start = np.concatenate([[0], np.cumsum(n_move)[:-1]])
    u = (np.arange(idx.size) - start[idx] + 1) / (n_move[idx] + 1)

    def dips(idx, u):
        zc = cl(ax[idx] + u * (bx[idx] - ax[idx]), ay[idx] + u * (by[idx] - ay[idx]))
        return zc - (az[idx] + u * (bz[idx] - az[idx])), zc

    d, zc = dips(idx, u)
    order = np.lexsort((-d, idx))
    first = order[start]  # the worst sample of each move
    best_d, best_u, best_z = d[first], u[first], zc[first]
    # Zoom in where the path rises above the move; elsewhere the samples show it below all along.
    zoom = np.flatnonzero(best_d > 0.0)
    width = 1.0 / (n_move[zoom] + 1)
    offs = np.array([-2.0, -1.0, 1.0, 2.0]) / 3.0
    for _ in range(_CHECK_ZOOM):
        uu = np.clip(best_u[zoom, None] + width[:, None] * offs, 0.0, 1.0)
        d, zc = dips(np.repeat(zoom, len(offs)), uu.ravel())
        d, zc = d.reshape(uu.shape), zc.reshape(uu.shape)
        j = np.argmax(d, axis=1)
        r = np.arange(zoom.size)
        better = d[r, j] > best_d[zoom]
        k = zoom[better]
        best_d[k], best_u[k], best_z[k] = d[r, j][better], uu[r, j][better], zc[r, j][better]
        width = width / 3.0
    return np.maximum(best_d, 0.0), best_u, best_z


def _check_moves(cl, vx, vy, vz, vrow, sag, seen, dense, tol, radius):
    """Check the moves marked ``dense`` against the true cutter path; with a tolerance, split those that dip more.

    The sag of a checked move becomes the larger of the dip found and the sag
    its fine samples show (``seen``).  A move whose sag exceeds ``tol`` gets
    the cutter location at its worst point as a new point, and both halves are
    checked again.  Returns the points and each move's sag.
    """
    check = np.flatnonzero(dense)
    seen = seen[check]
    for _ in range(_CHECK_SPLITS + 1):
        a, b = check, check + 1
        length = np.hypot(vx[b] - vx[a], vy[b] - vy[a])
        d, u, zc = _move_dips(cl, vx[a], vy[a], vz[a], vx[b], vy[b], vz[b], length, radius)
        sag[check] = np.maximum(d, seen)
        if tol is None:
            break
        over = d > tol
        split = check[over]
        if not split.size:
            break
        w = u[over]
        nx = vx[split] + w * (vx[split + 1] - vx[split])
        ny = vy[split] + w * (vy[split + 1] - vy[split])
        vx, vy = np.insert(vx, split + 1, nx), np.insert(vy, split + 1, ny)
        # Few points are added, so their cutter locations get a three times finer, more thorough search.
        vz = np.insert(vz, split + 1, cl(nx, ny, lattice=24, starts=8))
        vrow = np.insert(vrow, split + 1, vrow[split])
        sag = np.insert(sag, split + 1, 0.0)
        moved = split + np.arange(split.size)
        check = np.sort(np.concatenate([moved, moved + 1]))
        seen = np.zeros(check.size)
    return vx, vy, vz, vrow, sag


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
                  evaluator: SurfaceEvaluator | None = None) -> Toolpath:
    """Plan a zig-zag raster of gouge-free cutter locations over the surface.

    Parameters
    ----------
    surface : LagrangeSurface
        The exact surface; lengths in its units become mm by ``settings.scale``.
    tool : Tool
        Cutter shape and diameter (mm).
    raster : RasterSpec
        Direction and steps (mm), or scallop height and chordal tolerance.
    settings : MachineSettings
        Scale, work offset and stock to leave.

    Returns
    -------
    Toolpath

    Examples
    --------
    >>> from lagsym.grid import grid_from_points
    >>> from lagsym.lagrange import lagrange_surface
    >>> s = lagrange_surface(grid_from_points([(0, 0, 1), (0, 1, 1), (1, 0, 1), (1, 1, 1)]))
    >>> tp = plan_toolpath(s, Tool("ball", 0.0), RasterSpec("x", 0.5, 0.5), MachineSettings(scale=1.0))
    >>> tp.points_mm[:, :2].tolist()  # zig-zag: along x, up the edge, back
    [[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [1.0, 0.5], [0.5, 0.5], [0.0, 0.5], [0.0, 1.0], [0.5, 1.0], [1.0, 1.0]]
    >>> bool((tp.points_mm[:, 2] == 1.0).all()), tp.rows.tolist()
    (True, [0, 0, 0, 1, 1, 1, 2, 2, 2])
    """
    ev = evaluator or SurfaceEvaluator(surface)
    scale = settings.scale
    r_mm = tool.radius_mm
    stock = settings.stock_to_leave_mm
    if raster.stepover_mm is not None:
        stepover = raster.stepover_mm
    else:
        if tool.shape != "ball":
            raise ToolpathError("a scallop height (--scallop) needs a ball-end cutter; give --stepover for a flat end")
        stepover = scallop_stepover(r_mm, raster.scallop_mm)
    tol = raster.tolerance_mm
    if raster.step_mm is not None:
        step = raster.step_mm
        fine = step / 4.0 if tol is None else min(step, _tolerance_step(ev, tol, scale))
    else:
        fine = _tolerance_step(ev, tol, scale)
        step = fine
    levels, along = raster_pattern(ev.bounds, raster.direction, stepover / scale, fine / scale)
    emit_every = None
    if tol is None:
        # Fixed forward step: a fine sample halfway along each move measures its sag.
        emit_every = 2
        n = len(_levels(along[0], along[-1], step / scale)) - 1
        along = np.linspace(along[0], along[-1], n * emit_every + 1)
    # Drop the tool over every fine sample of every row and of the links between rows.
    r = (r_mm + (stock if tool.shape == "ball" else 0.0)) / scale
    lift_tip = r - r_mm / scale if tool.shape == "ball" else stock / scale
    a_grid, l_grid = np.meshgrid(along, levels, indexing="xy")  # (rows, along)
    xs, ys = (a_grid, l_grid) if raster.direction == "x" else (l_grid, a_grid)
    z_rows = (drop_cutter(surface, xs, ys, r, tool.shape, evaluator=ev) + lift_tip) * scale  # tool tip, mm
    gap = (levels[1] - levels[0]) if len(levels) > 1 else 0.0
    link_n = max(2, 2 * int(math.ceil(gap * scale / fine / 2)))
    u = np.linspace(0.0, 1.0, link_n + 1)[1:-1]
    ends = np.where(np.arange(len(levels) - 1) % 2 == 0, along[-1], along[0])
    link_a = np.repeat(ends, len(u))
    link_l = (levels[:-1, None] + u[None, :] * gap).ravel()
    lx, ly = (link_a, link_l) if raster.direction == "x" else (link_l, link_a)
    z_links = ((drop_cutter(surface, lx, ly, r, tool.shape, evaluator=ev) + lift_tip) * scale
               if len(link_a) else np.zeros(0)).reshape(len(levels) - 1, len(u))
    # One fine polyline through all rows and links, then the points to emit on it.
    fa, fl, fz, frow, keep = [], [], [], [], []
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
        nxt = row_end + len(u) + 1 if i + 1 < len(levels) else None
        for lo, hi, is_row in ((count, row_end, True), (row_end, nxt, False)):
            if hi is not None:
                keep.append((lo, hi, is_row))
        count = row_end + len(u) + 1 if i + 1 < len(levels) else row_end + 1
    fa, fl, fz, frow = (np.concatenate(v) for v in (fa, fl, fz, frow))
    fx, fy = (fa, fl) if raster.direction == "x" else (fl, fa)
    s_mm = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(fx), np.diff(fy)))]) * scale
    # Where the tool stays clear of the box edges, the cutter path is semi-convex: it bends down
    # no faster than the surface does, so between two samples h apart it sags at most K h**2 / 8.
    kappa = ev.curvature_bound() / scale
    h = np.diff(s_mm)
    semi = kappa * np.maximum(np.concatenate([[0.0], h]), np.concatenate([h, [0.0]])) ** 2 / 8.0
    bend = np.concatenate([_bend(fz[lo:hi + 1])[:-1] for lo, hi, _ in keep] + [[0.0]])
    extra = np.maximum(bend, semi)
    kept = [0]
    for lo, hi, is_row in keep:
        if tol is not None:
            k = filter_rows(s_mm[lo:hi + 1] - s_mm[lo], fz[lo:hi + 1], tol, extra[lo:hi + 1]) + lo
        elif is_row:
            k = np.arange(lo, hi + 1, emit_every)
        else:
            k = np.array([lo, hi])
        kept.extend(int(v) for v in k[1:])
    kept = np.array(kept, dtype=int)
    sag, seen = _sag(s_mm, fz, kept, bend, kappa)
    vx, vy, vz, vrow = fx[kept], fy[kept], fz[kept], frow[kept]
    # Where the tool crosses a box edge across the move, it starts to rest on the edge or a
    # corner and the cutter path can bend down sharply between samples: there each move is
    # checked against the true path.  (An edge along the move cuts the same part off the tool
    # all along it, which leaves the path semi-convex.)
    x0, x1, y0, y1 = ev.bounds
    reach = r * (1 + 1e-9)
    near_x = np.minimum(vx - x0, x1 - vx) < reach
    near_y = np.minimum(vy - y0, y1 - vy) < reach
    dense = (((near_x[:-1] | near_x[1:]) & (vx[:-1] != vx[1:]))
             | ((near_y[:-1] | near_y[1:]) & (vy[:-1] != vy[1:])))
    cl = functools.partial(_cl_mm, surface, ev, r, tool.shape, lift_tip, scale)
    vx, vy, vz, vrow, sag = _check_moves(cl, vx, vy, vz, vrow, sag, seen, dense, tol, r)
    lift = np.zeros(len(vz))
    if len(sag):
        lift[:-1] = sag
        lift[1:] = np.maximum(lift[1:], sag)
    ox, oy, oz = settings.origin_mm
    points = np.stack([vx * scale + ox, vy * scale + oy, vz + lift + oz], axis=1)
    b = ev.bounds
    return Toolpath(
        points_mm=points,
        rows=vrow,
        exact_mm=vz + oz,
        tool=tool,
        raster=raster,
        stepover_mm=float((levels[1] - levels[0]) * scale) if len(levels) > 1 else float(stepover),
        step_mm=float(step),
        bounds_mm=(b[0] * scale + ox, b[1] * scale + ox, b[2] * scale + oy, b[3] * scale + oy),
    )


def _tolerance_step(ev: SurfaceEvaluator, tol: float, scale: float) -> float:
    """A sampling step whose own chordal error on the surface is a quarter of ``tol`` (mm)."""
    kappa = ev.curvature_bound() / scale  # 1/mm
    x0, x1, y0, y1 = ev.bounds
    longest = max(x1 - x0, y1 - y0) * scale
    if kappa <= 0:
        return longest / 4
    return float(min(math.sqrt(2.0 * tol / kappa), longest / 4))
