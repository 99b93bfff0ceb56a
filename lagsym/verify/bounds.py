"""Gouge and material left between the cell centres: bounded from the safe side, whatever the cell.

The height map holds the cut at the cell centres only; a cusp or a dent
between them would be missed.  Two facts close the gap.

**Material left** is bounded from above on every triangle of the grid (each
square of four neighbouring centres split along its diagonal).  Over one
straight move the lowest height of the tool's lower surface, ``E_k(p)``, is
a convex function of the point ``p`` on the set the tool covers (the profile
is convex and increasing in the distance, the distance convex in the point
and the move's position, and a minimum over a convex set of a jointly convex
function is convex).  So on a triangle whose three corners the move covers,
``E_k`` lies below the plane through its corner values, and the cut (the
lowest over all moves) below the lowest of those planes over the moves
tried: the moves that are lowest at the square's four corners.  The surface
lies above the plane through its own corner values less ``M rho**2 / 2``,
``M`` the largest curvature of the surface (the largest eigenvalue of its
Hessian, sampled at every cell centre with a quarter added) and ``rho`` the
triangle's circumradius.  What is left over the triangle is at most the
highest point of the lowest of the planes of ``E_k - S``, a small linear
game solved exactly (at the triangle's corners, where two planes cross an
edge, or where three meet), plus that curvature term.  Measured normal to
the surface it is multiplied by the largest cosine of the slope angle over
the triangle (the slope at the corners less the curvature times the
circumradius).  A square whose bound is above the figure already reached
is split ``SPLIT`` x ``SPLIT`` and bounded again with the same moves (near
the rim of a ball on a steep flank the swept tool curves sharply, and a
plane through corners a cell apart lies well above it).

**Gouge** is found at the critical points: from every cell centre, for the
move lowest there and those lowest at its four neighbours, Newton's method
climbs surface minus tool (``S - E_k``, its derivatives the surface's own
and the swept tool's by central differences) to its highest point within
the centre's cell, in :data:`NEWTON_STEPS` steps, and the depth is evaluated
exactly there.  Every depth reported is the surface minus the swept tool at
a real point on a real move, so a gouge is never invented.  This is a search,
not a bound: it finds the tangency points where a gouge is deepest, and the
tests hold it against a brute-force sweep at 0.01 mm.
"""

from __future__ import annotations

import numpy as np

from .swept import lowest_along, lowest_in_frame, move_frames

__all__ = ["curvature_limits", "left_bound", "deepest_cut", "NEWTON_STEPS", "CURVATURE_MARGIN"]

NEWTON_STEPS = 4  # Newton steps from each cell centre towards the highest point of surface minus tool
CURVATURE_MARGIN = 1.25  # the largest sampled curvature of the surface, with a quarter added
_BIG = 1.0e30  # stands for a move that does not cover a corner
SPLIT = 8  # squares whose bound is above the figure reached are split SPLIT x SPLIT
_SPLIT_BATCH = 256  # squares split at a time
_NODES_AT_ONCE = 32768  # cell centres searched from at a time
_SQUARES_AT_ONCE = 65536  # squares bounded at a time (memory: some hundred bytes each)
_CORNERS = ((0, 0), (1, 0), (0, 1), (1, 1))
_TRIANGLES = ((0, 1, 3), (0, 2, 3))  # each square cut along its diagonal from its first corner


def curvature_limits(ev, sx, sy, mm_per_unit: float) -> tuple[float, float]:
    """The surface's largest curvature (largest Hessian eigenvalue, 0 at least) and largest absolute one, per mm.

    Sampled at the cell centres ``sx`` x ``sy`` (surface units), times :data:`CURVATURE_MARGIN`.
    """
    gx, gy = np.meshgrid(sx, sy, indexing="ij")
    x, y = gx.ravel(), gy.ravel()
    fxx, fxy, fyy = ev.fast_points(x, y, dx=2), ev.fast_points(x, y, dx=1, dy=1), ev.fast_points(x, y, dy=2)
    mid, rad = 0.5 * (fxx + fyy), np.sqrt(0.25 * (fxx - fyy) ** 2 + fxy * fxy)
    top = max(float(np.max(mid + rad)), 0.0)
    most = float(np.max(np.abs(mid) + rad))
    return CURVATURE_MARGIN * top / mm_per_unit, CURVATURE_MARGIN * most / mm_per_unit


def _game(d):
    """``max over l in the simplex of min over k of sum_v l_v d[k, v]`` for ``d`` of shape ``(K, 3, n)``.

    Returns the value and the barycentric point ``(3, n)`` where it is reached.
    """
    K, _, n = d.shape
    best = np.full(n, -np.inf)
    where = np.zeros((3, n))

    def consider(lam):
        nonlocal best, where
        val = np.min(np.einsum("kvn,vn->kn", d, lam), axis=0)
        ok = np.all(lam >= -1e-12, axis=0) & np.isfinite(val)
        better = ok & (val > best)
        best = np.where(better, val, best)
        where = np.where(better[None], lam, where)

    eye = np.eye(3)
    for v in range(3):
        consider(np.repeat(eye[:, v:v + 1], n, axis=1))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for p in range(K):
            for q in range(p + 1, K):
                diff = d[p] - d[q]
                for v1, v2 in ((0, 1), (1, 2), (0, 2)):
                    a, b = diff[v1], diff[v2]
                    t = a / (a - b)
                    t = np.where((a * b <= 0.0) & (a != b), t, -1.0)
                    lam = np.zeros((3, n))
                    lam[v1], lam[v2] = 1.0 - t, t
                    consider(lam)
                for s in range(q + 1, K):
                    # l . (d[p] - d[q]) = 0, l . (d[p] - d[s]) = 0, sum l = 1.
                    m = np.stack([d[p] - d[q], d[p] - d[s], np.ones((3, n))], axis=0).transpose(2, 0, 1)
                    det = np.linalg.det(m)
                    good = np.abs(det) > 1e-300
                    lam = np.zeros((n, 3))
                    if good.any():
                        rhs = np.zeros((int(good.sum()), 3, 1))
                        rhs[:, 2, 0] = 1.0
                        lam[good] = np.linalg.solve(m[good], rhs)[:, :, 0]
                    lam[~good] = -1.0
                    consider(lam.T)
    return best, where


def left_bound(cut, surf, winner, moves, grid, *, curvature, cosine, skip_below, surface_at, inner, split=SPLIT):
    """The most material left over the triangles of the grid, bounded from above; see the module.

    ``moves = (a, b)`` the moves the ``winner`` map indexes, ``grid = (xs, ys,
    r, corner)``, ``curvature = (slope, M, Mabs)``: the surface's slope at the
    centres and :func:`curvature_limits`; ``cosine(slope)`` the normal factor
    of a slope; ``surface_at(x_mm, y_mm)`` the surface's height and slope at
    points; ``inner`` the centres the scallop is measured over; ``skip_below``
    a normal figure already reached at a cell centre inside: triangles whose
    bound is below it are not refined.  Triangles whose bound
    is above it are split ``split`` x ``split`` and bounded again with the
    same moves.  Returns ``(normal, height, x, y, i, j)`` over the triangles
    solved (flat arrays), ``(i, j)`` the square's first corner.
    """
    xs, ys, r, corner = grid
    a_all, b_all = moves
    slope_at, m_top, m_abs = curvature
    nx, ny = cut.shape
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    out, lost_keys, lost_moves = [], [], []
    rows = max(1, _SQUARES_AT_ONCE // max(ny - 1, 1))
    for i0 in range(0, nx - 1, rows):
        i, j = np.meshgrid(np.arange(i0, min(i0 + rows, nx - 1)), np.arange(ny - 1), indexing="ij")
        i, j = i.ravel(), j.ravel()
        w = np.stack([winner[i + di, j + dj] for di, dj in _CORNERS])  # (4 candidates, squares)
        # E_k - S at the four corners for the four candidate moves.
        d = np.full((4, 4, len(i)), _BIG)
        for c, (di, dj) in enumerate(_CORNERS):
            for k in range(4):
                ok = w[k] >= 0
                if ok.any():
                    e = lowest_along(a_all[w[k][ok]], b_all[w[k][ok]], xs[i[ok] + di], ys[j[ok] + dj], r, corner)
                    d[k, c, ok] = np.where(np.isfinite(e), e - surf[i[ok] + di, j[ok] + dj], _BIG)
        extra = np.full((8, len(i)), -1, dtype=np.int64)
        for t, tri in enumerate(_TRIANGLES):
            dt = d[:, list(tri), :]
            ids = w.copy()
            lost = np.flatnonzero(~(dt < _BIG).all(axis=1).any(axis=0))
            if len(lost):
                # No move lowest at a corner covers the whole triangle: try those lowest at the 32 centres around.
                dt[:, :, lost], extra[4 * t:4 * t + 4, lost] = _wider(lost, tri, (i, j), (cut, surf, winner), moves,
                                                                      grid)
                ids[:, lost] = extra[4 * t:4 * t + 4, lost]
            slope = np.min(np.stack([slope_at[i + _CORNERS[v][0], j + _CORNERS[v][1]] for v in tri]), axis=0)
            # The convex bound: the lowest over the moves of their highest corner.
            cheap = np.min(np.where((dt < _BIG).all(axis=1), dt.max(axis=1), _BIG), axis=0)
            cheap = _raise(cheap, slope, (hx, hy), (m_top, m_abs), cosine)[0]
            k = np.flatnonzero((cheap > skip_below) | (cheap >= _BIG))
            if not len(k):
                continue
            vx = np.stack([xs[i[k] + _CORNERS[v][0]] for v in tri])
            vy = np.stack([ys[j[k] + _CORNERS[v][1]] for v in tri])
            normal, height, px, py = _solve(dt[:, :, k], vx, vy, slope[k], cell=(hx, hy), curvature=(m_top, m_abs),
                                            cosine=cosine, ids=ids[:, k])
            out.append([normal, height, px, py, i[k], j[k]])
        wide = (extra >= 0).any(axis=0)
        lost_keys.append(i[wide] * (ny - 1) + j[wide])
        lost_moves.append(extra[:, wide])
    if not out:
        return tuple(np.zeros(0) for _ in range(6))
    found = tuple(np.concatenate(p) for p in zip(*out))
    extra = (np.concatenate(lost_keys), np.concatenate(lost_moves, axis=1))
    return _refine(found, extra, winner, moves, grid, surface_at=surface_at, split=split,
                   curvature=(m_top, m_abs), cosine=cosine, skip_below=skip_below, inner=inner)


def _refine(found, extra, winner, moves, grid, *, surface_at, split, curvature, cosine, skip_below, inner):
    """Split the squares whose bound is above the figure reached, highest first, and bound them again.

    A square whose bound is below the highest bound already final cannot
    change the figure (nor, inside, the scallop's), so it is left whole.
    """
    normal, height, px, py, ti, tj = found
    m_top, m_abs = curvature
    nx, ny = winner.shape
    sny = ny - 1
    key = ti * sny + tj
    sq_inner = inner[:-1, :-1] & inner[1:, :-1] & inner[:-1, 1:] & inner[1:, 1:]
    top = np.full(sny * (nx - 1), -np.inf)
    np.maximum.at(top, key, normal)
    order = np.argsort(-top)
    order = order[top[order] > skip_below]
    final_all = final_in = skip_below
    s0 = 0
    while s0 < len(order):
        part = order[s0:s0 + _SPLIT_BATCH]
        s0 += _SPLIT_BATCH
        need = top[part] > np.where(sq_inner.ravel()[part], final_in, final_all)
        # A square with a corner the tool never reached is left whole: all of it is left there.
        need &= np.all([winner[part // sny + di, part % sny + dj] >= 0 for di, dj in _CORNERS], axis=0)
        part = np.sort(part[need])
        if not len(part):
            continue
        more = _extra_at(extra, part)
        for group in (part[~(more >= 0).any(axis=0)], part[(more >= 0).any(axis=0)]):
            if not len(group):
                continue
            si, sj = group // sny, group % sny
            cand = np.stack([winner[si + di, sj + dj] for di, dj in _CORNERS])
            if (_extra_at(extra, group) >= 0).any():
                cand = np.concatenate([cand, _extra_at(extra, group)])
            fine = _split(si, sj, cand, moves, grid, surface_at=surface_at, split=split,
                          curvature=(m_top, m_abs), cosine=cosine)
            normal, height, px, py, ti, tj = _replace((normal, height, px, py, ti, tj), key, group, fine)
            key = ti * sny + tj
            final_all = max(final_all, float(fine[0].max()))
            ins = sq_inner.ravel()[group]
            if ins.any():
                final_in = max(final_in, float(fine[0][ins].max()))
    return normal, height, px, py, ti, tj


def _extra_at(extra, keys):
    """The moves tried beyond the corners' for the squares ``keys`` (``(8, n)``, -1 where none): ``extra``
    holds them as ``(squares, moves)`` for the few squares that needed them."""
    held, moves = extra
    at = np.clip(np.searchsorted(held, keys), 0, max(len(held) - 1, 0))
    found = (at < len(held)) & (held[at] == keys) if len(held) else np.zeros(len(keys), dtype=bool)
    return np.where(found[None, :], moves[:, at] if len(held) else -1, -1)


def _replace(found, key, group, fine):
    """The bounds ``found`` (normal, height, x, y, i, j; ``key`` their squares) with the squares ``group`` split:
    each square's coarse triangles give way to the highest of its small ones (``fine``), and a square none
    of whose small triangles a move tried covers keeps its coarse bound."""
    normal = found[0]
    mine = np.isin(key, group)
    lost = ~np.isfinite(fine[1])
    if lost.any():
        best_of = {}
        for q in np.flatnonzero(mine):
            if int(key[q]) not in best_of or normal[q] > normal[best_of[int(key[q])]]:
                best_of[int(key[q])] = q
        src = np.array([best_of[int(v)] for v in group[lost]])
        for f, v in zip(fine[:4], found[:4]):
            f[lost] = v[src]
    return tuple(np.concatenate([v[~mine], f]) for v, f in zip(found, fine))


def _raise(value, slope, cell, curvature, cosine):
    """A bound of ``E_k - S`` at the corners turned into one over the triangle: plus the surface's curvature
    term, times the largest cosine over it.  Returns the normal figure and the height."""
    hx, hy = cell
    m_top, m_abs = curvature
    height = np.where(value < _BIG / 2, value + m_top * (hx * hx + hy * hy) / 8.0, np.inf)
    return height * cosine(np.maximum(slope - m_abs * 0.5 * np.hypot(hx, hy), 0.0)), height


def _solve(d, vx, vy, slope, *, cell, curvature, cosine, ids):
    """The bound over triangles: ``d`` ``(K, 3, n)`` is ``E_k - S`` at their corners ``(vx, vy)`` ``(3, n)``
    for the moves ``ids`` ``(K, n)``; a move met twice, or not covering a corner, is left out."""
    valid = (d < _BIG).all(axis=1) & (ids >= 0)
    for k in range(1, len(ids)):
        valid[k] &= ~(ids[:k] == ids[k]).any(axis=0)
    # The games of one, two, ... moves are solved apart: most triangles see one or two.
    order = np.argsort(~valid, axis=0, kind="stable")
    d = np.take_along_axis(d, order[:, None, :], axis=0)
    count = valid.sum(axis=0)
    val, lam = np.full(d.shape[2], _BIG), np.zeros((3, d.shape[2]))
    for kv in range(1, len(ids) + 1):
        cols = np.flatnonzero(count == kv)
        if len(cols):
            val[cols], lam[:, cols] = _game(d[:kv, :, cols])
    normal, height = _raise(val, slope, cell, curvature, cosine)
    return normal, height, (lam * vx).sum(axis=0), (lam * vy).sum(axis=0)


def _split(si, sj, cand, moves, grid, *, surface_at, split, curvature, cosine):
    """Squares ``(si, sj)`` split ``split`` x ``split``, each small triangle bounded with the moves ``cand``
    ``(K, n)`` (-1: none); returns the highest small triangle of each square (infinite where none covers one)."""
    xs, ys, r, corner = grid
    a_all, b_all = moves
    hx, hy = (xs[1] - xs[0]) / split, (ys[1] - ys[0]) / split
    n = len(si)
    w = cand
    K = len(w)
    u = np.arange(split + 1)
    gu, gv = np.meshgrid(u, u, indexing="ij")
    gu, gv = gu.ravel(), gv.ravel()  # the small nodes of a square
    px = xs[si][None, :] + gu[:, None] * hx
    py = ys[sj][None, :] + gv[:, None] * hy
    s, slope = surface_at(px.ravel(), py.ravel())
    s, slope = s.reshape(px.shape), slope.reshape(px.shape)
    d = np.full((K,) + px.shape, _BIG)
    for k in range(K):
        ok = w[k] >= 0
        if ok.any():
            e = lowest_along(a_all[w[k][ok]], b_all[w[k][ok]], px[:, ok], py[:, ok], r, corner)
            d[k][:, ok] = np.where(np.isfinite(e), e - s[:, ok], _BIG)
    node = (gu * (split + 1) + gv).reshape(split + 1, split + 1)
    corners = []
    for a in range(split):
        for b in range(split):
            for tri in _TRIANGLES:
                corners.append([node[a + _CORNERS[v][0], b + _CORNERS[v][1]] for v in tri])
    corners = np.array(corners)  # (small triangles, 3)
    m = len(corners)
    dt = d[:, corners, :].transpose(0, 2, 1, 3).reshape(K, 3, m * n)  # (K, 3, triangle-major)
    vx = px[corners].transpose(1, 0, 2).reshape(3, m * n)
    vy = py[corners].transpose(1, 0, 2).reshape(3, m * n)
    sl = slope[corners].min(axis=1).reshape(m * n)
    normal, height, qx, qy = _solve(dt, vx, vy, sl, cell=(hx, hy), curvature=curvature, cosine=cosine,
                                    ids=np.tile(w, (1, m)))
    normal, height = normal.reshape(m, n), height.reshape(m, n)
    qx, qy = qx.reshape(m, n), qy.reshape(m, n)
    top = np.argmax(normal, axis=0)
    cols = np.arange(n)
    return normal[top, cols], height[top, cols], qx[top, cols], qy[top, cols], si, sj


def _wider(lost, tri, ij, maps, moves, grid):
    """``E_k - S`` at the triangle's corners for the four moves, among those lowest at the 6 x 6 centres around
    the square, that cover the triangle and have the lowest highest corner (``_BIG`` where fewer do); and
    those moves (-1 where fewer)."""
    i, j = (v[lost] for v in ij)
    cut, surf, winner = maps
    xs, ys, r, corner = grid
    a_all, b_all = moves
    nx, ny = cut.shape
    corners = ((0, 0), (1, 0), (0, 1), (1, 1))
    cand = np.stack([winner[np.clip(i + di, 0, nx - 1), np.clip(j + dj, 0, ny - 1)]
                     for di in range(-2, 4) for dj in range(-2, 4)])
    d = np.full((len(cand), 3, len(i)), _BIG)
    for v, c in enumerate(tri):
        di, dj = corners[c]
        for k in range(len(cand)):
            ok = cand[k] >= 0
            e = lowest_along(a_all[cand[k][ok]], b_all[cand[k][ok]], xs[i[ok] + di], ys[j[ok] + dj], r, corner)
            d[k, v, ok] = np.where(np.isfinite(e), e - surf[i[ok] + di, j[ok] + dj], _BIG)
    cheap = np.where((d < _BIG).all(axis=1), d.max(axis=1), _BIG)
    order = np.argsort(cheap, axis=0)[:4]
    chosen = np.where(np.take_along_axis(cheap, order, axis=0) < _BIG, np.take_along_axis(cand, order, axis=0), -1)
    return np.take_along_axis(d, order[:, None, :], axis=0), chosen


def deepest_cut(ev, placement, cut, surf, winner, *, moves, grid):
    """The deepest the moves go below the surface, at the critical points near the cell centres; see the module.

    Returns ``(depth, (x, y), move)``: the surface minus the swept tool at the
    highest point found (negative where the tool stays above everywhere), and
    the index of the move that reaches it.
    """
    xs, ys = grid[0], grid[1]
    ny = cut.shape[1]
    reached = np.isfinite(cut)
    if not reached.any():
        return -np.inf, (float(xs[0]), float(ys[0])), -1
    g = np.where(reached, surf - cut, -np.inf)
    k0 = int(np.argmax(g))
    best = (float(g.flat[k0]), (float(xs[k0 // ny]), float(ys[k0 % ny])), int(winner.flat[k0]))
    all_i, all_j = np.nonzero(reached)
    for s0 in range(0, len(all_i), _NODES_AT_ONCE):
        found = _climb(ev, placement, all_i[s0:s0 + _NODES_AT_ONCE], all_j[s0:s0 + _NODES_AT_ONCE], winner,
                       moves=moves, grid=grid)
        if found[0] > best[0]:
            best = found
    return best


def _climb(ev, placement, ii, jj, winner, *, moves, grid):
    """Newton from the centres ``(ii, jj)`` for the moves lowest there and at their four neighbours: the
    highest surface minus tool found, where, and the move (see the module)."""
    xs, ys, r, corner = grid
    a_all, b_all = moves
    nx, ny = winner.shape
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    # The moves lowest at each centre and at its four neighbours, each once.
    cand = [winner[ii, jj]]
    for di, dj in ((-1, 0), (1, 0), (0, -1), (0, 1)):
        w = winner[np.clip(ii + di, 0, nx - 1), np.clip(jj + dj, 0, ny - 1)]
        seen = np.zeros(len(ii), dtype=bool)
        for c in cand:
            seen |= w == c
        cand.append(np.where(seen, -1, w))
    node = np.concatenate([np.flatnonzero(c >= 0) for c in cand])
    move = np.concatenate([c[c >= 0] for c in cand])
    frame = move_frames(a_all[move], b_all[move])
    cx, cy = xs[ii[node]], ys[jj[node]]
    px, py = cx.copy(), cy.copy()
    lo_x, hi_x = np.maximum(cx - hx / 2, xs[0]), np.minimum(cx + hx / 2, xs[-1])
    lo_y, hi_y = np.maximum(cy - hy / 2, ys[0]), np.minimum(cy + hy / 2, ys[-1])
    scale = placement.mm_per_unit
    step = 1e-3 * min(hx, hy)
    for _ in range(NEWTON_STEPS):
        sx, sy = placement.to_surface(px, py)
        s_x, s_y = ev.fast_points(sx, sy, dx=1), ev.fast_points(sx, sy, dy=1)
        s_xx = ev.fast_points(sx, sy, dx=2) / scale
        s_xy = ev.fast_points(sx, sy, dx=1, dy=1) / scale
        s_yy = ev.fast_points(sx, sy, dy=2) / scale
        e = {(i, j): lowest_in_frame(frame, px + i * step, py + j * step, r, corner)
             for i, j in ((0, 0), (1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1))}
        e_x, e_y = (e[1, 0] - e[-1, 0]) / (2 * step), (e[0, 1] - e[0, -1]) / (2 * step)
        e_xx = (e[1, 0] - 2 * e[0, 0] + e[-1, 0]) / step**2
        e_yy = (e[0, 1] - 2 * e[0, 0] + e[0, -1]) / step**2
        e_xy = (e[1, 1] - e[1, 0] - e[0, 1] + 2 * e[0, 0] - e[-1, 0] - e[0, -1] + e[-1, -1]) / (2 * step * step)
        # Newton on surface minus tool, its Hessian made negative definite; kept within the centre's cell.
        gx, gy = s_x - e_x, s_y - e_y
        hxx, hxy, hyy = s_xx - e_xx, s_xy - e_xy, s_yy - e_yy
        top = 0.5 * (hxx + hyy) + np.sqrt(0.25 * (hxx - hyy) ** 2 + hxy * hxy)
        shift = np.maximum(top + 1e-3 / r, 0.0)
        hxx, hyy = hxx - shift, hyy - shift
        det = hxx * hyy - hxy * hxy
        with np.errstate(invalid="ignore", divide="ignore"):
            dx, dy = -(hyy * gx - hxy * gy) / det, -(-hxy * gx + hxx * gy) / det
        ok = np.isfinite(dx) & np.isfinite(dy)
        px = np.where(ok, np.clip(px + np.where(ok, dx, 0.0), lo_x, hi_x), px)
        py = np.where(ok, np.clip(py + np.where(ok, dy, 0.0), lo_y, hi_y), py)
    sx, sy = placement.to_surface(px, py)
    depth = placement.height_mm(ev.fast_points(sx, sy)) - lowest_in_frame(frame, px, py, r, corner)
    depth = np.where(np.isfinite(depth), depth, -np.inf)
    if not len(depth):
        return -np.inf, (0.0, 0.0), -1
    k = int(np.argmax(depth))
    return float(depth[k]), (float(px[k]), float(py[k])), int(move[k])
