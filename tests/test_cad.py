"""The exact patches: the change to Bernstein form, knot insertion, lowest height, volume.

Every comparison is ``==`` on Fractions.  The patches are checked against
evaluations that share no code with the conversion: the Lagrange surface's own
exact value, a direct Bernstein sum and an exact Cox-de Boor recursion.
"""

from __future__ import annotations

import dataclasses
import random
import subprocess
import sys
from fractions import Fraction
from math import comb

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from lagsym.cad import (
    BezierPatch,
    bernstein_transform,
    bezier_patch,
    cad_patch,
    check_base,
    exact_height,
    insert_knot,
    lowest_height,
    polynomial_volume,
    volume,
)
from lagsym.errors import InputError
from lagsym.grid import grid_from_table
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.surfaces import bezier_surface, bspline_surface

from conftest import EXAMPLES, ROOT

PAPER = [EXAMPLES / f"paper-example-{k}.json" for k in range(1, 5)]
UNEVEN = grid_from_table([0, 3, 4, 9, 12], [-2, Fraction(1, 2), 5, 6],
                         [[1, 4, 2, 0], [3, Fraction(7, 2), -1, 2], [0, 2, 6, 1], [5, 1, 1, 3],
                          [2, 0, 4, Fraction(5, 4)]], source="uneven")


def bernstein_sum(patch: BezierPatch, u, v):
    """``sum_ik b_i(s) b_k(t) P_ik`` written out term by term."""
    u0, u1, v0, v1 = patch.box
    s, t = (Fraction(u) - u0) / (u1 - u0), (Fraction(v) - v0) / (v1 - v0)
    p, q = patch.degree_u, patch.degree_v
    out = [Fraction(0)] * 3
    for i, row in enumerate(patch.control_points):
        for k, point in enumerate(row):
            w = comb(p, i) * s**i * (1 - s) ** (p - i) * comb(q, k) * t**k * (1 - t) ** (q - k)
            out = [o + w * c for o, c in zip(out, point)]
    return tuple(out)


def de_boor(knots, degree, i, t):
    """The B-spline basis function ``N_{i,degree}(t)``, exactly, by the Cox-de Boor recursion (right-closed at the end)."""
    if degree == 0:
        last = knots[i + 1] == knots[-1] and t == knots[-1]
        return Fraction(1) if knots[i] <= t < knots[i + 1] or (last and knots[i] < knots[i + 1]) else Fraction(0)
    out = Fraction(0)
    if knots[i + degree] != knots[i]:
        out += (t - knots[i]) / (knots[i + degree] - knots[i]) * de_boor(knots, degree - 1, i, t)
    if knots[i + degree + 1] != knots[i + 1]:
        out += (knots[i + degree + 1] - t) / (knots[i + degree + 1] - knots[i + 1]) * de_boor(knots, degree - 1, i + 1, t)
    return out


def bspline_value(patch, u, v):
    n, m = patch.shape
    bu = [de_boor(patch.knots_u, patch.degree_u, i, u) for i in range(n)]
    bv = [de_boor(patch.knots_v, patch.degree_v, k, v) for k in range(m)]
    return tuple(sum(bu[i] * bv[k] * patch.control_points[i][k][c] for i in range(n) for k in range(m))
                 for c in range(3))


def rational_points(box, count, seed=0):
    rnd = random.Random(seed)
    x0, x1, y0, y1 = box
    return [(x0 + (x1 - x0) * Fraction(rnd.randint(0, 997), 997), y0 + (y1 - y0) * Fraction(rnd.randint(0, 991), 991))
            for _ in range(count)]


# --- the Lagrange surface as a Bezier patch ----------------------------------------------------------------------------


@pytest.mark.parametrize("path", PAPER, ids=lambda p: p.stem)
def test_bezier_patch_is_the_lagrange_polynomial(path):
    s = lagrange_surface(read_points(path))
    b = bezier_patch(s)
    assert (b.degree_u, b.degree_v) == s.degree and b.box == s.grid.bounds
    for x, y in rational_points(s.grid.bounds, 60):
        assert bernstein_sum(b, x, y) == (x, y, s.exact_value(x, y))
        assert b.point(x, y) == (x, y, s.exact_value(x, y))


@pytest.mark.parametrize("path", PAPER, ids=lambda p: p.stem)
def test_patch_corners_are_the_corner_control_points(path):
    g = read_points(path)
    net = bezier_patch(lagrange_surface(g)).control_points
    n, m = g.shape
    for i, k in ((0, 0), (0, m - 1), (n - 1, 0), (n - 1, m - 1)):
        assert net[0 if i == 0 else -1][0 if k == 0 else -1] == (g.x[i], g.y[k], g.z[i][k])


def test_example_1_control_net():
    """z = x**2 + 3y on [1, 5] x [2, 4]: the middle row of the net is x0 * x1 = 5 plus 3y, not x**2 = 9."""
    net = bezier_patch(lagrange_surface(read_points(EXAMPLES / "paper-example-1.json"))).control_points
    assert [[p[2] for p in row] for row in net] == [[7, 10, 13], [11, 14, 17], [31, 34, 37]]
    assert [row[0][0] for row in net] == [1, 3, 5] and [p[1] for p in net[0]] == [2, 3, 4]


def test_bernstein_transform_of_powers():
    """Column a of the matrix holds the Bernstein coefficients of x**a: the Bernstein sum reproduces x**a."""
    lo, hi = Fraction(-1, 3), Fraction(5, 2)
    a_mat = bernstein_transform(3, lo, hi)
    for a in range(4):
        for x in (lo, hi, Fraction(1, 7), Fraction(2)):
            t = (x - lo) / (hi - lo)
            assert sum(a_mat[i][a] * comb(3, i) * t**i * (1 - t) ** (3 - i) for i in range(4)) == x**a


fractions = st.fractions(min_value=-50, max_value=50, max_denominator=20)


@st.composite
def grids(draw):
    xs = draw(st.lists(fractions, min_size=2, max_size=5, unique=True))
    ys = draw(st.lists(fractions, min_size=2, max_size=5, unique=True))
    return grid_from_table(xs, ys, [[draw(fractions) for _ in ys] for _ in xs])


@given(grids(), st.randoms(use_true_random=False))
def test_bezier_patch_of_any_grid(g, rnd):
    s = lagrange_surface(g)
    b = bezier_patch(s)
    for x, y in rational_points(g.bounds, 5, rnd.randint(0, 10**6)):
        assert bernstein_sum(b, x, y) == (x, y, s.exact_value(x, y))


@given(grids())
def test_exact_volume_two_ways(g):
    s = lagrange_surface(g)
    assert volume(cad_patch(s), Fraction(-3, 7)) == polynomial_volume(s, Fraction(-3, 7))


def test_patch_is_frozen():
    b = bezier_patch(lagrange_surface(UNEVEN))
    with pytest.raises(dataclasses.FrozenInstanceError):
        b.degree_u = 1


# --- the comparison surfaces ---------------------------------------------------------------------------------------------


def test_bezier_comparison_patch_is_the_bezier_surface():
    p = cad_patch(UNEVEN, "bezier")
    ref = bezier_surface(UNEVEN)
    for u, v in rational_points((0, 1, 0, 1), 40):
        assert bspline_value(p, u, v) == bernstein_sum(p.bezier_pieces()[0], u, v)
        assert np.allclose(bernstein_sum(p.bezier_pieces()[0], u, v), ref.evaluate_uv(float(u), float(v)),
                           rtol=0, atol=1e-12)


@pytest.mark.parametrize("degree", [1, 2, 3])
def test_bspline_pieces_are_the_bspline_surface(degree):
    p = cad_patch(UNEVEN, "bspline", degree=degree)
    ref = bspline_surface(UNEVEN, degree)
    pieces = p.bezier_pieces()
    assert len(pieces) == (5 - degree) * (4 - min(degree, 3))
    for u, v in rational_points((0, 1, 0, 1), 40, seed=degree):
        exact = bspline_value(p, u, v)
        piece = next(b for b in pieces if b.box[0] <= u <= b.box[1] and b.box[2] <= v <= b.box[3])
        assert piece.point(u, v) == exact
        assert np.allclose(exact, ref.evaluate_uv(float(u), float(v)), rtol=0, atol=1e-12)


def test_insert_knot_keeps_the_curve():
    knots = (0, 0, 0, Fraction(1, 3), 1, 1, 1)
    points = [Fraction(v) for v in (0, 5, -2, 7)]
    new_knots, new_points = insert_knot(knots, 2, points, Fraction(3, 4))
    assert new_knots == (0, 0, 0, Fraction(1, 3), Fraction(3, 4), 1, 1, 1)
    for t in (Fraction(j, 17) for j in range(18)):
        assert (sum(de_boor(knots, 2, i, t) * c for i, c in enumerate(points))
                == sum(de_boor(new_knots, 2, i, t) * c for i, c in enumerate(new_points)))


def test_unknown_method():
    with pytest.raises(InputError, match="'hermite' is not one of lagrange, bezier, bspline"):
        cad_patch(UNEVEN, "hermite")


# --- lowest height and the base -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("path", PAPER, ids=lambda p: p.stem)
def test_lowest_height_brackets_the_minimum(path):
    s = lagrange_surface(read_points(path))
    b = lowest_height(cad_patch(s))
    heights = [v for row in bezier_patch(s).heights() for v in row]
    lo, hi = min(heights), max(heights)  # the tolerance is 2**-40 of the net's range
    assert b.lower <= b.upper <= b.lower + (hi - lo) / 2**40
    sampled = min(s.exact_value(x, y) for x, y in rational_points(s.grid.bounds, 400))
    corners = min(s.exact_value(x, y) for x in s.grid.bounds[:2] for y in s.grid.bounds[2:])
    assert b.lower <= sampled and b.upper <= min(sampled, corners) + (hi - lo) / 2**40


def test_example_4_dips_below_every_control_point():
    """Example 4's surface overshoots: its lowest height, 0.1508, is below every control height (the least is 1)."""
    b = lowest_height(cad_patch(lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))))
    assert f"{float(b.upper):.10g}" == "0.1507663366" and b.upper < 1


def test_check_base_is_exact_at_an_attained_minimum():
    p = cad_patch(lagrange_surface(read_points(EXAMPLES / "paper-example-1.json")))  # lowest: 7 at (1, 2)
    assert check_base(p, 7 - Fraction(1, 10**30)) == 7 - Fraction(1, 10**30)
    with pytest.raises(InputError, match=r"--base-z 7 is not below the surface, whose lowest height is 7;"):
        check_base(p, 7, "ex1.json")


def test_check_base_names_the_lowest_height():
    p = cad_patch(lagrange_surface(read_points(EXAMPLES / "paper-example-4.json")))
    with pytest.raises(InputError, match=r"^ex4.json: --base-z 0.2 is not below the surface, whose lowest height "
                                         r"is 0.1507663366;"):
        check_base(p, "0.2", "ex4.json")
    assert check_base(p, "0.15") == Fraction(3, 20)


def test_check_base_on_a_bspline_patch():
    p = cad_patch(UNEVEN, "bspline")
    low = lowest_height(p)
    assert check_base(p, low.lower - Fraction(1, 10**20)) < low.lower
    with pytest.raises(InputError):
        check_base(p, low.upper)


@pytest.mark.parametrize("bad", [True, None, "abc", "nan", "inf", [1]])
def test_exact_height_refuses(bad):
    with pytest.raises(InputError):
        exact_height(bad)


def test_exact_height_reads_decimals_exactly():
    assert exact_height("1.06") == Fraction(53, 50) and exact_height(0.1) == Fraction(1, 10)


# --- volume ----------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("path", PAPER, ids=lambda p: p.stem)
def test_volume_from_patch_equals_integral_of_polynomial(path):
    s = lagrange_surface(read_points(path))
    for base in (0, -1, Fraction(-7, 3)):
        assert volume(cad_patch(s), base) == polynomial_volume(s, base)


def test_volume_of_comparison_patches_by_quadrature():
    """The B-spline volume int int z x'(u) y'(v) against Gauss-Legendre on each span (exact for polynomials)."""
    for degree in (1, 2, 3):
        p = cad_patch(UNEVEN, "bspline", degree=degree)
        total = 0.0
        nodes, weights = np.polynomial.legendre.leggauss(8)
        for piece in p.bezier_pieces():
            net = piece.control_points
            xs = [float(row[0][0]) for row in net]
            ys = [float(q[1]) for q in net[0]]
            s = (nodes + 1) / 2
            bu = np.array([[comb(piece.degree_u, i) * t**i * (1 - t) ** (piece.degree_u - i)
                            for i in range(piece.degree_u + 1)] for t in s])
            bv = np.array([[comb(piece.degree_v, k) * t**k * (1 - t) ** (piece.degree_v - k)
                            for k in range(piece.degree_v + 1)] for t in s])
            z = bu @ np.array([[float(q[2]) for q in row] for row in net]) @ bv.T
            dx = _derivative(xs, s)
            dy = _derivative(ys, s)
            total += float((weights / 2) @ (z * dx[:, None] * dy[None, :]) @ (weights / 2))
        assert abs(total - float(volume(p))) <= 1e-12 * abs(total)


def _derivative(nodes, s):
    p = len(nodes) - 1
    d = [nodes[j + 1] - nodes[j] for j in range(p)]
    return np.array([p * sum(d[j] * comb(p - 1, j) * t**j * (1 - t) ** (p - 1 - j) for j in range(p)) for t in s])


def test_import_lagsym_loads_no_cad_kernel():
    code = ("import sys, lagsym, lagsym.cad, lagsym.export.cad, lagsym.cli.export; "
            "bad = [m for m in ('OCP', 'pyvista', 'vtk') if m in sys.modules]; print(bad)")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


@pytest.mark.slow
@given(grids(), st.randoms(use_true_random=False))
def test_lowest_height_of_any_grid(g, rnd):
    s = lagrange_surface(g)
    b = lowest_height(cad_patch(s))
    values = [s.exact_value(x, y) for x, y in rational_points(g.bounds, 20, rnd.randint(0, 10**6))]
    assert b.lower <= b.upper and b.lower <= min(values)
    assert check_base(cad_patch(s), b.lower - Fraction(1, 10**9)) < min(values)
    with pytest.raises(InputError):
        check_base(cad_patch(s), b.upper)


@pytest.mark.parametrize("height", [lambda x, y: (y - 1) ** 2, lambda x, y: (x - y) ** 2], ids=["axis", "diagonal"])
def test_valley_at_a_height_the_search_cannot_reach(height):
    """A minimum along a whole line at non-dyadic parameters: the bounds stay safe and the answer comes quickly."""
    xs, ys = [0, 1, 3], [0, 1, 3]
    p = cad_patch(lagrange_surface(grid_from_table(xs, ys, [[height(x, y) for y in ys] for x in xs])))
    b = lowest_height(p)
    assert b.lower <= 0 <= b.upper
    with pytest.raises(InputError, match="--base-z 0 is not below the surface, whose lowest height is (0|between)"):
        check_base(p, 0)
    assert check_base(p, Fraction(-1, 10**4)) == Fraction(-1, 10**4)
