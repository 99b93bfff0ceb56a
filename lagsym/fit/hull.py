"""The points' convex hull and the share of the box outside it, where a fit extrapolates: exact rationals."""

from __future__ import annotations

from fractions import Fraction

__all__ = ["convex_hull", "polygon_area", "inside_hull"]


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
