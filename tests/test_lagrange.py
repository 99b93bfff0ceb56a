"""The exact Lagrange core: the paper's examples and the defining properties."""

from __future__ import annotations

from fractions import Fraction

import pytest
import sympy
from hypothesis import given
from hypothesis import strategies as st

from lagsym import (
    curve_from_points,
    grid_from_points,
    grid_from_table,
    lagrange_basis,
    lagrange_curve,
    lagrange_surface,
    read_curve_points,
    read_points,
)
from lagsym.lagrange import X, Y, basis_coefficients

from conftest import EXAMPLES

R = sympy.Rational
x, y = X, Y


# --- the paper's examples -------------------------------------------------------------------

def test_paper_curve_2nd_degree():
    assert lagrange_curve(read_curve_points(EXAMPLES / "paper-curve-2nd.json")).expr == -2 * x**2 + 8 * x - 5


def test_paper_curve_3rd_degree_exact_and_as_printed():
    curve = lagrange_curve(read_curve_points(EXAMPLES / "paper-curve-3rd.json"))
    assert curve.expr == R(5, 6) * x**3 - R(13, 2) * x**2 + R(47, 3) * x - 9
    # The paper prints 0.833x^3 - 6.5x^2 + 15.67x - 9: the same polynomial rounded.
    printed = [0.833, -6.5, 15.67, -9]
    exact = [float(c) for c in reversed(curve.coefficients)]
    assert all(abs(p - e) < 5e-3 for p, e in zip(printed, exact))


def test_paper_example_1():
    assert lagrange_surface(read_points(EXAMPLES / "paper-example-1.json")).expr == x**2 + 3 * y


def test_paper_example_2_matches_print_exactly():
    s = lagrange_surface(read_points(EXAMPLES / "paper-example-2.json"))
    printed = (R(1, 2) * x**2 * y**2 - R(5, 2) * x * y**2 + 2 * y**2 - R(5, 2) * x**2 * y + R(25, 2) * x * y
               - 10 * y + 2 * x**2 - 10 * x + 8)
    assert sympy.expand(s.expr - printed) == 0


def test_paper_example_3_exact_terms():
    s = lagrange_surface(read_points(EXAMPLES / "paper-example-3.json"))
    c = s.coefficients
    assert c[3][3] == Fraction(1, 6)
    assert c[1][2] == Fraction(-139, 6)  # the paper prints -23.1667 xy (errata)
    assert c[1][1] == Fraction(161, 3)
    assert c[0][0] == 15


def test_paper_example_4_passes_through_its_points_and_has_degree_4():
    g = read_points(EXAMPLES / "paper-example-4.json")
    s = lagrange_surface(g)
    assert s.poly.degree(x) == 4 and s.poly.degree(y) == 4
    assert s.coefficients[4][4] == Fraction(-1, 2880)
    for xi, yk, zik in g.points():
        assert s.exact_value(xi, yk) == zik
    assert g.z[1][1] == Fraction(263, 100)  # 2.63 is exact, not the binary float


def test_poly_is_over_qq_and_expr_parses_back():
    s = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
    assert s.poly.domain == sympy.QQ
    back = sympy.sympify(str(s.expr), locals={"x": x, "y": y})
    assert sympy.expand(back - s.expr) == 0


def test_basis_polynomials_figure_4():
    g = read_points(EXAMPLES / "paper-example-1.json")
    s = lagrange_surface(g)
    assert s.basis_x[0].as_expr() == sympy.expand((x - 3) * (x - 5) / 8)
    assert s.basis_y[2].as_expr() == sympy.expand((y - 2) * (y - 3) / 2)
    assert basis_coefficients([1, 2, 3])[1] == (Fraction(-3), Fraction(4), Fraction(-1))


def test_degree_one_is_the_paper_line_equation():
    curve = lagrange_curve(curve_from_points([(1, 2), (3, 8)]))
    assert curve.expr == 3 * x - 1


def test_large_grid_is_exact():
    n = 12
    nodes = [Fraction(i, 3) for i in range(n)]
    z = [[Fraction((i * 7 + k * 3) % 5, 2) for k in range(n)] for i in range(n)]
    s = lagrange_surface(grid_from_table(nodes, nodes, z))
    for i in (0, 5, 11):
        for k in (0, 7, 11):
            assert s.exact_value(nodes[i], nodes[k]) == z[i][k]


def test_surface_and_curve_are_frozen():
    s = lagrange_surface(read_points(EXAMPLES / "paper-example-1.json"))
    with pytest.raises(AttributeError):
        s.coefficients = ()
    with pytest.raises(ValueError):
        s.grid.z_array[0, 0] = 1.0


# --- properties -----------------------------------------------------------------------------

fractions = st.fractions(min_value=-50, max_value=50, max_denominator=20)


@st.composite
def node_sets(draw, min_size=2, max_size=6):
    return draw(st.lists(fractions, min_size=min_size, max_size=max_size, unique=True))


@st.composite
def grids(draw):
    xs = draw(node_sets())
    ys = draw(node_sets())
    z = [[draw(fractions) for _ in ys] for _ in xs]
    return xs, ys, z


@given(grids())
def test_surface_passes_through_every_control_point(data):
    xs, ys, z = data
    s = lagrange_surface(grid_from_table(xs, ys, z))
    for i, xi in enumerate(xs):
        for k, yk in enumerate(ys):
            assert s.exact_value(xi, yk) == z[i][k]


@pytest.mark.slow
@given(grids(), st.data())
def test_surface_reproduces_polynomials_of_low_enough_degree(data, draw):
    xs, ys, _ = data
    n, m = len(xs), len(ys)
    c = [[draw.draw(fractions) for _ in range(m)] for _ in range(n)]

    def p(a, b):
        return sum(c[i][j] * a**i * b**j for i in range(n) for j in range(m))

    s = lagrange_surface(grid_from_table(xs, ys, [[p(a, b) for b in ys] for a in xs]))
    assert [list(r) for r in s.coefficients] == c


@given(node_sets(max_size=8))
def test_basis_sums_to_one_and_is_cardinal(nodes):
    basis = lagrange_basis(nodes)
    assert sum(basis, sympy.Poly(0, x, domain=sympy.QQ)).as_expr() == 1
    for i, p in enumerate(basis):
        for j, t in enumerate(nodes):
            assert p.eval(sympy.Rational(t.numerator, t.denominator)) == (1 if i == j else 0)


@pytest.mark.slow
@given(grids(), st.randoms(use_true_random=False))
def test_shuffling_or_reversing_the_input_changes_nothing(data, rnd):
    xs, ys, z = data
    pts = [(xi, yk, z[i][k]) for i, xi in enumerate(xs) for k, yk in enumerate(ys)]
    base = lagrange_surface(grid_from_points(pts))
    shuffled = pts[:]
    rnd.shuffle(shuffled)
    assert lagrange_surface(grid_from_points(shuffled)).coefficients == base.coefficients
    assert lagrange_surface(grid_from_points(pts[::-1])).coefficients == base.coefficients
    rev = grid_from_table(xs[::-1], ys[::-1], [row[::-1] for row in z[::-1]])
    assert lagrange_surface(rev).coefficients == base.coefficients


@given(node_sets(max_size=8), st.data())
def test_curve_passes_through_its_points(xs, data):
    ys = [data.draw(fractions) for _ in xs]
    curve = lagrange_curve(curve_from_points(list(zip(xs, ys))))
    for a, b in zip(xs, ys):
        assert curve.exact_value(a) == b


@given(grids(), st.data())
def test_exact_value_agrees_with_sympy(data, draw):
    xs, ys, z = data
    s = lagrange_surface(grid_from_table(xs, ys, z))
    a, b = draw.draw(fractions), draw.draw(fractions)
    assert s.exact_value(a, b) == s.expr.subs({x: R(a.numerator, a.denominator), y: R(b.numerator, b.denominator)})
