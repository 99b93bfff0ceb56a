"""The contours of waterline finishing: levels spaced from the slope, marching squares, bracketing, thinning.

:mod:`.waterline` states what is computed; ``f`` is its grid of cutter
locations (``xs, ys, z, dz``) and ``drop`` its tip heights at surface
positions.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["crossings_at_least", "CROSSING_POINTS", "BISECTIONS", "contour_passes"]

BISECTIONS = 10
"""A crossing is bracketed to the width this many halvings of its grid edge leave (about 0.00025 mm)."""


_FALSE_POSITIONS = 2  # steps of false position before the last, a pair of points
CROSSING_POINTS = _FALSE_POSITIONS + 2  # the fewest drop-cutter points one crossing takes


def _levels(f, steep: np.ndarray, d0: float) -> list[float]:
    """Contour heights (mm) walked down the steep parts, each step the smallest allowed between it and the next."""
    z, dz = f.z[steep], f.dz[steep]
    if not z.size:
        return []
    top, bottom = float(z.max()), float(z.min())
    out: list[float] = []
    start = top
    while True:
        step = d0
        for _ in range(64):  # the step shrinks to the smallest allowed in the band it spans
            new = float(np.min(dz[(z <= start) & (z >= start - step)], initial=np.inf))
            if new >= step:
                break
            step = new
        level = start - (0.5 * step if not out else step)
        if level <= bottom:
            return out
        out.append(level)
        start = level


def crossings_at_least(f, steep: np.ndarray, d0: float) -> int:
    """A lower bound of the level crossings the contours of the steep region find, before the levels are walked.

    Every step between levels is at most ``d0`` and the levels run from the
    top of the steep region to within ``d0`` of its bottom, so a grid edge
    between two steep nodes rising ``Δz`` crosses at least ``floor(Δz / d0)``.
    """
    n = 0
    for axis in (0, 1):
        both = steep[:-1, :] & steep[1:, :] if axis == 0 else steep[:, :-1] & steep[:, 1:]
        rise = np.abs(np.diff(f.z, axis=axis))[both]
        n += int(np.floor(rise / d0).sum())
    return n


def contour_passes(drop, f, steep: np.ndarray, d0: float, tol: float, kappa: float, *, mpu: float,
                    milling: str, counter=None):
    """The contours of the steep region at every level, as passes ``(points (n, 3), closed)``; and the levels."""
    levels = _levels(f, steep, d0)
    nx, ny = f.z.shape
    edges = []  # (level index, edge id, low node, high node)
    for li, level in enumerate(levels):
        above = f.z > level
        for axis in (0, 1):
            a = above[:-1, :] if axis == 0 else above[:, :-1]
            b = above[1:, :] if axis == 0 else above[:, 1:]
            sa = steep[:-1, :] if axis == 0 else steep[:, :-1]
            sb = steep[1:, :] if axis == 0 else steep[:, 1:]
            i, j = np.nonzero((a != b) & sa & sb)
            i2, j2 = (i + 1, j) if axis == 0 else (i, j + 1)
            low_first = ~a[i, j]
            lo = np.where(low_first, i * ny + j, i2 * ny + j2)
            hi = np.where(low_first, i2 * ny + j2, i * ny + j)
            eid = axis * nx * ny + i * ny + j
            edges.append(np.stack([np.full(i.size, li), eid, lo, hi], axis=1))
    if not edges or not sum(len(e) for e in edges):
        return [], levels
    e = np.concatenate(edges)
    gx, gy = np.meshgrid(f.xs, f.ys, indexing="ij")
    gx, gy = gx.ravel(), gy.ravel()
    lev = np.array(levels)[e[:, 0]]
    fz = f.z.ravel()
    lx, ly = _crossings(drop, (gx[e[:, 2]], gy[e[:, 2]], fz[e[:, 2]]), (gx[e[:, 3]], gy[e[:, 3]], fz[e[:, 3]]), lev,
                        counter)
    where = {(int(li), int(eid)): k for k, (li, eid) in enumerate(e[:, :2])}
    passes = []
    for li, level in enumerate(levels):
        for chain, closed in _chains(f.z > level, steep, nx, ny, li, where):
            pts = np.stack([lx[chain], ly[chain], np.full(len(chain), level)], axis=1)
            if len(pts) < 2:
                continue
            pts = _oriented(pts, f, milling)
            keep = _thinned(pts[:, :2], tol / mpu, closed)
            passes.append((pts[keep], closed, ("contour", li)))
    steps = [-d for d in np.diff(levels)] if len(levels) > 1 else [0.0]
    return passes, steps


def _crossings(drop, low, high, lev, counter=None):
    """Where each grid edge from ``low = (lx, ly, zl)`` (tip height ``zl`` at or below ``lev``) to
    ``high = (hx, hy, zh)`` (``zh`` above it) crosses the level: the low end of a bracket of the exact crossing at most ``2**-BISECTIONS`` of the edge
    wide, as many bisections would leave it.

    The bracket is narrowed by steps of false position on the drop-cutter
    values (the last a pair of points that width apart about its estimate),
    then halved where it is still wider; the low end stays at or below the
    level: the tool there clears the surface.
    """
    (lx, ly, zl), (hx, hy, zh) = low, high
    width = 0.5 ** BISECTIONS
    ul, uh = np.zeros(len(lev)), np.ones(len(lev))

    def at(u):
        n = len(u) // len(lev)  # one or two points an edge
        z = drop(np.tile(lx, n) + u * np.tile(hx - lx, n), np.tile(ly, n) + u * np.tile(hy - ly, n))
        if counter is not None:
            counter.add(len(u))
        return z

    def narrowed(u, z, ul, uh, zl, zh):
        up = z > lev
        return np.where(up, ul, u), np.where(up, u, uh), np.where(up, zl, z), np.where(up, z, zh)

    def estimate():
        return ul + np.clip((lev - zl) / (zh - zl), 0.0, 1.0) * (uh - ul)

    for _ in range(_FALSE_POSITIONS):
        u = np.clip(estimate(), ul + 0.01 * (uh - ul), uh - 0.01 * (uh - ul))
        ul, uh, zl, zh = narrowed(u, at(u), ul, uh, zl, zh)
    u = estimate()
    lo = np.clip(u - 0.5 * width, ul, uh)
    hi = np.clip(lo + width, ul, uh)
    lo = np.clip(hi - width, ul, uh)
    z = at(np.concatenate([lo, hi]))
    up_lo, up_hi = z[:len(lo)] > lev, z[len(lo):] > lev
    ul, uh = np.where(up_lo, ul, np.where(up_hi, lo, hi)), np.where(up_lo, lo, np.where(up_hi, hi, uh))
    for _ in range(BISECTIONS):  # the bracket is at most the whole edge: as many halvings bring it to ``width``
        wide = np.flatnonzero(uh - ul > width * (1 + 1e-9))
        if not wide.size:
            break
        m = 0.5 * (ul[wide] + uh[wide])
        zm = drop(lx[wide] + m * (hx[wide] - lx[wide]), ly[wide] + m * (hy[wide] - ly[wide]))
        if counter is not None:
            counter.add(len(m))
        up = zm > lev[wide]
        ul[wide], uh[wide] = np.where(up, ul[wide], m), np.where(up, m, uh[wide])
    return lx + ul * (hx - lx), ly + ul * (hy - ly)


def _chains(above: np.ndarray, steep: np.ndarray, nx: int, ny: int, li: int, where: dict):
    """Marching squares over the cells with every corner in the steep region: chains of crossing indices.

    Yields ``(indices, closed)``; a closed chain repeats its first index at
    the end.  A saddle cell is split by the sign of its corners' mean.
    """
    ok = steep[:-1, :-1] & steep[1:, :-1] & steep[:-1, 1:] & steep[1:, 1:]
    a00, a10, a01, a11 = above[:-1, :-1], above[1:, :-1], above[:-1, 1:], above[1:, 1:]
    mixed = ok & ~((a00 == a10) & (a00 == a01) & (a00 == a11))
    link: dict[int, list[int]] = {}
    for i, j in zip(*np.nonzero(mixed)):
        # The cell's edges: bottom (x, j), top (x, j+1), left (y, i), right (y, i+1).
        sides = [i * ny + j, i * ny + j + 1, nx * ny + i * ny + j, nx * ny + (i + 1) * ny + j]
        crossed = [where[(li, s)] for s in sides if (li, s) in where]
        if len(crossed) == 2:
            pairs = [tuple(crossed)]
        elif len(crossed) == 4:
            b, t, lft, r = crossed
            centre = (int(a00[i, j]) + int(a10[i, j]) + int(a01[i, j]) + int(a11[i, j])) >= 2
            # Join the crossings around the corners on the side the centre is not on.
            pairs = [(b, r), (t, lft)] if centre == bool(a00[i, j]) else [(b, lft), (t, r)]
        else:
            continue
        for p, q in pairs:
            link.setdefault(p, []).append(q)
            link.setdefault(q, []).append(p)
    seen = set()
    ends = [k for k, v in link.items() if len(v) == 1]
    for start in ends + list(link):
        if start in seen:
            continue
        chain, prev, cur = [start], None, start
        seen.add(start)
        while True:
            nxt = [n for n in link[cur] if n != prev and (n not in seen or (n == start and len(chain) > 2))]
            if not nxt:
                break
            prev, cur = cur, nxt[0]
            chain.append(cur)
            if cur == start:
                break
            seen.add(cur)
        yield np.array(chain), len(chain) > 2 and chain[-1] == chain[0]


def _oriented(pts: np.ndarray, f, milling: str) -> np.ndarray:
    """The contour run with the material (uphill) on its right for climb milling, on its left for conventional."""
    i = np.clip(np.searchsorted(f.xs, pts[:, 0]), 1, len(f.xs) - 1)
    j = np.clip(np.searchsorted(f.ys, pts[:, 1]), 1, len(f.ys) - 1)
    zx = f.z[i, j] - f.z[i - 1, j] + f.z[i, j - 1] - f.z[i - 1, j - 1]
    zy = f.z[i, j] - f.z[i, j - 1] + f.z[i - 1, j] - f.z[i - 1, j - 1]
    tx, ty = np.gradient(pts[:, 0]), np.gradient(pts[:, 1])
    right = float(np.sum(zx * ty - zy * tx))  # uphill against the right-hand normal (ty, -tx)
    return pts if (right >= 0) == (milling == "climb") else pts[::-1]


def _thinned(xy: np.ndarray, tol: float, closed: bool) -> np.ndarray:
    """Indices kept by Douglas-Peucker: every dropped point within ``tol`` of its chord in plan."""
    n = len(xy)
    keep = np.zeros(n, dtype=bool)
    keep[0] = keep[-1] = True
    if closed and n > 3:
        keep[n // 2] = True
    stack = [(0, n // 2), (n // 2, n - 1)] if closed and n > 3 else [(0, n - 1)]
    while stack:
        a, b = stack.pop()
        if b - a < 2:
            continue
        d = xy[b] - xy[a]
        length = math.hypot(*d)
        rel = xy[a + 1:b] - xy[a]
        dist = np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0]) / length if length > 0 else np.hypot(*rel.T)
        k = int(np.argmax(dist))
        if dist[k] > tol:
            m = a + 1 + k
            keep[m] = True
            stack += [(a, m), (m, b)]
    return np.flatnonzero(keep)
