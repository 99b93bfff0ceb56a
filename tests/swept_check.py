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

        def height(t):
            cx, cy = a[k, 0] + t * (b[k, 0] - a[k, 0]), a[k, 1] + t * (b[k, 1] - a[k, 1])
            cz = a[k, 2] + t * (b[k, 2] - a[k, 2])
            d2 = (qx - cx) ** 2 + (qy - cy) ** 2
            # Outside the ball's shadow the height rises steeply, so the search still finds the covered part.
            return np.where(d2 <= radius * radius, cz + radius - np.sqrt(np.maximum(radius * radius - d2, 0.0)),
                            cz + radius + (np.sqrt(d2) - radius) * 1e6)

        lo, hi = np.zeros(len(qx)), np.ones(len(qx))
        for _ in range(iterations):
            m1, m2 = hi - GOLDEN * (hi - lo), lo + GOLDEN * (hi - lo)
            left = height(m1) <= height(m2)
            hi, lo = np.where(left, m2, hi), np.where(left, lo, m1)
        best = np.minimum(np.minimum(height(lo), height(hi)), np.minimum(height(np.zeros(len(qx))),
                                                                         height(np.ones(len(qx)))))
        d2best = np.full(len(qx), np.inf)
        for t in (lo, hi, np.zeros(len(qx)), np.ones(len(qx))):
            cx, cy = a[k, 0] + t * (b[k, 0] - a[k, 0]), a[k, 1] + t * (b[k, 1] - a[k, 1])
            d2best = np.minimum(d2best, (qx - cx) ** 2 + (qy - cy) ** 2)
        best = np.where(d2best <= radius * radius, best, np.inf)
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
