"""The numeric evaluator agrees with exact evaluation, within its stated bound."""

from __future__ import annotations

import copy
import dataclasses
import math
import subprocess
import sys
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from conftest import EXAMPLES
from lagsym.conditioning import check_surface, float_error_bound
from lagsym.evaluate import (
    COMPILED_POINTS,
    chebyshev_basis,
    chebyshev_matrix,
    chebyshev_transform,
    evaluate_curve,
    evaluate_grid,
    evaluate_points,
    lambdify_surface,
    load_compiled,
    surface_evaluator,
)
from lagsym.grid import curve_from_points, grid_from_table
from lagsym.io import read_points
from lagsym.lagrange import lagrange_curve, lagrange_surface

EXAMPLE_FILES = sorted(EXAMPLES.glob("paper-example-*.json"))


def _error(surface, x, y, z) -> float:
    """Largest ``|z - F(x, y)|`` with ``F`` evaluated exactly at the float coordinates."""
    return max(
        abs(float(surface.exact_value(Fraction(a), Fraction(b)) - Fraction(c)))
        for a, b, c in zip(np.ravel(x).tolist(), np.ravel(y).tolist(), np.ravel(z).tolist())
    )


def _chebyshev_like(n: int, a: int, b: int) -> list[Fraction]:
    """Chebyshev points of the first kind on [a, b], rounded to 3 decimals (as a user would type them)."""
    return [Fraction(round((a + b) / 2 - (b - a) / 2 * math.cos(math.pi * (2 * k + 1) / (2 * n)), 3)).limit_denominator(1000)
            for k in range(n)]


def _rough(n: int, m: int, seed: int) -> list[list[Fraction]]:
    rng = np.random.default_rng(seed)
    return [[Fraction(int(v), 100) for v in rng.integers(100, 340, m)] for _ in range(n)]


exact_decimal = st.integers(-10_000, 10_000).map(lambda k: Fraction(k, 100))


@st.composite
def surfaces(draw, max_nodes: int = 7):
    n = draw(st.integers(2, max_nodes))
    m = draw(st.integers(2, max_nodes))
    xs = sorted(draw(st.sets(st.integers(-500, 500), min_size=n, max_size=n)))
    ys = sorted(draw(st.sets(st.integers(-500, 500), min_size=m, max_size=m)))
    scale = draw(st.sampled_from([Fraction(1), Fraction(1, 10), Fraction(1, 3)]))
    z = [[draw(exact_decimal) for _ in range(m)] for _ in range(n)]
    return lagrange_surface(grid_from_table([v * scale for v in xs], [v * scale for v in ys], z))


@given(surfaces(), st.lists(st.tuples(st.floats(0, 1), st.floats(0, 1)), min_size=1, max_size=8))
def test_points_agree_with_exact_evaluation_within_the_bound(surface, unit_points):
    x0, x1, y0, y1 = (float(v) for v in surface.grid.bounds)
    x = np.array([x0 + u * (x1 - x0) for u, _ in unit_points])
    y = np.array([y0 + v * (y1 - y0) for _, v in unit_points])
    ev = surface_evaluator(surface)
    assert _error(surface, x, y, evaluate_points(surface, x, y)) <= ev.error_bound()


@given(surfaces(max_nodes=5), st.integers(2, 9), st.integers(2, 9))
def test_grid_agrees_with_exact_evaluation_within_the_bound(surface, nx, ny):
    x0, x1, y0, y1 = (float(v) for v in surface.grid.bounds)
    xs, ys = np.linspace(x0, x1, nx), np.linspace(y0, y1, ny)
    z = evaluate_grid(surface, xs, ys)
    xx, yy = np.meshgrid(xs, ys, indexing="ij")
    assert _error(surface, xx, yy, z) <= surface_evaluator(surface).error_bound()


@given(surfaces(max_nodes=5))
def test_the_surface_passes_through_every_control_point_exactly(surface):
    g = surface.grid
    xs = np.array([float(v) for v in g.x])
    exact_x = np.array([Fraction(float(v)) == v for v in g.x])
    exact_y = np.array([Fraction(float(v)) == v for v in g.y])
    ys = np.array([float(v) for v in g.y])
    z = evaluate_grid(surface, xs, ys)
    xx, yy = np.meshgrid(xs, ys, indexing="ij")
    zp = evaluate_points(surface, xx, yy)
    for i in range(len(xs)):
        for k in range(len(ys)):
            if exact_x[i] and exact_y[k]:
                assert z[i, k] == float(g.z[i][k])
                assert zp[i, k] == float(g.z[i][k])


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.stem)
def test_paper_examples_to_the_last_digits(path):
    surface = lagrange_surface(read_points(path))
    ev = surface_evaluator(surface)
    rng = np.random.default_rng(3)
    x0, x1, y0, y1 = ev.bounds
    x, y = rng.uniform(x0, x1, 40), rng.uniform(y0, y1, 40)
    assert _error(surface, x, y, evaluate_points(surface, x, y)) <= 1e-14 * ev.data_range
    assert float_error_bound(surface) <= 1e-12


@pytest.mark.parametrize("n", [10, 15, 20])
def test_chebyshev_like_nodes_up_to_20x20_reach_1e12_of_the_data_range(n):
    nodes = _chebyshev_like(n, 0, 100)
    surface = lagrange_surface(grid_from_table(nodes, nodes, _rough(n, n, n)))
    ev = surface_evaluator(surface)
    rng = np.random.default_rng(n)
    x, y = rng.uniform(0.5, 99.5, 12), rng.uniform(0.5, 99.5, 12)
    err = _error(surface, x, y, evaluate_points(surface, x, y))
    assert err <= 1e-12 * ev.data_range
    assert err <= ev.error_bound()
    assert ev.relative_error_bound() <= 1e-12


def test_paper_kind_of_nodes_smooth_data_at_12x12():
    nodes = [Fraction(k) for k in range(1, 13)]
    z = [[Fraction(1) + Fraction(i * k, 50) + Fraction((i - 6) ** 2, 40) for k in range(12)] for i in range(12)]
    surface = lagrange_surface(grid_from_table(nodes, nodes, z))
    rng = np.random.default_rng(12)
    x, y = rng.uniform(1, 12, 15), rng.uniform(1, 12, 15)
    assert _error(surface, x, y, evaluate_points(surface, x, y)) <= 1e-12 * surface_evaluator(surface).data_range
    assert float_error_bound(surface) <= 1e-12


def test_ill_conditioned_grids_are_flagged_and_the_bound_holds():
    # 20 equally spaced nodes with rough data: the interpolant swings far beyond the data (Runge)
    nodes = [Fraction(100 * k, 19) for k in range(20)]
    surface = lagrange_surface(grid_from_table(nodes, nodes, _rough(20, 20, 7)))
    ev = surface_evaluator(surface)
    rng = np.random.default_rng(1)
    x, y = rng.uniform(0, 100, 10), rng.uniform(0, 100, 10)
    assert _error(surface, x, y, evaluate_points(surface, x, y)) <= ev.error_bound()
    assert float_error_bound(surface) > 1e-12
    report = check_surface(surface)
    assert "float_error" in {f.name for f in report.warnings}


def test_the_bound_grows_outside_the_control_box():
    surface = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
    inside = float_error_bound(surface)
    assert float_error_bound(surface, (0.0, 6.0, 0.0, 6.0)) > inside
    assert float_error_bound(surface, (2.0, 3.0, 2.0, 3.0)) == inside  # within the box: the same bound


def test_chebyshev_transform_is_exact():
    xs = [Fraction(1, 3), Fraction(2), Fraction(7, 2), Fraction(11, 2)]
    curve = lagrange_curve(curve_from_points([(x, Fraction(k * k - 3, 7)) for k, x in enumerate(xs)]))
    offset, scale, a = chebyshev_transform(xs)
    n = len(xs)
    d = [Fraction(int(a[k, j].p), int(a[k, j].q)) for k in range(n) for j in range(n)]
    cheb = [sum(d[k * n + j] * curve.coefficients[j] for j in range(n)) for k in range(n)]
    for x in (Fraction(0), Fraction(5, 4), Fraction(9, 2), Fraction(6)):
        s = (x - Fraction(offset)) / Fraction(scale)
        t = [Fraction(1), s]
        while len(t) < n:
            t.append(2 * s * t[-1] - t[-2])
        assert sum(c * tk for c, tk in zip(cheb, t)) == curve.exact_value(x)


def test_chebyshev_matrix_matches_numpy():
    s = np.linspace(-1.2, 1.2, 25)
    ours = chebyshev_matrix(s, 7)
    ref = np.polynomial.chebyshev.chebvander(s, 6).T
    assert np.allclose(ours, ref, rtol=1e-14, atol=1e-14)


def test_evaluate_broadcasts_like_numpy():
    surface = lagrange_surface(read_points(EXAMPLES / "paper-example-1.json"))
    x = np.linspace(1, 5, 4)[:, None]
    y = np.linspace(2, 4, 3)[None, :]
    z = evaluate_points(surface, x, y)
    assert z.shape == (4, 3)
    assert np.allclose(z, x**2 + 3 * y, rtol=0, atol=1e-13)
    assert evaluate_points(surface, 2.0, 3.0).shape == ()
    assert np.array_equal(z, evaluate_grid(surface, x.ravel(), y.ravel()))


def test_scattered_points_in_chunks_match_one_block():
    surface = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
    ev = surface_evaluator(surface)
    rng = np.random.default_rng(0)
    x, y = rng.uniform(1, 5, 1000), rng.uniform(1, 5, 1000)
    assert np.array_equal(ev.points(x, y, chunk=64), ev.points(x, y, chunk=4096))


@pytest.mark.parametrize("offset, scale, lo, hi", [
    (3.0, 2.0, 1.0, 5.0), (3.0, 3.0, -1.0, 7.0), (0.7, 1.3, -0.6, 2.0), (12.345, 0.1, 12.2, 12.5), (-40.0, 7.0, -48, -30),
])
def test_the_compensated_basis_is_the_exact_value_rounded_once(offset, scale, lo, hi):
    x = np.random.default_rng(7).uniform(lo, hi, 300)
    x[:3] = lo, hi, offset
    got = chebyshev_basis(x, offset, scale, 12)
    wrong = 0
    for i, v in enumerate(x.tolist()):
        s = (Fraction(v) - Fraction(offset)) / Fraction(scale)
        t = [Fraction(1), s]
        for _ in range(10):
            t.append(2 * s * t[-1] - t[-2])
        wrong += sum(got[k, i] != float(t[k]) for k in range(12))  # float(Fraction) rounds correctly
    assert wrong == 0


@pytest.mark.slow
@pytest.mark.parametrize("shape, spread", [((5, 5), 0.25), ((7, 3), 1.5), ((2, 9), 0.0), ((14, 11), 0.1)])
def test_a_large_batch_runs_compiled_with_the_bits_of_small_ones(shape, spread):
    load_compiled()  # large batches run compiled from here on (lagsym.evaluate.engine)
    rng = np.random.default_rng(shape[0])
    n, m = shape
    xs = np.cumsum(rng.uniform(0.5, 2.0, n)) - 3.3
    ys = np.cumsum(rng.uniform(0.2, 1.0, m)) + 17.1
    zs = rng.normal(size=(n, m)).round(3)
    surface = lagrange_surface(grid_from_table([Fraction(v).limit_denominator(1000) for v in xs],
                                               [Fraction(v).limit_denominator(1000) for v in ys],
                                               [[Fraction(v).limit_denominator(1000) for v in row] for row in zs]))
    ev = surface_evaluator(surface)
    x0, x1, y0, y1 = ev.bounds
    k = COMPILED_POINTS + 1001  # the kernel, in two threads where there are two cores
    x = rng.uniform(x0 - spread * (x1 - x0), x1 + spread * (x1 - x0), k)
    y = rng.uniform(y0 - spread * (y1 - y0), y1 + spread * (y1 - y0), k)
    x[:200], y[:200] = rng.choice(ev.x_nodes, 200), rng.choice(ev.y_nodes, 200)  # control points: snapped
    x[200] = y[201] = np.nan
    whole = ev.points(x, y)
    pieces = np.concatenate([ev.points(x[i:i + 50_000], y[i:i + 50_000]) for i in range(0, k, 50_000)])
    assert np.array_equal(whole, pieces, equal_nan=True)
    assert np.isnan(whole[200:202]).all() and not np.isnan(whole[202:]).any()
    exact_nodes = (ev.x_exact[np.searchsorted(ev.x_nodes, x[:200])] & ev.y_exact[np.searchsorted(ev.y_nodes, y[:200])])
    hits = np.flatnonzero(exact_nodes)
    assert whole[hits].tolist() == ev.node_values[np.searchsorted(ev.x_nodes, x[hits]),
                                                  np.searchsorted(ev.y_nodes, y[hits])].tolist()
    box = (min(x0, x[202:].min()), max(x1, x[202:].max()), min(y0, y[202:].min()), max(y1, y[202:].max()))
    assert _error(surface, x[202:1202], y[202:1202], whole[202:1202]) <= ev.error_bound(box)


def test_a_small_batch_does_not_load_the_compiler():
    code = ("import sys, numpy as np; from lagsym import lagrange_surface, read_points, evaluate_points; "
            f"s = lagrange_surface(read_points({str(EXAMPLES / 'paper-example-4.json')!r})); "
            "evaluate_points(s, np.linspace(1, 5, 100_000), 2.5); print('numba' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"


def test_curves_agree_with_exact_evaluation():
    curve = lagrange_curve(curve_from_points([(1, 1), (2, 3), (3, 2), (4, 3)]))
    x = np.linspace(1, 4, 31)
    got = evaluate_curve(curve, x)
    assert got.shape == x.shape
    for a, b in zip(x.tolist(), got.tolist()):
        assert abs(float(curve.exact_value(Fraction(a))) - b) <= 1e-14
    assert evaluate_curve(curve, np.array([1.0, 2.0, 3.0, 4.0])).tolist()[:1] == [1.0]


def test_lambdify_is_the_exact_expression_as_a_numpy_function():
    surface = lagrange_surface(read_points(EXAMPLES / "paper-example-2.json"))
    f = lambdify_surface(surface)
    x, y = np.meshgrid(np.linspace(1, 4, 7), np.linspace(1, 4, 5), indexing="ij")
    assert np.allclose(f(x, y), evaluate_points(surface, x, y), rtol=0, atol=1e-12)
    flat = lagrange_surface(grid_from_table([0, 1], [0, 1], [[2, 2], [2, 2]]))
    assert lambdify_surface(flat)(np.zeros(3), 0.0).tolist() == [2.0, 2.0, 2.0]


def test_the_evaluator_is_immutable():
    ev = surface_evaluator(lagrange_surface(read_points(EXAMPLES / "paper-example-4.json")))
    with pytest.raises(dataclasses.FrozenInstanceError):
        ev.x_scale = 2.0
    with pytest.raises(ValueError):
        ev.coefficients[0, 0] = 1.0


def test_fast_points_agree_with_exact_values():
    """The float64 path drop-cutter searches with."""
    example4 = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
    ev = surface_evaluator(example4).fast_points
    for x, y in [(1, 1), (Fraction(5, 2), Fraction(7, 3)), (5, 5), (Fraction(13, 10), 4)]:
        assert ev(float(x), float(y)) == pytest.approx(float(example4.exact_value(x, y)), abs=1e-12)


@pytest.mark.parametrize("shape", [(1, 1, 1), (37, 3, 5), (400, 5, 2000), (3, 20, 9000)])
def test_the_blocked_grid_product_is_the_matrix_product(shape):
    """Blocks of rows (and a given output array) give the product NumPy's one matmul gives, to rounding."""
    from lagsym.evaluate.surface import grid_product

    n, k, m = shape
    rng = np.random.default_rng(n)
    w, ty = rng.uniform(-1, 1, (n, k)), rng.uniform(-1, 1, (k, m))
    out = np.full((n, m), np.nan)
    got = grid_product(w, ty, out)
    scale = np.abs(w) @ np.abs(ty)
    assert got is out and np.all(np.abs(got - w @ ty) <= 2 * k * np.finfo(float).eps * scale)


class _Unreferable:
    """A surface as the evaluator reads it (its grid and coefficients) that cannot be weakly referenced."""

    __slots__ = ("grid", "coefficients")

    def __init__(self, surface):
        self.grid, self.coefficients = surface.grid, surface.coefficients


@pytest.mark.parametrize("new", [copy.copy, _Unreferable], ids=["surface", "no weak references"])
def test_a_new_surface_at_a_dead_ones_address_gets_its_own_evaluator(monkeypatch, new):
    """The evaluators are remembered per object, never by its address alone: Python places new objects
    where dead ones were, and such a surface must not be handed the dead one's evaluator.  Here every
    object has the one address, so the case is met on every call rather than by chance."""
    from lagsym.evaluate import cache

    monkeypatch.setattr(cache, "id", lambda obj: 1, raising=False)
    one = lagrange_surface(grid_from_table([0, 1], [0, 1], [[0, 0], [1, 1]]))
    two = lagrange_surface(grid_from_table([0, 1], [0, 1], [[5, 5], [7, 7]]))
    first = new(one)
    assert float(surface_evaluator(first).points(1.0, 0.5)) == 1.0
    del first
    second = new(two)
    assert float(surface_evaluator(second).points(1.0, 0.5)) == 7.0
    third = new(one)  # alive beside the second, at its address
    assert float(surface_evaluator(third).points(1.0, 0.5)) == 1.0
    assert float(surface_evaluator(second).points(1.0, 0.5)) == 7.0


def test_an_evaluator_is_remembered_while_its_surface_lives_and_no_longer():
    from lagsym.evaluate.surface import _SURFACES

    surface = lagrange_surface(grid_from_table([0, 1, 2], [0, 1], [[0, 0], [1, 1], [4, 3]]))
    before = len(_SURFACES)
    assert surface_evaluator(surface) is surface_evaluator(surface)
    assert len(_SURFACES) == before + 1
    del surface
    assert len(_SURFACES) == before
