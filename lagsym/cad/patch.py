"""Exact B-spline and Bezier patches: the form CAD systems store a surface in.

A :class:`BezierPatch` is ``P(u, v) = sum_ik b_i(s) b_k(t) P_ik`` with the
Bernstein polynomials of its degrees, ``s`` and ``t`` the parameters scaled
onto ``[0, 1]`` from the patch's ``box``.  A :class:`BSplinePatch` is the same
with clamped knot vectors; one span in each direction is a Bezier patch.
Every number is an exact :class:`fractions.Fraction`; floats appear only when
a file is written.

Every patch lagsym builds is a graph over the ``(x, y)`` plane: the x
coordinate of ``P_ik`` depends on ``i`` alone and the y coordinate on ``k``
alone, increasing, so ``x`` is a function of ``u`` and ``y`` of ``v``.  The
lowest height and the volume (:mod:`lagsym.cad.solid`) rest on that.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

__all__ = ["BezierPatch", "BSplinePatch", "de_casteljau", "split_half", "insert_knot"]

Point = tuple[Fraction, Fraction, Fraction]


def de_casteljau(values, t: Fraction):
    """The Bezier polynomial with coefficients ``values`` at ``t`` in ``[0, 1]``, exactly.

    ``values`` may hold numbers or tuples (points); tuples are combined per coordinate.

    Examples
    --------
    >>> de_casteljau([Fraction(0), Fraction(2), Fraction(0)], Fraction(1, 2))
    Fraction(1, 1)
    """
    work = list(values)
    while len(work) > 1:
        work = [_lerp(a, b, t) for a, b in zip(work, work[1:])]
    return work[0]


def _lerp(a, b, t):
    if isinstance(a, tuple):
        return tuple(p + t * (q - p) for p, q in zip(a, b))
    return a + t * (b - a)


def split_half(values) -> tuple[list, list]:
    """The coefficients of the two halves ``[0, 1/2]`` and ``[1/2, 1]`` of a Bezier polynomial.

    Examples
    --------
    >>> split_half([Fraction(0), Fraction(4)])
    ([Fraction(0, 1), Fraction(2, 1)], [Fraction(2, 1), Fraction(4, 1)])
    """
    work = list(values)
    left, right = [work[0]], [work[-1]]
    while len(work) > 1:
        work = [(a + b) / 2 for a, b in zip(work, work[1:])]
        left.append(work[0])
        right.append(work[-1])
    return left, right[::-1]


def insert_knot(knots: tuple[Fraction, ...], degree: int, points: list, t: Fraction) -> tuple[tuple, list]:
    """Boehm's knot insertion: the same curve with ``t`` once more in its knots.

    ``points`` may hold numbers or tuples.  Returns the new knots and points.

    Examples
    --------
    >>> k, p = insert_knot((0, 0, 1, 1), 1, [Fraction(0), Fraction(4)], Fraction(1, 4))
    >>> p
    [Fraction(0, 1), Fraction(1, 1), Fraction(4, 1)]
    """
    span = max(j for j in range(len(knots) - 1) if knots[j] <= t < knots[j + 1])
    mult = sum(1 for k in knots if k == t)
    out = list(points[: span - degree + 1])
    for i in range(span - degree + 1, span - mult + 1):
        alpha = Fraction(t - knots[i]) / (knots[i + degree] - knots[i])
        out.append(_lerp(points[i - 1], points[i], alpha))
    out.extend(points[span - mult:])
    return tuple(knots[: span + 1]) + (t,) + tuple(knots[span + 1:]), out


@dataclass(frozen=True)
class BezierPatch:
    """A tensor-product Bezier patch with exact control points.

    Attributes
    ----------
    degree_u, degree_v : int
        Degrees in the two parameters; there are ``degree + 1`` control points
        in each direction.
    control_points : tuple of tuple of (Fraction, Fraction, Fraction)
        ``control_points[i][k]`` is ``P_ik``, ``i`` along ``u``.
    box : (Fraction, Fraction, Fraction, Fraction)
        ``(u0, u1, v0, v1)``, the parameter domain.
    """

    degree_u: int
    degree_v: int
    control_points: tuple[tuple[Point, ...], ...]
    box: tuple[Fraction, Fraction, Fraction, Fraction]

    def __post_init__(self):
        rows = self.control_points
        if len(rows) != self.degree_u + 1 or any(len(r) != self.degree_v + 1 for r in rows):
            raise ValueError(f"a Bezier patch of degree ({self.degree_u}, {self.degree_v}) needs "
                             f"{self.degree_u + 1} x {self.degree_v + 1} control points")

    def point(self, u, v) -> Point:
        """``P(u, v)`` in exact arithmetic (de Casteljau), ``(u, v)`` in the patch's box."""
        u0, u1, v0, v1 = self.box
        s = (Fraction(u) - u0) / (u1 - u0)
        t = (Fraction(v) - v0) / (v1 - v0)
        return de_casteljau([de_casteljau(row, t) for row in self.control_points], s)

    def heights(self) -> list[list[Fraction]]:
        """The z coordinates of the control points, ``[i][k]``."""
        return [[p[2] for p in row] for row in self.control_points]

    def bspline(self, name: str = "surface") -> BSplinePatch:
        """The same surface as a clamped B-spline of one span over the box."""
        u0, u1, v0, v1 = self.box
        return BSplinePatch(name, self.degree_u, self.degree_v,
                            (u0,) * (self.degree_u + 1) + (u1,) * (self.degree_u + 1),
                            (v0,) * (self.degree_v + 1) + (v1,) * (self.degree_v + 1),
                            self.control_points)


@dataclass(frozen=True)
class BSplinePatch:
    """A clamped tensor-product B-spline patch with exact knots and control points.

    Attributes
    ----------
    name : str
        What the surface is (``"Lagrange"``, ``"Bezier"``, ``"B-spline"``), for files.
    degree_u, degree_v : int
    knots_u, knots_v : tuple of Fraction
        Full knot vectors, each end repeated ``degree + 1`` times.
    control_points : tuple of tuple of (Fraction, Fraction, Fraction)
        ``control_points[i][k]``, ``i`` along ``u``.
    """

    name: str
    degree_u: int
    degree_v: int
    knots_u: tuple[Fraction, ...]
    knots_v: tuple[Fraction, ...]
    control_points: tuple[tuple[Point, ...], ...]

    def __post_init__(self):
        n, m = len(self.control_points), len(self.control_points[0])
        if len(self.knots_u) != n + self.degree_u + 1 or len(self.knots_v) != m + self.degree_v + 1:
            raise ValueError(f"{n} x {m} control points of degree ({self.degree_u}, {self.degree_v}) need "
                             f"{n + self.degree_u + 1} and {m + self.degree_v + 1} knots")

    @property
    def shape(self) -> tuple[int, int]:
        """Number of control points along ``u`` and along ``v``."""
        return len(self.control_points), len(self.control_points[0])

    @property
    def box(self) -> tuple[Fraction, Fraction, Fraction, Fraction]:
        """``(u0, u1, v0, v1)``, the parameter domain."""
        return self.knots_u[0], self.knots_u[-1], self.knots_v[0], self.knots_v[-1]

    @property
    def xy_box(self) -> tuple[Fraction, Fraction, Fraction, Fraction]:
        """``(x0, x1, y0, y1)``: the corners' x and y (the patch is a graph over this box)."""
        p = self.control_points
        return p[0][0][0], p[-1][0][0], p[0][0][1], p[0][-1][1]

    def boundary(self, side: str) -> tuple[int, tuple[Fraction, ...], tuple[Point, ...]]:
        """The boundary curve ``side`` (``"v0"``, ``"u1"``, ``"v1"``, ``"u0"``): degree, knots, points.

        ``"v0"`` is ``P(u, v0)``; each runs in the direction of increasing parameter.
        """
        p = self.control_points
        if side in ("v0", "v1"):
            return self.degree_u, self.knots_u, tuple(row[0 if side == "v0" else -1] for row in p)
        if side in ("u0", "u1"):
            return self.degree_v, self.knots_v, p[0 if side == "u0" else -1]
        raise ValueError(f"boundary {side!r} is not one of v0, u1, v1, u0")

    def bezier_pieces(self) -> list[BezierPatch]:
        """The patch cut at its interior knots into Bezier patches (knot insertion, exact)."""
        # Lines along u are the columns of the net (fixed k); along v, its rows (fixed i).
        cols, knots_u = _to_bezier([list(c) for c in zip(*self.control_points)], self.knots_u, self.degree_u)
        rows, knots_v = _to_bezier([list(r) for r in zip(*cols)], self.knots_v, self.degree_v)
        pu, pv = self.degree_u, self.degree_v
        breaks_u, breaks_v = sorted(set(knots_u)), sorted(set(knots_v))
        pieces = []
        for a in range(len(breaks_u) - 1):
            for b in range(len(breaks_v) - 1):
                net = tuple(tuple(rows[a * pu + i][b * pv: b * pv + pv + 1]) for i in range(pu + 1))
                pieces.append(BezierPatch(pu, pv, net, (breaks_u[a], breaks_u[a + 1], breaks_v[b], breaks_v[b + 1])))
        return pieces


def _to_bezier(lines: list[list], knots: tuple, degree: int) -> tuple[list[list], tuple]:
    """Insert every interior knot of each line up to multiplicity ``degree``."""
    interior = sorted(set(knots[degree + 1: -degree - 1]))
    out = []
    new = knots
    for line in lines:
        new = knots
        for t in interior:
            while sum(1 for k in new if k == t) < degree:
                new, line = insert_knot(new, degree, line, t)
        out.append(line)
    return out, new
