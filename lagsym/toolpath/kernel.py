"""Drop-cutter's search at each tool position, compiled by Numba: candidates, starts, Newton, pattern search.

:mod:`.dropcutter` states what is computed and :mod:`.newton` the rules of a
ball's Newton steps; this module computes them one tool position at a time in
machine code, compiled by Numba once and kept in its cache beside this file.
One module holds every compiled function: the cache checks the file of the
function it loads, not the files of the functions that one calls.

The candidates of a position, and the eight steps of a pattern-search round,
are evaluated together, a SIMD lane each (:func:`_values`).  The geometry is
one float64 array ``geo``: the evaluator's ``x_offset, x_scale, y_offset,
y_scale``, the box ``x0, x1, y0, y1``, the tool's ``radius, corner``, the
lattice ``spacing`` and ``settle``, the change below which the search has
settled.  The surface is its Chebyshev coefficients ``c[i, j]`` (``T_i(s)
T_j(t)``, normalized ``s, t``), and for Newton those of ``F`` and its partial
derivatives stacked (:func:`.newton.jet_coefficients`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["drop_chunk", "newton_starts"]

_HALF = math.sqrt(0.5)
_STEPS = ((1.0, 0.0, 1.0), (-1.0, 0.0, 1.0), (0.0, 1.0, 1.0), (0.0, -1.0, 1.0), (0.0, 0.0, 1.0), (0.0, 0.0, -1.0),
          (0.0, 0.0, 1.0), (0.0, 0.0, -1.0))  # a pattern-search round: axis steps, then signs along and across
_ROUNDS = 12  # Newton steps at most
_EDGE_POINTS = 16  # four box corners, and three points on each of the four edges
_compiled = njit(cache=True, error_model="numpy")  # no zero check before each division: no divisor here is 0
_inline = njit(cache=True, error_model="numpy", inline="always")  # copied into each caller: constants propagate
_entry = njit(cache=True, nogil=True, error_model="numpy")  # called from Python: threads may run it side by side


@_inline
def _values(c, geo, xs, ys, count, out, work):
    """``F`` at the first ``count`` points ``xs, ys`` into ``out``, summed in the order of
    :meth:`~lagsym.evaluate.SurfaceEvaluator.fast_points`; ``work``: ``n + m + 1`` rows of scratch."""
    n, m = c.shape
    bx, by, w = work[:n], work[n:n + m], work[n + m]
    _basis(bx, xs, geo[0], geo[1], count)
    _basis(by, ys, geo[2], geo[3], count)
    for j in range(m):  # each sum starts from 0.0 (0.0 + -0.0 is 0.0), within its first term's pass
        for i in range(n):
            cij = c[i, j]
            for k in range(count):
                w[k] = (w[k] if i else 0.0) + cij * bx[i, k]
        for k in range(count):
            out[k] = (out[k] if j else 0.0) + w[k] * by[j, k]


@_inline
def _basis(rows, vs, offset, scale, count):
    """Chebyshev polynomials at the first ``count`` points ``vs`` (then normalized), a row each, by their recurrence."""
    for k in range(count):
        rows[0, k] = 1.0
    if rows.shape[0] > 1:
        for k in range(count):
            rows[1, k] = (vs[k] - offset) / scale
    for i in range(2, rows.shape[0]):
        for k in range(count):
            rows[i, k] = 2.0 * rows[1, k] * rows[i - 1, k] - rows[i - 2, k]


@_inline
def _jet(jt, m, geo, x, y, acc, out):
    """``F, F_x, F_y, F_xx, F_xy, F_yy`` at ``(x, y)`` into ``out`` (``jt`` the stacked coefficients transposed,
    ``(n, 6 m)``)."""
    n = jt.shape[0]
    s, t = (x - geo[0]) / geo[1], (y - geo[2]) / geo[3]
    for r in range(6 * m):
        acc[r] = 0.0
    a, b = 1.0, s
    for i in range(n):
        ti = 1.0 if i == 0 else (s if i == 1 else 2.0 * s * b - a)
        if i > 1:
            a, b = b, ti
        for r in range(6 * m):
            acc[r] += jt[i, r] * ti
    for q in range(6):
        out[q] = 0.0
    a, b = 1.0, t
    for k in range(m):
        tk = 1.0 if k == 0 else (t if k == 1 else 2.0 * t * b - a)
        if k > 1:
            a, b = b, tk
        for q in range(6):
            out[q] += acc[q * m + k] * tk


@_inline
def _clip(v, lo, hi):
    return min(max(v, lo), hi)


@_inline
def _project(px, py, cx, cy, geo):
    """A candidate moved into the box, then into the disc: towards the axis where the box holds it, else along
    the line to the box point nearest the axis; ``(x, y, d2)``, ``d2`` the squared distance from the axis.
    Both ways are computed and one kept: with no branch, a loop of projections runs a SIMD lane a point."""
    x0, x1, y0, y1, radius = geo[4], geo[5], geo[6], geo[7], geo[8]
    qx, qy = _clip(px, x0, x1), _clip(py, y0, y1)
    dx, dy = qx - cx, qy - cy
    d2 = dx * dx + dy * dy
    r2 = radius * radius
    ax, ay = _clip(cx, x0, x1), _clip(cy, y0, y1)  # the axis itself where it is over the box
    wx, wy = ax - cx, ay - cy
    ex, ey = qx - ax, qy - ay
    ee = ex * ex + ey * ey
    ee = ee if ee > 0.0 else 1.0
    we = wx * ex + wy * ey
    t = _clip((-we + math.sqrt(max(we * we - ee * (wx * wx + wy * wy - r2), 0.0))) / ee, 0.0, 1.0)
    f = radius / math.sqrt(max(d2, 1e-300))  # kept only where d2 > r2
    beyond = ax != cx or ay != cy
    rx, ry = (ax + t * ex, ay + t * ey) if beyond else (cx + dx * f, cy + dy * f)
    inside = d2 <= r2
    rx, ry = (qx, qy) if inside else (rx, ry)
    dx, dy = rx - cx, ry - cy
    return rx, ry, (d2 if inside else min(dx * dx + dy * dy, r2))


@_compiled
def _edge_point(e, cx, cy, geo):
    """Corner ``e`` of the region under the tool, unprojected: a box corner, an axis's foot or a rim crossing."""
    x0, x1, y0, y1, radius = geo[4], geo[5], geo[6], geo[7], geo[8]
    if e < 4:
        return (x0 if e < 2 else x1), (y0 if e % 2 == 0 else y1)
    side, k = (e - 4) // 3, (e - 4) % 3
    off = 0.0 if k == 0 else (1.0 if k == 1 else -1.0)
    a = (x0, x1, y0, y1)[side]  # the edge x = x0, x1, y = y0 or y1
    w = off * math.sqrt(max(radius * radius - ((cx if side < 2 else cy) - a) ** 2, 0.0))
    return (a, cy + w) if side < 2 else (cx + w, a)


@_compiled
def _candidates(c, geo, cx, cy, offsets, reach2, val, px, py, d2, moved, work):
    """Heights, contact points, squared distances from the axis and whether the box moved each, for the lattice
    and rim (``offsets``, ``reach2`` their squared distances) and the region's corners under the tool at
    ``(cx, cy)``; into ``val, px, py, d2, moved``.  Only a tool over a box edge has its points moved."""
    x0, x1, y0, y1, radius = geo[4], geo[5], geo[6], geo[7], geo[8]
    beyond = (cx < geo[4] or cx > geo[5] or cy < geo[6] or cy > geo[7])
    edge = not beyond and (cx - radius < x0 or cx + radius > x1 or cy - radius < y0 or cy + radius > y1)
    k_all = offsets.shape[0]
    for k in range(k_all if beyond else 0):  # a loop of its own: a SIMD lane a point
        ox, oy = cx + offsets[k, 0], cy + offsets[k, 1]
        px[k], py[k], d2[k] = _project(ox, oy, cx, cy, geo)
        moved[k] = px[k] != ox or py[k] != oy
    for k in range(k_all if beyond else 0, k_all):
        ox, oy = cx + offsets[k, 0], cy + offsets[k, 1]
        if edge:
            qx, qy = _clip(ox, x0, x1), _clip(oy, y0, y1)
            q2 = min((qx - cx) ** 2 + (qy - cy) ** 2, reach2[k])
        else:
            qx, qy, q2 = ox, oy, reach2[k]
        px[k], py[k], d2[k] = qx, qy, q2
        moved[k] = qx != ox or qy != oy
    for e in range(_EDGE_POINTS):
        k = k_all + e
        ex, ey = _edge_point(e, cx, cy, geo)
        px[k], py[k], d2[k] = _project(ex, ey, cx, cy, geo)
        moved[k] = False
    _heights(c, geo, px, py, d2, k_all + _EDGE_POINTS, val, work)


@_inline
def _heights(c, geo, xs, ys, d2, count, out, work):
    """Tip heights of the tool in contact at the first ``count`` points (``d2``: squared distances from the axis)."""
    _values(c, geo, xs, ys, count, out, work)
    radius, corner = geo[8], geo[9]
    if corner <= 0.0:
        return
    flat = radius - corner
    if flat <= 0.0:
        for k in range(count):
            out[k] = out[k] - (radius - math.sqrt(max(radius * radius - d2[k], 0.0)))
    else:
        for k in range(count):
            o = max(math.sqrt(max(d2[k], 0.0)) - flat, 0.0)
            out[k] = out[k] - (corner - math.sqrt(max(corner * corner - o * o, 0.0)))


@_compiled
def _starts(val, px, py, moved, nb, nearest, nlat, starts, apart, tie, rank, top, far, chosen):
    """The candidates the search starts from, into ``chosen``: the best of all, then the best of distinct basins.

    Among the first ``8 starts + 32`` candidates in the order of :func:`_ranked` come, in turn, the first
    :func:`_distinct` from those already chosen, or where none is the next in order.  Those that head no basin
    are ranked only where needed, which is rare.
    """
    many = min(moved.size, 8 * starts + 32)
    count = _ranked(val, moved, nb, nearest, nlat, rank, top, many)
    chosen[0] = top[0]
    far[0] = False
    for t in range(1, count):
        far[t] = True
    for s in range(1, starts):
        pick, t = -1, 0
        while pick < 0:
            if t == count:
                grown = count if count == many else _ranked_rest(val, rank, top, count, many)
                if grown == count:
                    break
                for u in range(count, grown):
                    far[u] = True
                    for q in range(s - 1):
                        far[u] = far[u] and _distinct(val, px, py, top[u], chosen[q], apart, tie)
                count = grown
            if far[t]:
                far[t] = _distinct(val, px, py, top[t], chosen[s - 1], apart, tie)
                if far[t]:
                    pick = t
            t += 1
        if pick < 0:
            if s >= count and count < many:
                count = _ranked_rest(val, rank, top, count, many)
            pick = min(s, count - 1)
        chosen[s] = top[pick]


@_inline
def _distinct(val, px, py, k, q, apart, tie):
    """Whether candidate ``k`` may head another basin than chosen ``q``: ``apart`` from it and not within ``tie`` of
    its height (one as high likely lies on the same plateau, a level box edge, say: where every start went there,
    a basin whose peak lies between the lattice's points was missed)."""
    return math.hypot(px[k] - px[q], py[k] - py[q]) >= apart and abs(val[k] - val[q]) > tie


@_compiled
def _ranked(val, moved, nb, nearest, nlat, rank, top, many):
    """Rank each candidate and put the basins' heads in order into ``top``; how many were put.

    Rank 0: a local maximum (no lattice or rim neighbour higher; the region's
    corners always count) the box did not move, and the best of all; rank 1:
    one the box moved; rank 2: the others.  ``val[-1]`` is -inf: the height
    where ``nb`` names no neighbour (-1).
    """
    w, nrim = moved.size, nearest.size
    best = 0
    for k in range(w):
        if val[k] > val[best]:
            best = k
    for k in range(nlat):
        higher = val[nb[k, 0]]
        for q in range(1, nb.shape[1]):
            higher = max(higher, val[nb[k, q]])
        rank[k] = 2 if higher > val[k] else (1 if moved[k] else 0)
    for r in range(nrim):
        k = nlat + r
        peak = val[k] >= val[k - 1 if r > 0 else k + nrim - 1] and val[k] >= val[k + 1 if r + 1 < nrim else nlat] \
            and val[k] >= val[nearest[r]]
        rank[k] = 2 if not peak else (1 if moved[k] else 0)
    for k in range(nlat + nrim, w):
        rank[k] = 1 if moved[k] else 0
    rank[best] = 0
    count = 0
    for r in range(2):
        first = count
        for k in range(w):
            if rank[k] == r:
                count = _insert(val, top, first, count, many, k)
    return count


@_compiled
def _ranked_rest(val, rank, top, count, many):
    """After the ``count`` basins' heads in ``top``, the other candidates, up to ``many`` in all; how many now."""
    first = count
    for k in range(rank.size):
        if rank[k] == 2:
            count = _insert(val, top, first, count, many, k)
    return count


@_compiled
def _insert(val, top, first, count, many, k):
    """Candidate ``k`` into ``top[first:count]``, kept best first (the earlier of equals first) and ``many`` long
    at most; the new ``count``."""
    if count == many:
        if count == first or not val[k] > val[top[count - 1]]:
            return count
        count -= 1
    t = count
    while t > first and val[top[t - 1]] < val[k]:
        top[t] = top[t - 1]
        t -= 1
    top[t] = k
    return count + 1


@_inline
def _newton_step(jet, px, py, cx, cy, geo):
    """The Newton step of the contact height at ``p``, a coordinate held at a box edge the gradient points out of:
    ``(sx, sy, ok, flat, gain)``, ``ok`` the Hessian negative definite, ``flat`` its eigenvalue nearest 0."""
    x0, x1, y0, y1, radius = geo[4], geo[5], geo[6], geo[7], geo[8]
    fx, fy, fxx, fxy, fyy = jet[1], jet[2], jet[3], jet[4], jet[5]
    dx, dy = px - cx, py - cy
    s = math.sqrt(max(radius * radius - dx * dx - dy * dy, 1e-300))
    s3 = s * s * s
    gx, gy = fx - dx / s, fy - dy / s
    hxx, hxy, hyy = fxx - 1.0 / s - dx * dx / s3, fxy - dx * dy / s3, fyy - 1.0 / s - dy * dy / s3
    hold_x = (px <= x0 and gx < 0) or (px >= x1 and gx > 0)
    hold_y = (py <= y0 and gy < 0) or (py >= y1 and gy > 0)
    det = hxx * hyy - hxy * hxy
    ok = (hold_x and hold_y) or (hyy < 0 if hold_x else (hxx < 0 if hold_y else det > 0 and hxx < 0))
    if not (ok and not hold_x and not hold_y):
        det = 1.0
    sx, sy = -(hyy * gx - hxy * gy) / det, -(hxx * gy - hxy * gx) / det
    one_x = -gx / (hxx if hxx < 0 else -1.0)
    one_y = -gy / (hyy if hyy < 0 else -1.0)
    sx = 0.0 if hold_x else (one_x if hold_y else sx)
    sy = 0.0 if hold_y else (one_y if hold_x else sy)
    half = 0.5 * (hxx + hyy)
    flat = abs(half + math.sqrt(max(half * half - det, 0.0)))
    flat = 1.0 / s if hold_x and hold_y else (abs(hyy) if hold_x else (abs(hxx) if hold_y else flat))
    return sx, sy, ok, flat, 0.5 * (gx * sx + gy * sy)


@_inline
def _contact(jt, m, geo, qx, qy, cx, cy, acc, out):
    """The jet at ``q`` into ``out`` and the ball's tip height in contact there."""
    _jet(jt, m, geo, qx, qy, acc, out)
    radius = geo[8]
    d2 = (qx - cx) ** 2 + (qy - cy) ** 2
    return out[0] + math.sqrt(max(radius * radius - d2, 0.0)) - radius


@_compiled
def _newton(jt, m, geo, px, py, val, cx, cy, acc, jet, qjet):
    """One start's Newton climb (:func:`.newton.newton_ball`): ``(px, py, val, h, done)``, ``h`` the step the
    pattern search starts from."""
    x0, x1, y0, y1, radius, spacing, settle = geo[4], geo[5], geo[6], geo[7], geo[8], geo[10], geo[11]
    r2 = radius * radius * (1.0 - 1e-6)
    if (px - cx) ** 2 + (py - cy) ** 2 >= r2:
        f = 1.0 - min(0.25 * spacing / radius, 0.5)
        qx, qy = _clip(cx + f * (px - cx), x0, x1), _clip(cy + f * (py - cy), y0, y1)
        qv = _contact(jt, m, geo, qx, qy, cx, cy, acc, qjet)
        if (qx - cx) ** 2 + (qy - cy) ** 2 < r2 and qv > val:
            px, py, val = qx, qy, qv
    if (px - cx) ** 2 + (py - cy) ** 2 >= r2:
        return px, py, val, spacing, False
    _jet(jt, m, geo, px, py, acc, jet)
    damp = 1.0
    for _ in range(_ROUNDS):
        sx, sy, ok, flat, gain = _newton_step(jet, px, py, cx, cy, geo)
        if ok and gain <= 0.01 * settle:
            return px, py, val, min(spacing, math.sqrt(16.0 * settle / max(flat, 1e-300))), True
        if not (ok and damp > 1e-3):
            break
        length = math.hypot(sx, sy)
        f = damp * (spacing / length if length > spacing else 1.0)
        qx, qy = _clip(px + f * sx, x0, x1), _clip(py + f * sy, y0, y1)
        qv = _contact(jt, m, geo, qx, qy, cx, cy, acc, qjet)
        if qv >= val and (qx - cx) ** 2 + (qy - cy) ** 2 < r2:
            px, py, val = qx, qy, qv
            for q in range(6):
                jet[q] = qjet[q]
            damp = 1.0
        else:
            damp *= 0.25
    return px, py, val, spacing, False


@_compiled
def _refine(c, geo, px, py, val, cx, cy, h, poll, work, qx, qy, q2, qv):
    """Pattern search from one start: the best contact height found.

    Eight steps a round from ``h``, halved where none climbs or the projection
    shortened the climb to a creep, down to ``1e-9`` of the radius or until no
    neighbour differs by the settling threshold; with ``poll`` (Newton
    converged) until a first round does not climb or a creep gains less than a
    hundredth of that threshold.
    """
    settle = geo[11]
    stop = geo[8] * 1e-9
    for rnd in range(120):
        if not h > stop:
            break
        ox, oy = px - cx, py - cy
        norm = math.hypot(ox, oy)
        erx, ery = (_HALF, _HALF) if norm <= stop else (ox / norm, oy / norm)
        for d in range(8):  # along +x, -x, +y, -y, then along and against the radius, then across it
            a, b, sign = _STEPS[d]
            qx[d], qy[d] = (a, b) if d < 4 else ((erx * sign, ery * sign) if d < 6 else (-ery * sign, erx * sign))
        for d in range(8):  # the steps' projections in a loop of their own: a SIMD lane each
            qx[d], qy[d], q2[d] = _project(px + h * qx[d], py + h * qy[d], cx, cy, geo)
        _heights(c, geo, qx, qy, q2, 8, qv, work)
        j, worst = 0, 0.0
        for d in range(8):
            if qv[d] > qv[j]:
                j = d
            if math.isfinite(qv[d]):
                worst = max(worst, abs(qv[d] - val))
        if qv[j] > val:
            creep, gain = math.hypot(qx[j] - px, qy[j] - py) < 0.25 * h, qv[j] - val
            px, py, val = qx[j], qy[j], qv[j]
            if creep:  # the box or the rim cut the step short: after Newton, settled where it gained next to nothing
                h = 0.5 * h if gain >= 0.01 * settle or not poll else 0.0
        else:
            h *= 0.5
            if worst < settle or (rnd == 0 and poll):
                h = 0.0
    return val


@_entry
def drop_chunk(c, jc, geo, cx, cy, offsets, reach2, nb, nearest, starts, newton):
    """Drop-cutter values (tip heights, no margin) at the tool positions ``cx, cy``.

    ``offsets``, ``reach2``, ``nb`` and ``nearest`` are the lattice and rim
    (:func:`.droplattice._lattice`); ``starts`` candidates are refined, with
    ``newton`` (a ball) first by Newton steps.
    """
    n, m = c.shape
    nlat = nb.shape[0]
    w = offsets.shape[0] + _EDGE_POINTS
    spacing = geo[10]
    val, px, py, d2 = np.empty(w + 1), np.empty(w), np.empty(w), np.empty(w)
    val[w] = -np.inf  # where ``nb`` names no neighbour (-1)
    moved, far = np.zeros(w, dtype=np.bool_), np.zeros(w, dtype=np.bool_)
    rank, top = np.empty(w, dtype=np.int64), np.empty(w, dtype=np.int64)
    work = np.empty((n + m + 1, w))
    qx, qy, q2, qv = np.empty(8), np.empty(8), np.empty(8), np.empty(8)
    acc, jet, qjet = np.empty(6 * m), np.empty(6), np.empty(6)
    jt = jc.T.copy()
    chosen = np.empty(starts, dtype=np.int64)
    out = np.empty(cx.size)
    for p in range(cx.size):
        _candidates(c, geo, cx[p], cy[p], offsets, reach2, val, px, py, d2, moved, work)
        _starts(val, px, py, moved, nb, nearest, nlat, starts, 2.5 * spacing, geo[11], rank, top, far, chosen)
        best = val[chosen[0]]  # the best candidate of all
        for s in range(starts):
            k = chosen[s]
            sx, sy, sv, h, done = px[k], py[k], val[k], spacing, False
            if newton:
                sx, sy, sv, h, done = _newton(jt, m, geo, sx, sy, sv, cx[p], cy[p], acc, jet, qjet)
            best = max(best, _refine(c, geo, sx, sy, sv, cx[p], cy[p], h, done, work, qx, qy, q2, qv))
        out[p] = best
    return out


@_entry
def newton_starts(jc, m, geo, px, py, val, cx, cy, h, done):
    """:func:`_newton` from each start, in place; the search's steps and whether Newton converged into ``h, done``."""
    acc, jet, qjet = np.empty(6 * m), np.empty(6), np.empty(6)
    jt = jc.T.copy()
    for k in range(px.size):
        px[k], py[k], val[k], h[k], done[k] = _newton(jt, m, geo, px[k], py[k], val[k], cx[k], cy[k], acc, jet, qjet)
