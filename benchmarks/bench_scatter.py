"""10**6 scattered points: lagsym's evaluator against a lambdified SymPy expression through NumPy, in one run.

The surface is the paper's Example 4 (5x5 nodes); the points are uniform
random in its control box, with some on control points exactly.  Measured,
alternating so a busy spell of a shared machine falls on all alike:

- ``evaluate_points``: the stable evaluator, whose result keeps
  :meth:`SurfaceEvaluator.error_bound` (the compensated Chebyshev basis, each
  value rounded once; control points return their heights exactly); 10**6
  points run its compiled kernel, loaded before the timed runs (``load_compiled()``);
- the same arithmetic in NumPy (``evaluate_points`` on blocks of 131,072
  points, below the compiled kernel's threshold): the same values, bit for bit;
- ``SurfaceEvaluator.fast_points``: the plain float64 recurrence, for the
  many small batches of a search; its basis adds up to ``k**2`` units of
  float64 rounding at degree ``k``, so the bound does not hold for it;
- ``lambdify`` of the expanded SymPy expression (``modules="numpy"``), the
  peer: the power basis.

Each line gives min and median of ``--runs`` runs and the ratio to the peer,
and the largest error against exact rational evaluation at ``--check`` of the
points (the first 1,000 of them control points) as a fraction of the bound.

Run:  python3 benchmarks/bench_scatter.py [--runs 9] [--points 1000000]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

import results as recorded

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from lagsym.evaluate import (COMPILED_POINTS, evaluate_points, lambdify_surface, load_compiled,  # noqa: E402
                             surface_evaluator)
from lagsym.io import read_points  # noqa: E402
from lagsym.lagrange import lagrange_surface  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


def _largest_error(surface, x, y, z) -> float:
    return max(abs(float(Fraction(c) - surface.exact_value(Fraction(a), Fraction(b))))
               for a, b, c in zip(x.tolist(), y.tolist(), z.tolist()))


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=9)
    p.add_argument("--points", type=int, default=10**6)
    recorded.add_option(p)
    p.add_argument("--check", type=int, default=21_000, help="points checked against exact evaluation")
    a = p.parse_args(argv)
    surface = lagrange_surface(read_points(ROOT / "examples" / "paper-example-4.json"))
    ev = surface_evaluator(surface)
    rng = np.random.default_rng(0)
    px, py = rng.uniform(1, 5, a.points), rng.uniform(1, 5, a.points)
    px[:1000], py[:1000] = rng.integers(1, 6, 1000), rng.integers(1, 6, 1000)  # control points
    f = lambdify_surface(surface)
    block = COMPILED_POINTS // 2

    def numpy_engine():
        return np.concatenate([evaluate_points(surface, px[i:i + block], py[i:i + block])
                               for i in range(0, a.points, block)])

    methods = {
        "`lambdify` of the SymPy expression, NumPy (peer)": lambda: f(px, py),
        "**lagsym** `evaluate_points` (bound kept; compiled)": lambda: evaluate_points(surface, px, py),
        "lagsym `evaluate_points` in blocks of 131,072 (bound kept; NumPy, one thread)": numpy_engine,
        "lagsym `fast_points` (float64 basis, no bound)": lambda: ev.fast_points(px, py),
    }
    times: dict[str, list[float]] = {k: [] for k in methods}
    load_compiled()
    results = {k: fn() for k, fn in methods.items()}
    engines = list(results.values())[1:3]
    if a.points >= COMPILED_POINTS and not np.array_equal(*engines):
        raise SystemExit("the compiled kernel and NumPy differ")
    for _ in range(a.runs):
        for k, fn in methods.items():
            t = time.perf_counter()
            fn()
            times[k].append(time.perf_counter() - t)
    bound = ev.error_bound()
    check = slice(0, min(a.check, a.points))
    peer = next(iter(times))
    pmin, pmed = min(times[peer]), statistics.median(times[peer])
    print(f"## {a.points:,} scattered points on paper Example 4, {a.runs} runs each\n")
    print(f"error: largest against exact rational evaluation at {check.stop:,} of the points (1,000 on control "
          f"points), / the bound {bound:.2e}\n")
    print("| method | min (ms) | median (ms) | peer time / its time (min / median) | error / bound |")
    print("|---|---:|---:|---:|---:|")
    for k, ts in times.items():
        lo, med = min(ts), statistics.median(ts)
        err = _largest_error(surface, px[check], py[check], results[k][check]) / bound
        print(f"| {k} | {lo * 1e3:.1f} | {med * 1e3:.1f} | {pmin / lo:.2f}x / {pmed / med:.2f}x | {err:.3f} |")
    ours = statistics.median(times["**lagsym** `evaluate_points` (bound kept; compiled)"])
    recorded.record("scatter", task=f"{a.points:,} scattered points, error bound kept",
                    peer="`lambdify` of the expanded SymPy expression",
                    ratio=pmed / ours, detail=f"medians of {a.runs} runs: {ours * 1e3:.1f} ms against "
                    f"{pmed * 1e3:.1f} ms", argv=argv, path=a.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
