"""``lagsym fit`` and :func:`lagsym.fit.fit_surface`: exact least squares from grids and scattered points.

The checks are independent of the fit: exact equality with the Lagrange
interpolant and with the polynomial the data came from, and distances to the
formula the noisy data was made from, evaluated in NumPy from the exact
coefficients, never by the fit's own surface code.
"""

from __future__ import annotations

import json
import random
from fractions import Fraction

import numpy as np
import pytest
from scipy.spatial import Delaunay

from lagsym.errors import GridError, InputError
from lagsym.fit import fit_surface
from lagsym.grid import grid_from_points, grid_from_table
from lagsym.io import read_points
from lagsym.lagrange import horner2, lagrange_surface

SIGMA = 0.02  # mm of measurement noise


def formula(x, y):
    """The part the noisy points measure: smooth, not a polynomial."""
    return 10 + 0.04 * x - 0.03 * y + 3 * np.sin(np.pi * x / 120) * np.cos(np.pi * y / 160)


def noisy_grid(seed: int = 37) -> list[tuple[Fraction, Fraction, Fraction]]:
    rng = np.random.default_rng(seed)
    xs, ys = np.linspace(0, 100, 12), np.linspace(0, 80, 12)
    return [(Fraction(f"{x:.3f}"), Fraction(f"{y:.3f}"), Fraction(f"{formula(x, y) + rng.normal(0, SIGMA):.4f}"))
            for x in xs for y in ys]


def noisy_scatter(n: int = 200, seed: int = 11) -> list[tuple[Fraction, Fraction, Fraction]]:
    rng = np.random.default_rng(seed)
    out = []
    for x, y in zip(rng.uniform(0, 100, n), rng.uniform(0, 80, n)):
        out.append((Fraction(f"{x:.3f}"), Fraction(f"{y:.3f}"),
                    Fraction(f"{formula(x, y) + rng.normal(0, SIGMA):.4f}")))
    return out


def polyval(coefficients, x, y):
    """The fit's polynomial in NumPy from its exact coefficients, shifted to the box centre first.

    Shifting is exact in rationals (a Taylor shift with SymPy would do; here the
    coefficients are re-expanded with exact binomials), so the float sum stays
    well scaled.
    """
    from math import comb

    cx, cy = Fraction(50), Fraction(40)
    P, Q = len(coefficients) - 1, len(coefficients[0]) - 1
    shifted = [[Fraction(0)] * (Q + 1) for _ in range(P + 1)]
    for a in range(P + 1):
        for b in range(Q + 1):
            c = coefficients[a][b]
            for i in range(a + 1):
                for j in range(b + 1):
                    shifted[i][j] += c * comb(a, i) * cx ** (a - i) * comb(b, j) * cy ** (b - j)
    return np.polynomial.polynomial.polyval2d(x - 50, y - 40, np.array([[float(v) for v in r] for r in shifted]))


def test_a_fit_with_as_many_coefficients_as_points_is_the_lagrange_interpolant():
    rnd = random.Random(3)
    grid = grid_from_table([0, Fraction(1, 2), 2, 3, 7], [1, 2, 5, Fraction(11, 2)],
                           [[Fraction(rnd.randint(-999, 999), 100) for _ in range(4)] for _ in range(5)])
    fit = fit_surface(grid, (4, 3))
    interpolant = lagrange_surface(grid)
    assert fit.coefficients == interpolant.coefficients
    assert fit.surface.expr == interpolant.expr
    assert all(r == 0 for r in fit.residuals)


@pytest.mark.parametrize("weighted", [False, True])
def test_a_fit_to_a_polynomial_of_the_fitted_degree_returns_it_exactly(weighted):
    rnd = random.Random(5)
    coeffs = tuple(tuple(Fraction(rnd.randint(-50, 50), rnd.randint(1, 9)) for _ in range(3)) for _ in range(4))
    points = []
    for _ in range(40):
        x, y = Fraction(rnd.randint(-5000, 5000), 1000), Fraction(rnd.randint(0, 3000), 100)
        points.append((x, y, horner2(coeffs, x, y)))
    weights = [Fraction(rnd.randint(1, 20), 7) for _ in points] if weighted else None
    fit = fit_surface(points, "3x2", weights=weights)
    assert fit.coefficients == coeffs
    assert fit.residual_numerators == (0,) * len(points) and fit.rss == 0
    # The surface every command receives is that polynomial too.
    assert lagrange_surface(fit.surface.grid).coefficients == fit.surface.coefficients
    assert fit.surface.coefficients == coeffs


@pytest.mark.parametrize("weighted", [False, True])
def test_the_statistics_in_floats_agree_with_the_exact_residuals_and_a_threshold_is_exact(weighted):
    # Statistics come from residuals in floating point (exact ones of many points are integers of thousands of
    # digits); they agree with the exact residuals, and a threshold equal to a residual is decided exactly.
    points = noisy_scatter(60, seed=7)
    weights = [Fraction(1 + k % 3, 2) for k in range(60)] if weighted else None
    fit = fit_surface(points, (3, 2), weights=weights)
    exact = [horner2(fit.coefficients, x, y) for x, y, _ in points]
    res = [z - v for (_, _, z), v in zip(points, exact)]
    assert [fit.residual(k) for k in range(60)] == res
    assert np.allclose(fit.float_residuals, [float(r) for r in res], rtol=0, atol=1e-12)
    assert fit.max_residual == pytest.approx(float(max(abs(r) for r in res)), rel=1e-12)
    assert fit.rms == pytest.approx(float(sum(r * r for r in res) / 60) ** 0.5, rel=1e-12)
    rss = sum((w if weighted else 1) * r * r for w, r in zip(weights or [1] * 60, res))
    assert fit.rss == rss and fit.sigma == pytest.approx(float(rss / (60 - 12)) ** 0.5, rel=1e-12)
    t = sorted(abs(r) for r in res)[-4]  # the 4th largest: strictly beyond it are 3 points (no tie here)
    assert fit.beyond(t) == tuple(sorted((k for k in range(60) if abs(res[k]) > t), key=lambda k: -abs(res[k])))
    assert len(fit.beyond(t)) == 3


def test_the_residuals_and_normal_equations_hold_exactly():
    points = noisy_scatter(30, seed=2)
    fit = fit_surface(points, (2, 1))
    # Least squares: the residual is orthogonal to every basis function, exactly.
    for a in range(3):
        for b in range(2):
            assert sum(r * x ** a * y ** b for r, (x, y, _) in zip(fit.residuals, points)) == 0
    assert fit.residuals == tuple(z - horner2(fit.coefficients, x, y) for x, y, z in points)


def test_auto_degree_on_a_noisy_12x12_grid_is_within_3_sigma_of_the_formula_on_the_whole_box():
    fit = fit_surface(noisy_grid())
    assert fit.criterion == "gcv" and fit.scores[0][0] == fit.degree and fit.score > 0
    xs, ys = np.meshgrid(np.linspace(0, 100, 201), np.linspace(0, 80, 161), indexing="ij")
    worst = np.abs(polyval(fit.coefficients, xs, ys) - formula(xs, ys)).max()
    assert worst < 3 * SIGMA
    assert fit.outside_hull == 0 and "no extrapolation" in fit.report()
    # The interpolant of the same data is far off: what the fit is for.
    lag = lagrange_surface(grid_from_points(noisy_grid()))
    assert np.abs(polyval(lag.coefficients, xs, ys) - formula(xs, ys)).max() > 10 * 3 * SIGMA


@pytest.mark.parametrize("criterion", ["gcv", "loo"])
def test_scattered_noisy_points_are_fitted_within_3_sigma_inside_their_hull(criterion):
    points = noisy_scatter()
    fit = fit_surface(points, criterion=criterion)
    xy = np.array([[float(x), float(y)] for x, y, _ in points])
    xs, ys = np.meshgrid(np.linspace(0, 100, 201), np.linspace(0, 80, 161), indexing="ij")
    inside = Delaunay(xy).find_simplex(np.column_stack([xs.ravel(), ys.ravel()])) >= 0
    err = np.abs(polyval(fit.coefficients, xs, ys) - formula(xs, ys)).ravel()
    assert inside.mean() > 0.9
    assert err[inside].max() < 3 * SIGMA
    # It says where it extrapolates: the share of the box outside the hull, and the corners.
    report = fit.report()
    assert 0 < fit.outside_hull < 0.1 and "extrapolates on" in report and "near the corners" in report
    assert len(fit.corners_outside()) == 4


def test_a_grid_with_a_missing_point_is_fitted():
    points = noisy_grid()
    del points[17]
    fit = fit_surface(points, 4)
    assert len(fit.points) == 143 and fit.degree == (4, 4)


def test_too_few_points_for_the_degree_are_refused():
    with pytest.raises(GridError, match="do not determine a degree 3x3"):
        fit_surface([(0, 0, 1), (1, 0, 2), (0, 1, 3), (1, 1, 4), (2, 2, 5)], 3)
    with pytest.raises(InputError, match="degree '4y'"):
        fit_surface(noisy_grid(), "4y")
    with pytest.raises(InputError, match="criterion chooses degrees; the degrees are given"):
        fit_surface(noisy_grid(), 4, criterion="loo")
    with pytest.raises(InputError, match="max_degree chooses degrees"):
        fit_surface(noisy_grid(), "4x3", max_degree=6)
    with pytest.raises(InputError, match="weight 1 = 0 is not positive"):
        fit_surface([(0, 0, 1), (1, 0, 2), (0, 1, 3), (1, 1, 4)], 1, weights=[0, 1, 1, 1])


def test_points_beyond_a_threshold_are_listed():
    points = noisy_grid()
    x, y, z = points[50]
    points[50] = (x, y, z + Fraction(1, 2))  # one bad probe hit
    fit = fit_surface(points, 4)
    assert fit.beyond(Fraction(1, 5)) == (50,)
    assert f"point 51 at (x, y) = ({float(x):.6g}, {float(y):.6g})" in fit.report()


def write_points(path, points):
    path.write_text("x,y,z\n" + "".join(f"{x},{y},{z}\n" for x, y, z in
                                        ((float(a), float(b), float(c)) for a, b, c in points)))


@pytest.mark.slow
def test_cli_fit_writes_a_surface_file_every_command_reads(run_cli, tmp_path):
    src, surf = tmp_path / "probe.csv", tmp_path / "surface.json"
    points = noisy_grid()
    src.write_text("x,y,z\n" + "".join(f"{_dec(x)},{_dec(y)},{_dec(z)}\n" for x, y, z in points))
    status, out, err = run_cli("fit", src, "--degree", "4x3", "-o", surf)
    assert status == 0, err
    assert "degree 4x3 as given" in out and "residuals: max" in out
    doc = json.loads(surf.read_text())
    assert doc["format"] == "lagsym-surface" and doc["degree"] == [4, 3]
    fit = fit_surface(points, (4, 3))
    assert [[Fraction(c) for c in row] for row in doc["coefficients"]] == [list(r) for r in fit.coefficients]
    assert lagrange_surface(read_points(surf)).coefficients == fit.surface.coefficients
    status, out, _ = run_cli("equation", surf)
    assert status == 0 and out.startswith("z = ")
    assert run_cli("check", surf)[0] == 0
    assert run_cli("sample", surf, "--nx", "5", "--ny", "5", "-o", tmp_path / "s.csv")[0] == 0
    status, _, err = run_cli("toolpath", surf, "--step", "5", "-o", tmp_path / "p.nc")
    assert status == 0, err


def _dec(v: Fraction) -> str:
    from decimal import Decimal

    return str(Decimal(v.numerator) / Decimal(v.denominator))


def test_cli_fit_auto_prints_the_choice_and_score(run_cli, tmp_path):
    src = tmp_path / "probe.json"
    src.write_text(json.dumps([[_dec(x), _dec(y), _dec(z)] for x, y, z in noisy_grid()]))
    status, out, err = run_cli("fit", src)
    assert status == 0
    assert json.loads(out)["format"] == "lagsym-surface"
    assert "chosen by generalized cross-validation: score" in err


def test_cli_fit_refuses_a_criterion_with_given_degrees(run_cli, tmp_path):
    src = tmp_path / "probe.json"
    src.write_text(json.dumps([[_dec(x), _dec(y), _dec(z)] for x, y, z in noisy_grid()]))
    status, _, err = run_cli("fit", src, "--degree", "4", "--criterion", "loo")
    assert status == 2 and "--criterion chooses the degrees" in err and err.count("\n") == 1
    status, _, err = run_cli("fit", src, "--degree", "4", "--max-degree", "5")
    assert status == 2 and "--max-degree chooses the degrees" in err


def test_a_surface_file_changed_by_hand_is_refused(run_cli, tmp_path):
    src, surf = tmp_path / "probe.csv", tmp_path / "surface.json"
    src.write_text("x,y,z\n" + "".join(f"{_dec(x)},{_dec(y)},{_dec(z)}\n" for x, y, z in noisy_grid()))
    assert run_cli("fit", src, "--degree", "3", "-o", surf)[0] == 0
    doc = json.loads(surf.read_text())
    doc["z"][1][2] = "12.5"
    surf.write_text(json.dumps(doc))
    status, out, err = run_cli("equation", surf)
    assert status == 2 and err.count("\n") == 1 and "is not the polynomial's value there" in err


def test_cli_fit_weights_and_bad_weights(run_cli, tmp_path):
    src, wts = tmp_path / "probe.csv", tmp_path / "w.txt"
    pts = noisy_scatter(40)
    src.write_text("x,y,z\n" + "".join(f"{_dec(x)},{_dec(y)},{_dec(z)}\n" for x, y, z in pts))
    wts.write_text("# one a line\n" + "2\n" * 40)
    status, out, err = run_cli("fit", src, "--degree", "2", "--weights", wts)
    assert status == 0 and "weighted least squares" in err
    wts.write_text("2\n" * 39 + "x\n")
    status, _, err = run_cli("fit", src, "--degree", "2", "--weights", wts)
    assert status == 2 and "line 40" in err and err.count("\n") == 1


def _disc_top(coefficients, cx, cy, radius, n=61):
    """The highest ball-tip height over the disc under a ball at (cx, cy): a brute-force drop-cutter."""
    t = np.linspace(-radius, radius, n)
    gx, gy = np.meshgrid(t, t)
    inside = gx ** 2 + gy ** 2 <= radius ** 2
    px, py = cx + gx[inside], cy + gy[inside]
    ok = (px >= 0) & (px <= 100) & (py >= 0) & (py <= 80)
    px, py = px[ok], py[ok]
    return float((polyval(coefficients, px, py) + np.sqrt(np.maximum(radius ** 2 - (px - cx) ** 2 - (py - cy) ** 2, 0))
                  - radius).max())


@pytest.mark.slow
def test_the_fitted_surface_machines_without_gouge_and_its_macro_runs_in_rs274(run_cli, tmp_path, rs274):
    from gcheck import interpret

    src, surf = tmp_path / "probe.csv", tmp_path / "surface.json"
    points = noisy_grid()
    src.write_text("x,y,z\n" + "".join(f"{_dec(x)},{_dec(y)},{_dec(z)}\n" for x, y, z in points))
    assert run_cli("fit", src, "-o", surf)[0] == 0
    coefficients = fit_surface(points).coefficients
    prog = tmp_path / "part.ngc"
    status, _, err = run_cli("toolpath", surf, "--dialect", "linuxcnc", "--tool-diameter", "6", "--stepover", "4",
                             "--step", "1", "-o", prog)
    assert status == 0, err
    feeds, _ = interpret(rs274, prog.read_text())
    rng = np.random.default_rng(1)
    for x, y, z in feeds[rng.choice(len(feeds), 300, replace=False)]:
        top = _disc_top(coefficients, x, y, 3.0)
        assert z >= top - 1e-3  # no gouge (the program's resolution and the lattice's step)
        assert z <= top + 0.02  # and on the part, not in the air
    macro = tmp_path / "part-macro.ngc"
    status, _, err = run_cli("macro", surf, "--dialect", "linuxcnc", "--tool-diameter", "6", "--stepover", "4",
                             "--step", "2", "-o", macro)
    assert status == 0, err
    mfeeds, _ = interpret(rs274, macro.read_text())
    assert len(mfeeds) > 500
    for x, y, z in mfeeds[rng.choice(len(mfeeds), 200, replace=False)]:
        if 0 <= x <= 100 and 0 <= y <= 80:
            assert z >= _disc_top(coefficients, x, y, 3.0) - 1e-3


def test_coefficients_longer_than_python_prints_are_written_read_and_printed(run_cli, tmp_path):
    # An exact fit of many points to a high degree has numerators and denominators of thousands of digits,
    # past the 4,300 that Python converts to text by itself.
    import io

    from lagsym.export.surfacejson import write_surface_json

    c = Fraction(3 * 10 ** 5000 + 1, 10 ** 5000 - 7)
    points = [(Fraction(x), Fraction(y), c * x + y) for x in range(3) for y in range(3)]
    fit = fit_surface(points, (1, 1))
    assert fit.coefficients == ((0, 1), (c, 0))
    buf = io.StringIO()
    write_surface_json(buf, fit.surface, fit.coefficients, fit)
    surf = tmp_path / "long.json"
    surf.write_text(buf.getvalue())
    assert lagrange_surface(read_points(surf)).coefficients == fit.surface.coefficients
    status, out, err = run_cli("equation", surf)
    assert status == 0, err
    assert out.startswith("z = 3000") and "/9999" in out and len(out) > 10_000
    status, out, err = run_cli("equation", surf, "--format", "json")
    import flint

    num, den = json.loads(out)["coefficients"]["1,0"].split("/")
    assert status == 0 and Fraction(int(flint.fmpz(num)), int(flint.fmpz(den))) == c
    assert run_cli("check", surf)[0] == 0


def _scores_one_qr_a_candidate(points, criterion, top):
    """The scores computed the plain way: each candidate's own least-squares problem, factored on its own."""
    xs, ys, zs = (np.array([float(p[i]) for p in points]) for i in range(3))
    cheb = np.polynomial.chebyshev.chebvander
    vx = cheb((2 * xs - (xs.min() + xs.max())) / (xs.max() - xs.min()), top[0])
    vy = cheb((2 * ys - (ys.min() + ys.max())) / (ys.max() - ys.min()), top[1])
    n, out = len(xs), {}
    for p in range(top[0] + 1):
        for q in range(top[1] + 1):
            k = (p + 1) * (q + 1)
            if k >= n:
                continue
            qm, rm = np.linalg.qr((vx[:, :p + 1, None] * vy[:, None, :q + 1]).reshape(n, k))
            diag = np.abs(np.diag(rm))
            if diag.min() <= 1e-10 * diag.max():
                continue
            res = zs - qm @ (qm.T @ zs)
            h = np.einsum("ij,ij->i", qm, qm)
            gcv = n * float(res @ res) / (n - k) ** 2
            out[p, q] = gcv if criterion == "gcv" else float(np.mean((res / (1 - h)) ** 2))
    return out


@pytest.mark.parametrize("criterion", ["gcv", "loo"])
@pytest.mark.parametrize("layout", ["scattered", "on four lines"])
def test_the_scores_from_one_factorization_are_each_candidates_own(criterion, layout):
    from lagsym.fit.select import scores

    rng = np.random.default_rng(5)
    n = 400
    xs = rng.uniform(0, 10, n) if layout == "scattered" else rng.choice([0.0, 2.5, 7.0, 10.0], n)
    ys = rng.uniform(0, 5, n)
    zs = xs * xs * ys - 3 * ys**3 + xs + rng.normal(0, 0.01, n)
    points = [(Fraction(float(x)), Fraction(float(y)), Fraction(float(z))) for x, y, z in zip(xs, ys, zs)]
    got = dict(scores(points, None, criterion, (6, 5)))
    want = _scores_one_qr_a_candidate(points, criterion, (6, 5))
    assert got.keys() == want.keys()  # the same candidates scored, the same refused (on four lines: x degree 3 at most)
    assert all(abs(got[c] - want[c]) <= 1e-9 * want[c] for c in want), max(abs(got[c] / want[c] - 1) for c in want)
    assert layout == "scattered" or max(p for p, _ in want) == 3


@pytest.mark.parametrize("span, weight, degree", [(1, 1, (0, 0)), (3, 1, (1, 3)), (10**5, 1, (8, 8)),
                                                  (10**9, 2**30, (6, 2)), (2**40, 7, (3, 3))])
def test_the_modular_moments_are_the_python_integer_sums(span, weight, degree):
    """lagsym.fit.moments (residues modulo primes below 2**16 in float64 products, then the CRT) against the sums
    in Python's own integers, with zeros, negatives, weights and values up to 2**40; beyond 64 bits it declines."""
    from lagsym.fit.moments import moments

    rng = np.random.default_rng(span % 1000 + degree[0])
    n = 700
    U, V, Z = ([int(v) for v in rng.integers(-span, span + 1, n)] for _ in range(3))
    U[:50] = [0] * 50
    W = [int(v) for v in rng.integers(1, weight + 1, n)]
    p, q = degree
    M = [[sum(w * u ** s * v ** t for u, v, w in zip(U, V, W)) for t in range(2 * q + 1)] for s in range(2 * p + 1)]
    R = [[sum(w * z * u ** a * v ** b for u, v, w, z in zip(U, V, W, Z)) for b in range(q + 1)] for a in range(p + 1)]
    assert moments(U, V, W, Z, degree) == (M, R)
    assert moments(U, V, W, [2 ** 63] + Z[1:], degree) is None
