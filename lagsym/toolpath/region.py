"""The region under the tool: candidate contact points moved into the box and the disc, and the region's corners.

Drop-cutter (:mod:`.dropcutter`) takes the surface inside the control points'
box only; the region under a tool centred over ``c`` is the box and the disc
of the tool's radius about ``c``, both convex.  :func:`project` moves points
into it, :func:`edge_points` gives the points on its boundary a maximum may
sit at (box corners, feet of perpendiculars, rim crossings).
"""

from __future__ import annotations

import numpy as np

__all__ = ["project", "edge_points"]


def project(px, py, cx, cy, radius, box):
    """Move candidate contact points into the region under the tool: the box, then the disc.

    With the axis inside the box, a point outside the disc is pulled towards
    the axis onto the rim (the box is convex and holds the axis).  With the
    axis beyond the box (``--boundary past``), it is pulled along the line to
    the box point nearest the axis (in both, the two being convex) until it
    meets the rim.  Candidates are ``(positions, k)`` arrays, the axis
    ``(positions, 1)``; only the rows with a point outside the disc take the
    second step.
    """
    x0, x1, y0, y1 = box
    px = np.minimum(np.maximum(px, x0), x1)
    py = np.minimum(np.maximum(py, y0), y1)
    dx, dy = px - cx, py - cy
    d2 = dx * dx + dy * dy
    over = d2 > radius * radius
    if not np.any(over):
        return px, py, d2
    rows = np.flatnonzero(over.any(axis=1))  # px, py and d2 are this call's own arrays: changed in place
    cx, cy = np.broadcast_to(cx, px.shape), np.broadcast_to(cy, px.shape)
    px[rows], py[rows], d2[rows] = _onto_disc(px[rows], py[rows], dx[rows], dy[rows], d2[rows], over[rows],
                                              cx[rows], cy[rows], radius, box)
    return px, py, d2


def _onto_disc(px, py, dx, dy, d2, over, cx, cy, radius, box):
    """The second step of :func:`project`, for the points in the box ``over`` the rim (all arrays one shape)."""
    x0, x1, y0, y1 = box
    beyond = np.broadcast_to((cx < x0) | (cx > x1) | (cy < y0) | (cy > y1), px.shape)
    radial = over & ~beyond
    if np.any(radial):
        f = np.where(radial, radius / np.sqrt(np.where(radial, d2, 1.0)), 1.0)
        px, py = cx + dx * f, cy + dy * f
    line = over & beyond
    if np.any(line):
        cxb, cyb = np.broadcast_to(cx, px.shape)[line], np.broadcast_to(cy, px.shape)[line]
        ax, ay = np.clip(cxb, x0, x1), np.clip(cyb, y0, y1)
        wx, wy = ax - cxb, ay - cyb
        ex, ey = px[line] - ax, py[line] - ay
        ee = ex * ex + ey * ey
        ee = np.where(ee > 0, ee, 1.0)
        we = wx * ex + wy * ey
        t = (-we + np.sqrt(np.maximum(we * we - ee * (wx * wx + wy * wy - radius * radius), 0.0))) / ee
        t = np.clip(t, 0.0, 1.0)
        px, py = px.copy(), py.copy()
        px[line], py[line] = ax + t * ex, ay + t * ey
    dx, dy = px - cx, py - cy
    return px, py, np.minimum(dx * dx + dy * dy, radius * radius)


def edge_points(cx, cy, radius, box):
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
