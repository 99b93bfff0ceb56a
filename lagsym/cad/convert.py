"""The exact change of basis from lagsym's surfaces to Bezier and B-spline patches.

A tensor-product polynomial ``F(x, y) = sum_ab C[a][b] x**a y**b`` of degree
``(p, q)`` over the box ``[x0, x1] x [y0, y1]`` is exactly a Bezier patch of
the same degrees.  On one axis, with ``x = x0 + h s`` and ``s`` in ``[0, 1]``,

    x**a = sum_k C(a, k) x0**(a - k) h**k s**k          (power of x to power of s)
    s**k = sum_{i >= k} C(i, k) / C(p, k) b_{i,p}(s)      (power of s to Bernstein)

so the Bernstein coefficients of one axis are ``A @ c`` with the rational
matrix ``A = R S`` of those two steps, and the heights of the control net are
``Ax @ C @ Ay.T``, computed with python-flint's exact rational matrices.  The
x coordinates of the net are the evenly spaced ``x0 + h i / p`` (they
reproduce ``x`` itself), likewise y; the knots are the box itself, so the
patch's parameters ``(u, v)`` are ``(x, y)``.

The Bezier and B-spline comparison surfaces (:mod:`lagsym.surfaces`) already
have the control grid as their net; their patches hold it with the knots they
use, on ``[0, 1]``.
"""

from __future__ import annotations

from fractions import Fraction
from math import comb

import flint

from ..errors import InputError
from ..exactsize import ExactClock, stepped_product, to_fraction
from ..lagrange import LagrangeSurface, lagrange_surface
from .patch import BezierPatch, BSplinePatch

__all__ = ["METHODS", "KERNEL_MAX_DEGREE", "bernstein_transform", "bezier_patch", "cad_patch", "double_error_bound",
           "piecewise_patch"]

METHODS = ("lagrange", "bezier", "bspline")
KERNEL_MAX_DEGREE = 25  # OpenCascade's Geom_BSplineSurface::MaxDegree(); several CAD kernels stop there too


def _fmpq(v: Fraction) -> flint.fmpq:
    return flint.fmpq(v.numerator, v.denominator)


def bernstein_transform(degree: int, lo: Fraction, hi: Fraction) -> tuple[tuple[Fraction, ...], ...]:
    """The matrix ``A`` taking power coefficients in ``x`` to Bernstein coefficients on ``[lo, hi]``.

    ``A[i][a]`` is the share of ``x**a`` in the coefficient of ``b_{i,degree}``.

    Examples
    --------
    >>> [[str(v) for v in row] for row in bernstein_transform(1, Fraction(1), Fraction(3))]
    [['1', '1'], ['1', '3']]
    """
    return tuple(tuple(to_fraction(v) for v in row) for row in _transform(degree, Fraction(lo), Fraction(hi)).tolist())


def _transform(degree: int, lo: Fraction, hi: Fraction) -> flint.fmpq_mat:
    size = degree + 1
    h = hi - lo
    s = [[_fmpq(comb(a, k) * lo ** (a - k) * h**k) if a >= k else 0 for a in range(size)] for k in range(size)]
    r = [[_fmpq(Fraction(comb(i, k), comb(degree, k))) if k <= i else 0 for k in range(size)] for i in range(size)]
    return flint.fmpq_mat(r) * flint.fmpq_mat(s)


def bezier_patch(surface: LagrangeSurface) -> BezierPatch:
    """The exact Bezier patch of the Lagrange surface over its control box.

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> s = lagrange_surface(grid_from_table([0, 1, 2], [0, 2], [[0, 0], [1, 1], [4, 4]]))  # z = x**2
    >>> [str(row[0][2]) for row in bezier_patch(s).control_points]
    ['0', '0', '4']
    """
    p, q = surface.degree
    x0, x1, y0, y1 = surface.grid.bounds
    c = flint.fmpq_mat([[_fmpq(v) for v in row] for row in surface.coefficients])
    # Two products as long as the polynomial's own: timed with it, against the command's --max-exact-s.
    clock = ExactClock(f"Bezier form of the surface through {p + 1} x {q + 1} nodes", surface.grid.source)
    left = stepped_product(_transform(p, x0, x1), c, clock=clock, products_after=1)
    z = stepped_product(left, _transform(q, y0, y1).transpose(), clock=clock).entries()
    xs = [x0 + (x1 - x0) * Fraction(i, p) for i in range(p + 1)]
    ys = [y0 + (y1 - y0) * Fraction(k, q) for k in range(q + 1)]
    net = tuple(tuple((xs[i], ys[k], to_fraction(z[i * (q + 1) + k])) for k in range(q + 1)) for i in range(p + 1))
    return BezierPatch(p, q, net, (x0, x1, y0, y1))


def cad_patch(surface, method: str = "lagrange", *, degree: int = 3) -> BSplinePatch:
    """The exact B-spline patch of a surface, for a CAD file.

    Parameters
    ----------
    surface : LagrangeSurface or ControlGrid
        The Lagrange surface, or the control grid the comparison surfaces are built on.
    method : {"lagrange", "bezier", "bspline"}
        ``"lagrange"``: the Lagrange polynomial as a single-span clamped B-spline
        of degree ``(n-1, m-1)`` whose parameters are ``(x, y)``.  ``"bezier"``
        and ``"bspline"``: the comparison surfaces of :mod:`lagsym.surfaces`,
        the control grid as the net, parameters on ``[0, 1]``.
    degree : int
        B-spline degree in each direction, capped at ``n - 1`` (``"bspline"`` only).

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> g = grid_from_table([0, 1, 2, 3], [0, 1], [[0, 1], [1, 2], [0, 1], [1, 2]])
    >>> cad_patch(g, "bspline", degree=2).knots_u
    (Fraction(0, 1), Fraction(0, 1), Fraction(0, 1), Fraction(1, 2), Fraction(1, 1), Fraction(1, 1), Fraction(1, 1))
    """
    from ..surfaces.bspline import clamped_uniform_knots

    if method not in METHODS:
        raise InputError(f"method {method!r} is not one of {', '.join(METHODS)}")
    if method == "lagrange":
        if not isinstance(surface, LagrangeSurface):
            surface = lagrange_surface(surface)
        return bezier_patch(surface).bspline("Lagrange")
    grid = surface.grid if isinstance(surface, LagrangeSurface) else surface
    n, m = grid.shape
    net = tuple(tuple((grid.x[i], grid.y[k], grid.z[i][k]) for k in range(m)) for i in range(n))
    if method == "bezier":
        return BezierPatch(n - 1, m - 1, net, (Fraction(0), Fraction(1), Fraction(0), Fraction(1))).bspline("Bezier")
    if isinstance(degree, bool) or not isinstance(degree, int) or degree < 1:
        raise InputError(f"B-spline degree {degree!r} should be an integer >= 1")
    pu, pv = min(degree, n - 1), min(degree, m - 1)
    return BSplinePatch("B-spline", pu, pv, clamped_uniform_knots(n, pu), clamped_uniform_knots(m, pv), net)


def double_error_bound(patch: BSplinePatch, data_range) -> float:
    """A bound on how far the surface a CAD kernel evaluates from the file may lie from the exact one.

    Relative to ``data_range``.  Rounding each control point to the nearest
    double moves the surface by at most half a unit in the last place of the
    largest coordinate (the basis is non-negative and sums to one), and a
    stable evaluation (de Boor) adds about one such rounding per degree.  The
    Bernstein coefficients of a high-degree interpolant can be far larger than
    the surface, which is what makes this grow.

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> g = grid_from_table([0, 1, 2], [0, 1], [[0, 0], [1, 1], [4, 4]])
    >>> double_error_bound(cad_patch(g), 4) < 1e-15
    True
    """
    largest = max(abs(float(p[2])) for row in patch.control_points for p in row)
    return (1 + patch.degree_u + patch.degree_v) * 2.0**-53 * largest / (float(data_range) or 1.0)


def piecewise_patch(surface) -> BSplinePatch:
    """A piecewise surface (:mod:`lagsym.surfaces.piecewise`) as one bicubic B-spline with its knots at the borders.

    Every interior node is a double knot (multiplicity 2 in degree 3: C1, as
    the pieces join), so one span is one piece and its Bezier net is the
    piece's: the net holds each piece's inner control points, and the points
    on a border, which the C1 join puts on the line between their
    neighbours, are left out, as knot removal leaves them.  The parameters
    ``(u, v)`` are ``(x, y)``.

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> from lagsym.surfaces.piecewise import piecewise_surface
    >>> g = grid_from_table([0, 1, 2, 3], [0, 1, 2], [[x * x + y for y in range(3)] for x in range(4)])
    >>> p = piecewise_patch(piecewise_surface(g))
    >>> [str(k) for k in p.knots_u], p.shape
    (['0', '0', '0', '0', '1', '1', '2', '2', '3', '3', '3', '3'], (8, 6))
    """
    g = surface.grid
    n, m = surface.shape
    w = [[Fraction(comb(j, a), comb(3, a)) if a <= j else Fraction(0) for a in range(4)] for j in range(4)]

    def spans(count):  # net index -> (piece, Bezier index): b0 of the first, b1 b2 of each, b3 of the last
        return [(0, 0)] + [(i, j) for i in range(count) for j in (1, 2)] + [(count - 1, 3)]

    nets = {}
    for i in range(n):
        for k in range(m):
            a = surface.local_coefficients(i, k)
            nets[i, k] = [[sum((w[j][p] * a[p][q] * w[l][q] for p in range(4) for q in range(4)), Fraction(0))
                           for l in range(4)] for j in range(4)]
    su, sv = spans(n), spans(m)
    net = tuple(tuple((g.x[i] + (g.x[i + 1] - g.x[i]) * Fraction(j, 3), g.y[k] + (g.y[k + 1] - g.y[k]) * Fraction(l, 3),
                       nets[i, k][j][l]) for k, l in sv) for i, j in su)
    knots_u = (g.x[0],) * 4 + tuple(v for v in g.x[1:-1] for _ in (0, 1)) + (g.x[-1],) * 4
    knots_v = (g.y[0],) * 4 + tuple(v for v in g.y[1:-1] for _ in (0, 1)) + (g.y[-1],) * 4
    return BSplinePatch("Piecewise", 3, 3, knots_u, knots_v, net)
