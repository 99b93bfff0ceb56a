"""An independent check of the simulated cut: a ball swept along straight moves over the exact polynomial.

Written for the tests apart from ``lagsym.verify``: the surface is the
polynomial's rational coefficients in the power basis, evaluated by NumPy
(``polyval2d``); the swept ball's lowest point over a point along a move is
found by a golden-section search on the move (the height of the ball's lower
surface over a fixed point is convex along a straight move), not by the
closed form verify uses.  Everything is on a fine grid of points over a
small window, so it is slow and only meant for windows around a defect.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import polynomial as P

GOLDEN = 0.5 * (np.sqrt(5.0) - 1.0)


def polynomial_heights(surface, mm_per_unit, x_mm, y_mm):
    """The machine height of the surface (placed at the origin, ``mm_per_unit`` mm a unit) at points in mm."""
    c = np.array([[float(v) for v in row] for row in surface.coefficients])
    return P.polyval2d(np.asarray(x_mm) / mm_per_unit, np.asarray(y_mm) / mm_per_unit, c) * mm_per_unit


def golden_lowest(height, n, iterations):
    """The least of ``height(t)`` over ``t`` in [0, 1] for ``n`` convex functions at once, by golden sections.

    Each turn keeps one of the two inner points and evaluates one new one;
    the ends of the last bracket and of the move are looked at too.
    Returns the least height and the ``t`` where it was found.
    """
    lo, hi = np.zeros(n), np.ones(n)
    c, d = hi - GOLDEN, lo + GOLDEN
    fc, fd = height(c), height(d)
    for _ in range(iterations):
        left = fc <= fd  # the least lies in [lo, d]: c becomes the upper inner point; else d the lower
        hi, lo = np.where(left, d, hi), np.where(left, lo, c)
        keep, fkeep = np.where(left, c, d), np.where(left, fc, fd)
        new = np.where(left, hi - GOLDEN * (hi - lo), lo + GOLDEN * (hi - lo))
        fnew = height(new)
        c, fc = np.where(left, new, keep), np.where(left, fnew, fkeep)
        d, fd = np.where(left, keep, new), np.where(left, fkeep, fnew)
    ts = (lo, hi, c, d, np.zeros(n), np.ones(n))
    values = np.array([height(lo), height(hi), fc, fd, height(ts[4]), height(ts[5])])
    k = np.argmin(values, axis=0)
    return values[k, np.arange(n)], np.choose(k, ts)


def ball_heights(a, b, radius, px, py):
    """``height(t)``: the ball's lower surface over ``(px, py)`` with its tip at ``a + t (b - a)`` (rows paired).

    Outside the ball's shadow the height rises steeply, so a search still finds the covered part.
    """
    a, b = np.broadcast_to(a, (len(px), 3)), np.broadcast_to(b, (len(px), 3))
    rx, ry, az = px - a[:, 0], py - a[:, 1], a[:, 2] + radius
    dx, dy, dz = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1], b[:, 2] - a[:, 2]
    r2 = radius * radius

    def height(t):
        ex, ey = rx - t * dx, ry - t * dy
        d2 = ex * ex + ey * ey
        return np.where(d2 <= r2, az + t * dz - np.sqrt(np.maximum(r2 - d2, 0.0)),
                        az + t * dz + (np.sqrt(d2) - radius) * 1e6)

    def reach2(t):  # squared plan distance from the point to the tip
        ex, ey = rx - t * dx, ry - t * dy
        return ex * ex + ey * ey

    return height, reach2


def swept_ball_window(moves_a, moves_b, radius, gx, gy, iterations=60):
    """Lowest height of a ball's lower surface (tip positions ``a -> b``) over every point ``(gx[i], gy[j])``.

    ``inf`` where no move passes over a point.  Each move's lowest point is
    searched on the move by golden sections.
    """
    X, Y = np.meshgrid(gx, gy, indexing="ij")
    px, py = X.ravel(), Y.ravel()
    out = np.full(px.shape, np.inf)
    a, b = np.asarray(moves_a, dtype=float), np.asarray(moves_b, dtype=float)
    for k in range(len(a)):
        lo_x, hi_x = min(a[k, 0], b[k, 0]) - radius, max(a[k, 0], b[k, 0]) + radius
        lo_y, hi_y = min(a[k, 1], b[k, 1]) - radius, max(a[k, 1], b[k, 1]) + radius
        near = (px >= lo_x) & (px <= hi_x) & (py >= lo_y) & (py <= hi_y)
        if not near.any():
            continue
        qx, qy = px[near], py[near]
        height, reach2 = ball_heights(a[k], b[k], radius, qx, qy)
        best, t = golden_lowest(height, len(qx), iterations)
        best = np.where(reach2(t) <= radius * radius, best, np.inf)
        out[near] = np.minimum(out[near], best)
    return out.reshape(X.shape)


def window_check(surface, mm_per_unit, moves_a, moves_b, radius, centre, half, step=0.01, box=None):
    """Deepest gouge, most material left (height) and most left normal to the surface over a window, brute force.

    ``centre = (x, y)`` and ``half = (hx, hy)`` in mm; the window is clipped to ``box`` ``(x0, x1, y0, y1)``.
    Returns a dict with ``gouge``, ``left_height``, ``left_normal`` and where each is.
    """
    x0, x1 = centre[0] - half[0], centre[0] + half[0]
    y0, y1 = centre[1] - half[1], centre[1] + half[1]
    if box is not None:
        x0, x1, y0, y1 = max(x0, box[0]), min(x1, box[1]), max(y0, box[2]), min(y1, box[3])
    gx = np.arange(x0, x1 + step / 2, step)
    gy = np.arange(y0, y1 + step / 2, step)
    a, b = np.asarray(moves_a, dtype=float), np.asarray(moves_b, dtype=float)
    near = ((np.minimum(a[:, 0], b[:, 0]) <= x1 + radius) & (np.maximum(a[:, 0], b[:, 0]) >= x0 - radius)
            & (np.minimum(a[:, 1], b[:, 1]) <= y1 + radius) & (np.maximum(a[:, 1], b[:, 1]) >= y0 - radius))
    cut = swept_ball_window(a[near], b[near], radius, gx, gy)
    X, Y = np.meshgrid(gx, gy, indexing="ij")
    s = polynomial_heights(surface, mm_per_unit, X, Y)
    h = 1e-4

    def height(x, y):
        return polynomial_heights(surface, mm_per_unit, x, y)

    sx = (height(X + h, Y) - height(X - h, Y)) / (2 * h)
    sy = (height(X, Y + h) - height(X, Y - h)) / (2 * h)
    above = cut - s
    normal = above / np.sqrt(1.0 + sx * sx + sy * sy)
    gi, li, ni = int(np.argmin(above)), int(np.argmax(above)), int(np.argmax(normal))

    def at(k):
        return float(X.flat[k]), float(Y.flat[k])

    return dict(gouge=max(0.0, -float(above.flat[gi])), gouge_at=at(gi), left_height=float(above.flat[li]),
                left_height_at=at(li), left_normal=float(normal.flat[ni]), left_normal_at=at(ni),
                left_normal_height=float(above.flat[ni]))
