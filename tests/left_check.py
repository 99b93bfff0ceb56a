"""An independent check of the material a ball leaves, along lines across its passes, on the exact polynomial.

Written for the tests apart from lagsym: the surface is the polynomial's
rational coefficients in the power basis evaluated by NumPy
(:func:`swept_check.polynomial_heights`), its slope and curvature by central
differences of that; the swept ball's lowest point over a query point along
each straight move is found by golden sections (it is convex along the
move), for every move that passes within the ball's radius of the point.  A
line of points a few micrometres apart crosses the cusps between passes, so
their peaks are seen; the material left is the height of the swept ball's
lower surface above the surface, times the cosine of the slope (normal to
the surface).  Moves that cannot come lower than a height the ball surely
reaches over a point are not searched for it.
"""

from __future__ import annotations

import numpy as np

from swept_check import ball_heights, golden_lowest, polynomial_heights

_BATCH = 200_000  # pairs of move and point per golden-section search


def _pairs(a, b, radius, qx, qy):
    """Per group of up to 64 moves: the pairs of move and point within the radius of the move's plan line.

    Yields the moves' ends of each pair, the point's index, and the lower and
    upper bounds of the ball's lowest height over the point along the move:
    at least the lower end's height with the ball's profile at the plan
    distance, and at most the height over the point where the axis passes
    nearest (a real position on the move).
    """
    r2 = radius * radius
    for s in range(0, len(a), 64):
        ma, mb = a[s:s + 64], b[s:s + 64]
        # Only the points within the radius of the group's plan box can be within it of a move of the group.
        lo = np.minimum(ma[:, :2], mb[:, :2]).min(axis=0) - radius
        hi = np.maximum(ma[:, :2], mb[:, :2]).max(axis=0) + radius
        near = np.flatnonzero((qx >= lo[0]) & (qx <= hi[0]) & (qy >= lo[1]) & (qy <= hi[1]))
        if not near.size:
            continue
        d = mb[:, :2] - ma[:, :2]
        dd = np.maximum((d * d).sum(axis=1), 1e-300)
        rx, ry = qx[None, near] - ma[:, 0:1], qy[None, near] - ma[:, 1:2]
        t0 = np.clip((rx * d[:, 0:1] + ry * d[:, 1:2]) / dd[:, None], 0.0, 1.0)
        ex, ey = rx - t0 * d[:, 0:1], ry - t0 * d[:, 1:2]
        e2 = ex * ex + ey * ey
        mi, ni = np.nonzero(e2 <= r2)
        if not mi.size:
            continue
        qi = near[ni]
        rise = radius - np.sqrt(r2 - e2[mi, ni])
        low = np.minimum(ma[mi, 2], mb[mi, 2]) + rise
        high = ma[mi, 2] + t0[mi, ni] * (mb[mi, 2] - ma[mi, 2]) + rise
        yield ma[mi], mb[mi], qi, low, high


def swept_lowest(points_mm, radius, qx, qy, iterations=48):
    """The lowest height a ball's lower surface reaches over each ``(qx[i], qy[i])`` following ``points_mm``.

    ``inf`` where no move passes within the radius.  A first pass puts over
    each point the height the ball surely reaches there (where some axis
    passes nearest); the golden-section search then runs only for the moves
    whose lower bound is below that.
    """
    p = np.asarray(points_mm, dtype=float)
    a, b = p[:-1], p[1:]
    qx, qy = np.asarray(qx, dtype=float), np.asarray(qy, dtype=float)
    out = np.full(qx.shape, np.inf)
    lo_x, hi_x = qx.min() - radius, qx.max() + radius
    lo_y, hi_y = qy.min() - radius, qy.max() + radius
    near = ((np.maximum(a[:, 0], b[:, 0]) >= lo_x) & (np.minimum(a[:, 0], b[:, 0]) <= hi_x)
            & (np.maximum(a[:, 1], b[:, 1]) >= lo_y) & (np.minimum(a[:, 1], b[:, 1]) <= hi_y))
    a, b = a[near], b[near]
    for _, _, qi, _, high in _pairs(a, b, radius, qx, qy):
        np.minimum.at(out, qi, high)
    # The pairs that may come lower, searched in large batches (one search's NumPy calls serve many pairs).
    todo = [(ma[keep], mb[keep], qi[keep]) for ma, mb, qi, low, _ in _pairs(a, b, radius, qx, qy)
            for keep in [low < out[qi]] if keep.any()]
    if not todo:
        return out
    ma, mb, qi = (np.concatenate(v) for v in zip(*todo))
    for s in range(0, len(qi), _BATCH):
        part = slice(s, s + _BATCH)
        height, _ = ball_heights(ma[part], mb[part], radius, qx[qi[part]], qy[qi[part]])
        best, _ = golden_lowest(height, len(qi[part]), iterations)
        np.minimum.at(out, qi[part], best)
    return out


def surface_frame(surface, mm_per_unit, qx, qy, h=1e-3):
    """Height, slope factor ``sqrt(1 + |grad|**2)`` and the larger principal curvature (1/mm, + a hollow) at points."""
    def f(x, y):
        return polynomial_heights(surface, mm_per_unit, x, y)

    z = f(qx, qy)
    fx = (f(qx + h, qy) - f(qx - h, qy)) / (2 * h)
    fy = (f(qx, qy + h) - f(qx, qy - h)) / (2 * h)
    fxx = (f(qx + h, qy) - 2 * z + f(qx - h, qy)) / (h * h)
    fyy = (f(qx, qy + h) - 2 * z + f(qx, qy - h)) / (h * h)
    fxy = (f(qx + h, qy + h) - f(qx + h, qy - h) - f(qx - h, qy + h) + f(qx - h, qy - h)) / (4 * h * h)
    w = np.sqrt(1 + fx * fx + fy * fy)
    # Shape operator of a graph: II / I; its larger eigenvalue.
    E, F, G = 1 + fx * fx, fx * fy, 1 + fy * fy
    L, M, N = fxx / w, fxy / w, fyy / w
    det = E * G - F * F
    H = (E * N - 2 * F * M + G * L) / (2 * det)
    K = (L * N - M * M) / det
    k1 = H + np.sqrt(np.maximum(H * H - K, 0.0))
    return z, w, k1


def left_normal(surface, mm_per_unit, points_mm, radius, qx, qy):
    """Material left normal to the surface at each query point (mm; negative: a gouge), and the hollow curvature."""
    cut = swept_lowest(points_mm, radius, qx, qy)
    z, w, k1 = surface_frame(surface, mm_per_unit, qx, qy)
    return (cut - z) / w, k1
