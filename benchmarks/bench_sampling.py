"""Sampling speed and accuracy, side by side with peers, in one run.

    python3 benchmarks/bench_sampling.py            # everything (about a minute)
    python3 benchmarks/bench_sampling.py --speed    # speed only
    python3 benchmarks/bench_sampling.py --accuracy # accuracy only

Speed: a 2000 x 2000 regular sample of the paper's 5x5 Example 4 against
NumPy filling an array of the same size (the memory limit: ``sample`` and
``np.full`` alternate, min and median of ``--runs`` runs each), with the
compiled kernels loaded (``load_compiled()``; a process loads them by itself
once its large grids have taken about half a second in NumPy, whose time for
the first ones is printed too), SciPy's
``BarycentricInterpolator`` along both axes, and ``lambdify`` of the expanded
expression; and 10**6 scattered points (``bench_scatter.py`` measures those
against ``lambdify`` alone).  The other figures are the best of several runs;
ratios are peer time / lagsym time.

Accuracy: the largest error against exact rational evaluation at random
points, as a fraction of the data range, for node sets up to 20 x 20 (the
paper's equally spaced integer nodes, equally spaced nodes over a 0-100 mm
box, Chebyshev-like nodes) and two kinds of data, next to the error bound
lagsym states and the errors of the expanded power basis and of a
Lagrange-basis (barycentric) evaluation.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

import results as recorded

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from lagsym.evaluate import (basis_matrix, evaluate_grid, evaluate_points, lambdify_surface,  # noqa: E402
                             load_compiled, surface_evaluator)
from lagsym.evaluate.engine import compiled_loaded  # noqa: E402
from lagsym.sampling import sample  # noqa: E402
from lagsym.grid import grid_from_table  # noqa: E402
from lagsym.io import read_points  # noqa: E402
from lagsym.lagrange import lagrange_surface  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
TRUST = 1e-12


def best(fn, repeat: int = 7, number: int = 1) -> float:
    """Best time of ``repeat`` runs of ``number`` calls, per call, in seconds."""
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - t) / number)
    return min(times)


def alternating(fns: dict, runs: int) -> dict[str, list[float]]:
    """Times of ``runs`` runs of each function, taken in turn, so a busy spell falls on all alike."""
    times: dict[str, list[float]] = {k: [] for k in fns}
    for _ in range(runs):
        for k, fn in fns.items():
            t = time.perf_counter()
            fn()
            times[k].append(time.perf_counter() - t)
    return times


def speed(n: int = 2000, runs: int = 21) -> dict:
    from scipy.interpolate import BarycentricInterpolator

    surface = lagrange_surface(read_points(ROOT / "examples" / "paper-example-4.json"))
    g = surface.grid
    xs, ys = np.linspace(1, 5, n), np.linspace(1, 5, n)
    sample(surface, 2, 2)  # the exact change of basis, once per surface
    f = lambdify_surface(surface)
    t_numpy = best(lambda: sample(surface, n, n), repeat=5)  # the first large grids of a process: NumPy
    assert not compiled_loaded()
    load_compiled()

    def scipy_both_axes():
        zx = BarycentricInterpolator(g.x_array, g.z_array, axis=0)(xs)  # (n, m)
        return BarycentricInterpolator(g.y_array, zx, axis=1)(ys)  # (n, n)

    def scipy_row_by_row():
        zx = BarycentricInterpolator(g.x_array, g.z_array, axis=0)(xs)
        return np.array([BarycentricInterpolator(g.y_array, row)(ys) for row in zx])

    ours = evaluate_grid(surface, xs, ys)
    assert np.abs(scipy_both_axes() - ours).max() < 1e-12
    assert np.abs(f(xs[:, None], ys[None, :]) - ours).max() < 1e-9

    paired = alternating({"full": lambda: np.full((n, n), 1.0), "sample": lambda: sample(surface, n, n),
                          "grid": lambda: evaluate_grid(surface, xs, ys)}, runs)
    t_fill, t_sample, t_grid = (min(paired[k]) for k in ("full", "sample", "grid"))
    med_fill, med_sample = statistics.median(paired["full"]), statistics.median(paired["sample"])
    t_scipy = best(scipy_both_axes, repeat=7)
    t_rows = best(scipy_row_by_row, repeat=3)
    t_lamb = best(lambda: f(xs[:, None], ys[None, :]), repeat=3)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    t_lamb_mesh = best(lambda: f(X, Y), repeat=3)
    rng = np.random.default_rng(0)
    px, py = rng.uniform(1, 5, 10**6), rng.uniform(1, 5, 10**6)
    t_scatter = best(lambda: evaluate_points(surface, px, py), repeat=5)
    t_scatter_lamb = best(lambda: f(px, py), repeat=3)

    print(f"## Speed: {n} x {n} regular sample of paper Example 4 (5x5 nodes)\n")
    print(f"`sample(surface, {n}, {n})` against `np.full(({n}, {n}), 1.0)`, {runs} runs each, alternating: "
          f"min {t_sample * 1e3:.2f} ms against {t_fill * 1e3:.2f} ms, **{t_sample / t_fill:.2f}x**; "
          f"median {med_sample * 1e3:.2f} ms against {med_fill * 1e3:.2f} ms, **{med_sample / med_fill:.2f}x**; "
          f"the first large grids of a process, in NumPy: {t_numpy * 1e3:.2f} ms (min of 5), "
          f"{t_numpy / t_fill:.1f}x\n")
    print("| method | time (ms) | ratio |")
    print("|---|---:|---:|")
    print(f"| NumPy `np.full` of the same size (the memory limit) | {t_fill * 1e3:.2f} | "
          f"lagsym is {t_grid / t_fill:.2f}x its time |")
    print(f"| **lagsym** `evaluate_grid` (tensor product, Chebyshev basis) | {t_grid * 1e3:.2f} | 1 |")
    print(f"| **lagsym** `sample(surface, n, n)` (with exact grid lines) | {t_sample * 1e3:.2f} | "
          f"{t_sample / t_grid:.2f}x |")
    print(f"| SciPy `BarycentricInterpolator`, along x then along y (vectorized) | {t_scipy * 1e3:.2f} | "
          f"{t_scipy / t_grid:.1f}x slower |")
    print(f"| SciPy `BarycentricInterpolator`, one interpolator per x row | {t_rows * 1e3:.1f} | "
          f"{t_rows / t_grid:.0f}x slower |")
    print(f"| `lambdify` of the expanded expression, broadcast `x[:, None]`, `y[None, :]` | {t_lamb * 1e3:.1f} | "
          f"{t_lamb / t_grid:.0f}x slower |")
    print(f"| `lambdify` of the expanded expression, on `meshgrid` arrays | {t_lamb_mesh * 1e3:.1f} | "
          f"{t_lamb_mesh / t_grid:.0f}x slower |")
    print()
    out = {"grid": t_grid, "scipy": t_scipy, "runs": runs, "n": n}
    print("| scattered points | time (ms) | ratio |")
    print("|---|---:|---:|")
    print(f"| **lagsym** `evaluate_points(surface, x, y)`, 10^6 random points | {t_scatter * 1e3:.1f} | 1 |")
    print(f"| `lambdify` of the expanded expression, same points | {t_scatter_lamb * 1e3:.1f} | "
          f"{t_scatter_lamb / t_scatter:.1f}x |")
    print()
    return out


def _chebyshev_like(n: int, a: float, b: float) -> list[Fraction]:
    return [Fraction(round((a + b) / 2 - (b - a) / 2 * math.cos(math.pi * (2 * k + 1) / (2 * n)), 3))
            .limit_denominator(1000) for k in range(n)]


def _nodes(kind: str, n: int) -> list[Fraction]:
    if kind == "paper":
        return [Fraction(k) for k in range(1, n + 1)]
    if kind == "equispaced 0-100":
        return [Fraction(100 * k, n - 1) for k in range(n)]
    return _chebyshev_like(n, 0, 100)


def _data(kind: str, xs, ys, rng) -> list[list[Fraction]]:
    if kind == "rough":  # heights like the paper's Example 4: two decimals, 1.00 to 3.40
        return [[Fraction(int(v), 100) for v in rng.integers(100, 341, len(ys))] for _ in xs]
    x0, x1, y0, y1 = float(xs[0]), float(xs[-1]), float(ys[0]), float(ys[-1])
    # smooth: an analytic function sampled to full float precision (every digit kept, exactly)
    return [[Fraction(1.0 + 0.5 * math.sin(2 * u + 1) * math.cos(3 * v) + 0.2 * u * v)
             for v in [(float(y) - y0) / (y1 - y0) for y in ys]]
            for u in [(float(x) - x0) / (x1 - x0) for x in xs]]


def _errors(surface, x, y, values) -> float:
    return max(abs(float(surface.exact_value(Fraction(a), Fraction(b)) - Fraction(c)))
               for a, b, c in zip(x.tolist(), y.tolist(), values.tolist()))


def accuracy(points: int = 60) -> None:
    print(f"## Accuracy: largest error at {points} random points / data range, against exact evaluation\n")
    print("bound: lagsym's stated bound; flagged: `lagsym check` and `sample` warn (bound > 1e-12).\n")
    print("| nodes | data | n x n | lagsym | bound | flagged | barycentric | power basis |")
    print("|---|---|---:|---:|---:|:---:|---:|---:|")
    rng = np.random.default_rng(2024)
    failures = 0
    for kind in ("paper", "equispaced 0-100", "Chebyshev-like 0-100"):
        for data in ("smooth", "rough"):
            for n in (3, 5, 8, 10, 12, 15, 20):
                xs = _nodes(kind, n)
                surface = lagrange_surface(grid_from_table(xs, xs, _data(data, xs, xs, rng)))
                ev = surface_evaluator(surface)
                g = surface.grid
                lo, hi = float(xs[0]), float(xs[-1])
                px, py = rng.uniform(lo, hi, points), rng.uniform(lo, hi, points)
                ours = _errors(surface, px, py, evaluate_points(surface, px, py)) / ev.data_range
                bary = np.einsum("pk,pk->p", basis_matrix(g.x_array, px) @ g.z_array, basis_matrix(g.y_array, py))
                bary_err = _errors(surface, px, py, bary) / ev.data_range
                power = np.polynomial.polynomial.polyval2d(px, py, np.array(surface.coefficients, dtype=float))
                power_err = _errors(surface, px, py, power) / ev.data_range
                bound = ev.relative_error_bound()
                flagged = bound > TRUST
                ok = (ours <= TRUST or flagged) and ours <= bound
                failures += not ok
                print(f"| {kind} | {data} | {n} | {ours:.1e} | {bound:.1e} | {'yes' if flagged else 'no'} | "
                      f"{bary_err:.1e} | {power_err:.1e} |" + ("" if ok else " **FAIL**"))
    print(f"\n{failures} case(s) where the error exceeded 1e-12 of the range unflagged, or exceeded the bound.\n")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--speed", action="store_true")
    p.add_argument("--accuracy", action="store_true")
    p.add_argument("--points", type=int, default=60, help="random points per accuracy case")
    p.add_argument("--runs", type=int, default=21, help="runs of the sample and of np.full, alternating")
    recorded.add_option(p)
    a = p.parse_args(argv)
    both = not (a.speed or a.accuracy)
    if a.speed or both:
        got = speed(runs=a.runs)
        recorded.record("sampling", task=f"a {got['n']}x{got['n']} grid of Example 4 (`evaluate_grid`)",
                        peer="SciPy's `BarycentricInterpolator` along both axes, vectorized",
                        ratio=got["scipy"] / got["grid"],
                        detail=f"best times: {got['grid'] * 1e3:.2f} ms against {got['scipy'] * 1e3:.2f} ms",
                        argv=argv, path=a.results)
    if a.accuracy or both:
        accuracy(a.points)
    return 0


if __name__ == "__main__":
    sys.exit(main())
