"""The points' convex hull and the share of the box outside it, where a fit extrapolates: exact rationals."""

from __future__ import annotations

from fractions import Fraction

__all__ = ["convex_hull", "convex_hull_integers", "polygon_area", "inside_hull"]

_SPAN = 1 << 30  # integer spans whose cross products fit 64 bits: the interior is dropped in whole arrays


def _cross(o, a, b) -> Fraction:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def convex_hull(points) -> tuple[tuple[Fraction, Fraction], ...]:
    """The convex hull of ``(x, y)`` points, counter-clockwise, exact (Andrew's monotone chain).

    Examples
    --------
    >>> convex_hull([(0, 0), (2, 0), (1, 1), (2, 2), (0, 2)])
    ((0, 0), (2, 0), (2, 2), (0, 2))
    """
    pts = sorted(set(points))
    if len(pts) <= 2:
        return tuple(pts)
    lower: list = []
    for p in pts:
        while len(lower) >= 2 and _cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list = []
    for p in reversed(pts):
        while len(upper) >= 2 and _cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return tuple(lower[:-1] + upper[:-1])


def convex_hull_integers(xs: list[int], ys: list[int]) -> tuple[tuple[int, int], ...]:
    """:func:`convex_hull` of the integer points ``(xs[k], ys[k])``, the same vertices in the same order.

    Many points first lose those strictly inside the polygon of their extreme
    points (least and greatest ``x``, ``y``, ``x + y`` and ``x - y``): no such
    point is a vertex.  The test is exact in 64-bit integers when the spans
    are below 2**30; else every point goes to :func:`convex_hull`.

    Examples
    --------
    >>> convex_hull_integers([0, 2, 1, 2, 0, 1], [0, 0, 1, 2, 2, 2])
    ((0, 0), (2, 0), (2, 2), (0, 2))
    """
    import numpy as np

    if len(xs) < 64:
        return convex_hull(list(zip(xs, ys)))
    x0, y0 = min(xs), min(ys)
    if max(xs) - x0 >= _SPAN or max(ys) - y0 >= _SPAN:
        return convex_hull(list(zip(xs, ys)))
    x, y = np.array(xs, dtype=np.int64) - x0, np.array(ys, dtype=np.int64) - y0
    extreme = {int(f(v)) for v in (x, y, x + y, x - y) for f in (np.argmin, np.argmax)}
    polygon = convex_hull([(int(x[k]), int(y[k])) for k in extreme])
    keep = np.ones(len(x), dtype=bool)
    if len(polygon) >= 3:
        inside = np.ones(len(x), dtype=bool)
        for (ax, ay), (bx, by) in zip(polygon, polygon[1:] + polygon[:1]):
            inside &= (bx - ax) * (y - ay) - (by - ay) * (x - ax) > 0
        keep = ~inside
    return convex_hull([(xs[k], ys[k]) for k in np.flatnonzero(keep).tolist()])


def polygon_area(vertices) -> Fraction:
    """The exact area of a simple polygon (shoelace), 0 for fewer than 3 vertices."""
    if len(vertices) < 3:
        return Fraction(0)
    s = sum((Fraction(a[0]) * b[1] - Fraction(b[0]) * a[1]
             for a, b in zip(vertices, vertices[1:] + vertices[:1])), Fraction(0))
    return abs(s) / 2


def inside_hull(hull, point) -> bool:
    """Whether ``point`` lies in the counter-clockwise convex polygon ``hull`` (its border included)."""
    if len(hull) < 3:
        return False
    return all(_cross(a, b, point) >= 0 for a, b in zip(hull, hull[1:] + hull[:1]))
