"""The comparison surfaces: one suite run over every method, then each method's exact properties."""

from __future__ import annotations

import dataclasses
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from lagsym.errors import InputError
from lagsym.grid import grid_from_table
from lagsym.lagrange import lagrange_surface
from lagsym.surfaces import (
    METHODS,
    BernsteinBasis,
    Surface,
    bernstein_matrix,
    bezier_surface,
    bspline_basis,
    bspline_surface,
    clamped_uniform_knots,
    difference_matrix,
    hermite_surface,
    invert_parameter,
    make_surface,
)

KINDS = {
    "lagrange": lambda g: make_surface("lagrange", g),
    "hermite-corner": lambda g: hermite_surface(g, "corner"),
    "hermite-piecewise": lambda g: hermite_surface(g, "piecewise"),
    "bezier": bezier_surface,
    "bspline": lambda g: bspline_surface(g, 3),
}

# An unevenly spaced 5 x 4 net with bumps, so no method is exact by accident.
UNEVEN = grid_from_table(
    [0, 3, 4, 9, 12],
    [-2, Fraction(1, 2), 5, 6],
    [[1, 4, 2, 0], [3, Fraction(7, 2), -1, 2], [0, 2, 6, 1], [5, 1, 1, 3], [2, 0, 4, Fraction(5, 4)]],
    source="uneven",
)


@pytest.fixture(params=sorted(KINDS))
def method(request):
    """``(kind, surface)`` for every compared method, built from the uneven net."""
    return request.param, KINDS[request.param](UNEVEN)


def _corners(g):
    return [(i, k) for i in (0, len(g.x) - 1) for k in (0, len(g.y) - 1)]


# --- the shared protocol --------------------------------------------------------------------------------------------


def test_follows_the_protocol_and_is_frozen(method):
    kind, s = method
    assert isinstance(s, Surface)
    assert isinstance(s.name, str) and s.name
    field = dataclasses.fields(s)[0].name
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(s, field, None)


def test_meets_the_four_corners_exactly(method):
    _, s = method
    for i, k in _corners(UNEVEN):
        x, y = float(UNEVEN.x[i]), float(UNEVEN.y[k])
        assert s.evaluate_grid([x], [y])[0, 0] == float(UNEVEN.z[i][k])
        assert s.evaluate(x, y) == float(UNEVEN.z[i][k])


def test_grid_and_scattered_evaluation_agree(method):
    _, s = method
    xs = np.linspace(0, 12, 9)
    ys = np.linspace(-2, 6, 7)
    z = s.evaluate_grid(xs, ys)
    assert z.shape == (9, 7)
    np.testing.assert_allclose(s.evaluate(xs[:, None], ys[None, :]), z, rtol=0, atol=1e-12)


@pytest.mark.parametrize("kind", ["lagrange", "hermite-piecewise"])
def test_interpolating_methods_meet_every_control_point(kind):
    s = KINDS[kind](UNEVEN)
    np.testing.assert_allclose(s.evaluate_grid(UNEVEN.x_array, UNEVEN.y_array), UNEVEN.z_array, rtol=0, atol=1e-12)


def test_held_arrays_are_read_only():
    s = hermite_surface(UNEVEN, "piecewise")
    for a in (s.z, s.zx, s.zy, s.zxy):
        with pytest.raises(ValueError):
            a[0, 0] = 1.0


def test_unknown_choices_name_the_valid_ones():
    with pytest.raises(InputError, match="lagrange, hermite, bezier, bspline"):
        make_surface("nurbs", UNEVEN)
    with pytest.raises(InputError, match="corner, piecewise"):
        hermite_surface(UNEVEN, "ferguson")
    with pytest.raises(InputError, match="degree 0"):
        bspline_surface(UNEVEN, 0)
    assert [make_surface(m, UNEVEN).name for m in METHODS] == ["Lagrange", "Hermite", "Bezier", "B-spline"]


# --- Bernstein and B-spline bases -----------------------------------------------------------------------------------

fractions01 = st.fractions(min_value=0, max_value=1, max_denominator=10**6)


@given(st.integers(1, 12), fractions01)
def test_bernstein_partition_of_unity_is_exact(n, t):
    assert sum(bernstein_matrix(n, [t])[0]) == 1


@given(st.integers(1, 12))
def test_bernstein_end_point_interpolation_is_exact(n):
    b = bernstein_matrix(n, [Fraction(0), Fraction(1)])
    assert list(b[0]) == [1] + [0] * n
    assert list(b[1]) == [0] * n + [1]
    f = bernstein_matrix(n, [0.0, 1.0])
    assert f[0, 0] == 1.0 and f[1, -1] == 1.0 and f[0, 1:].sum() == 0.0 and f[1, :-1].sum() == 0.0


@given(st.integers(2, 9), st.data())
def test_bspline_partition_of_unity(size, data):
    degree = data.draw(st.integers(1, size - 1))
    t = np.array(data.draw(st.lists(st.floats(0, 1), min_size=1, max_size=20)))
    b = bspline_basis(size, degree).evaluate(t)
    np.testing.assert_allclose(b.sum(axis=1), 1.0, rtol=0, atol=1e-14)
    assert (b >= -1e-15).all()


@given(st.integers(2, 10))
def test_bspline_of_full_degree_is_the_bernstein_basis(size):
    knots = clamped_uniform_knots(size, size - 1)
    assert knots == (0,) * size + (1,) * size
    t = np.linspace(0, 1, 33)
    np.testing.assert_allclose(bspline_basis(size, size - 1).evaluate(t), BernsteinBasis(size - 1).evaluate(t),
                               rtol=0, atol=1e-14)


def test_bspline_of_full_degree_equals_bezier_surface():
    g = grid_from_table(UNEVEN.x, UNEVEN.y[:4], [row[:4] for row in UNEVEN.z])
    xs, ys = np.linspace(0, 12, 25), np.linspace(-2, 6, 17)
    full = bspline_surface(g, 99)  # capped at n - 1 per direction
    assert (full.basis_u.degree, full.basis_v.degree) == (4, 3)
    np.testing.assert_allclose(full.evaluate_grid(xs, ys), bezier_surface(g).evaluate_grid(xs, ys), rtol=0, atol=1e-12)
    low = bspline_surface(g, 2).evaluate_grid(xs, ys)
    assert np.abs(low - bezier_surface(g).evaluate_grid(xs, ys)).max() > 1e-3


@pytest.mark.parametrize("degree", [1, 2, 3, 4])
def test_parametric_surfaces_agree_with_geomdl(degree):
    geomdl = pytest.importorskip("geomdl.BSpline")
    s = bezier_surface(UNEVEN) if degree == 4 else bspline_surface(UNEVEN, degree)
    ref = geomdl.Surface()
    ref.degree_u, ref.degree_v = s.basis_u.degree, s.basis_v.degree
    ref.ctrlpts2d = [[[float(x), float(y), float(UNEVEN.z[i][k])] for k, y in enumerate(UNEVEN.y)]
                     for i, x in enumerate(UNEVEN.x)]
    ref.knotvector_u = [float(k) for k in clamped_uniform_knots(5, s.basis_u.degree)]
    ref.knotvector_v = [float(k) for k in clamped_uniform_knots(4, s.basis_v.degree)]
    rng = np.random.default_rng(degree)
    uv = np.vstack([rng.random((40, 2)), [[0, 0], [1, 1], [0, 1], [0.5, 0.5]]])
    expected = np.array(ref.evaluate_list([tuple(p) for p in uv]))
    got = np.column_stack(s.evaluate_uv(uv[:, 0], uv[:, 1]))
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)


# --- parametric inversion: compared at the same (x, y), not the same (u, v) ----------------------------------------

uneven_nodes = st.lists(st.integers(-50, 50), min_size=2, max_size=7, unique=True).map(sorted)


@given(uneven_nodes, st.integers(1, 6), st.lists(st.floats(0, 1), min_size=1, max_size=15))
def test_inversion_finds_the_parameter_above_each_x(nodes, degree, fractions_of_span):
    degree = min(degree, len(nodes) - 1)
    nodes = np.array(nodes, dtype=float)
    x = nodes[0] + np.array(fractions_of_span) * (nodes[-1] - nodes[0])
    for basis in (BernsteinBasis(len(nodes) - 1), bspline_basis(len(nodes), degree)):
        u = invert_parameter(basis, nodes, x)
        assert ((0 <= u) & (u <= 1)).all()
        np.testing.assert_allclose(basis.evaluate(u) @ nodes, x, rtol=0, atol=1e-9 * (1 + np.abs(nodes).max()))


def test_uneven_bezier_is_compared_at_the_same_x_not_the_same_u():
    s = bezier_surface(UNEVEN)
    u, v = np.array([0.3, 0.8]), np.array([0.6, 0.1])
    x, y, z = s.evaluate_uv(u, v)
    np.testing.assert_allclose(s.evaluate(x, y), z, rtol=0, atol=1e-12)
    # The naive affine parameter would be wrong on this net:
    affine = (x - 0) / 12
    assert np.abs(affine - u).max() > 0.01


@given(st.lists(st.lists(st.integers(-100, 100), min_size=4, max_size=4), min_size=5, max_size=5))
def test_bezier_and_bspline_stay_in_the_convex_hull(z):
    g = grid_from_table([0, 1, 3, 4, 8], [0, 2, 3, 7], z)
    xs, ys = np.linspace(0, 8, 11), np.linspace(0, 7, 9)
    lo, hi = min(map(min, z)), max(map(max, z))
    for s in (bezier_surface(g), bspline_surface(g, 2)):
        zz = s.evaluate_grid(xs, ys)
        assert (zz >= lo - 1e-9).all() and (zz <= hi + 1e-9).all()


# --- Hermite ----------------------------------------------------------------------------------------------------------


def test_tangent_rule_is_central_inside_one_sided_at_the_ends():
    d = difference_matrix([0.0, 1.0, 3.0, 4.0])
    f = np.array([0.0, 1.0, 9.0, 16.0])  # x**2
    np.testing.assert_allclose(d @ f, [1.0, 3.0, 5.0, 7.0])


@given(st.integers(2, 4), st.integers(2, 4), st.integers(1, 5), st.integers(1, 5), st.data())
def test_corner_hermite_is_the_bezier_on_an_even_net_of_up_to_4x4(n, m, hx, hy, data):
    # Ferguson form of a Bezier of degree <= 3: end tangent n (P1 - P0) per unit parameter, i.e. the
    # one-sided difference per unit x; twist n m (P11 - P10 - P01 + P00), the cross difference.
    z = data.draw(st.lists(st.lists(st.integers(-50, 50), min_size=m, max_size=m), min_size=n, max_size=n))
    g = grid_from_table([hx * i for i in range(n)], [hy * k for k in range(m)], z)
    xs, ys = np.linspace(0, (n - 1) * hx, 13), np.linspace(0, (m - 1) * hy, 10)
    np.testing.assert_allclose(hermite_surface(g, "corner").evaluate_grid(xs, ys),
                               bezier_surface(g).evaluate_grid(xs, ys), rtol=0, atol=1e-9)


def test_piecewise_hermite_is_c1_across_cell_edges():
    s = hermite_surface(UNEVEN, "piecewise")
    h = 1e-6
    for x in (3.0, 4.0, 9.0):
        left = (s.evaluate(x, 2.0) - s.evaluate(x - h, 2.0)) / h
        right = (s.evaluate(x + h, 2.0) - s.evaluate(x, 2.0)) / h
        assert abs(left - right) < 1e-4


# --- Lagrange reproduces polynomials exactly --------------------------------------------------------------------------


@given(st.lists(st.integers(-9, 9), min_size=9, max_size=9), st.fractions(-5, 5, max_denominator=50),
       st.fractions(-5, 5, max_denominator=50))
def test_lagrange_reproduces_polynomials_of_its_degree(c, x, y):
    def p(a, b):
        a, b = Fraction(a), Fraction(b)
        return sum(c[3 * i + j] * a**i * b**j for i in range(3) for j in range(3))

    nodes_x, nodes_y = [-2, 0, 3], [1, 2, 4]
    g = grid_from_table(nodes_x, nodes_y, [[p(a, b) for b in nodes_y] for a in nodes_x])
    assert lagrange_surface(g).exact_value(x, y) == p(x, y)


# --- random nets ---------------------------------------------------------------------------------------------------


@st.composite
def nets(draw):
    """Random control nets: 2-6 unevenly spaced nodes per direction, integer heights."""
    xs = draw(st.lists(st.integers(-30, 30), min_size=2, max_size=6, unique=True))
    ys = draw(st.lists(st.integers(-30, 30), min_size=2, max_size=6, unique=True))
    z = draw(st.lists(st.lists(st.integers(-99, 99), min_size=len(ys), max_size=len(ys)),
                      min_size=len(xs), max_size=len(xs)))
    return grid_from_table(xs, ys, z)


@given(nets())
def test_every_method_meets_the_corners_of_any_net(g):
    for kind, build in KINDS.items():
        s = build(g)
        xs, ys = [float(g.x[0]), float(g.x[-1])], [float(g.y[0]), float(g.y[-1])]
        expected = [[float(g.z[i][k]) for k in (0, -1)] for i in (0, -1)]
        np.testing.assert_allclose(s.evaluate_grid(xs, ys), expected, rtol=0, atol=1e-9, err_msg=kind)


@given(nets())
def test_full_degree_bspline_is_bezier_on_any_net(g):
    xs = np.linspace(float(g.x[0]), float(g.x[-1]), 7)
    ys = np.linspace(float(g.y[0]), float(g.y[-1]), 5)
    np.testing.assert_allclose(bspline_surface(g, 10).evaluate_grid(xs, ys), bezier_surface(g).evaluate_grid(xs, ys),
                               rtol=0, atol=1e-9)
