"""10,000 scattered measured points fitted to degree 6x6: lagsym's exact least squares against a float peer.

The points are uniform random over 100 x 80 mm with heights of a smooth part
plus 0.02 mm noise, every coordinate a decimal of three places (as a probe
writes them).  Measured, alternating so a busy spell of a shared machine
falls on both alike:

- ``fit_coefficients``: the exact rational least-squares coefficients (the
  integer moments, the exact solve, the change back to powers of x and y);
- ``fit_surface``: the whole fit at given degrees: the coefficients, every
  residual exactly, the amplification (sampled), the convex hull and the
  surface every command takes;
- the whole ``lagsym fit POINTS --degree 6 -o surface.json`` command, a fresh
  process: reading the file, the fit, its report and the surface file;
- the peer: ``numpy.linalg.lstsq`` in floating point on the Chebyshev
  Vandermonde matrix of the same points (no exact result).

Each line gives min and median of ``--runs`` runs and the ratio to the peer;
the peer's time over ``fit_surface``'s is recorded (``fit`` in
``benchmarks/results.json``), with the times of both and of the command.

Run:  python3 benchmarks/bench_fit.py [--runs 5] [--points 10000] [--degree 6]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

import results as recorded

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from lagsym.fit import fit_coefficients, fit_surface  # noqa: E402


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--points", type=int, default=10_000)
    p.add_argument("--degree", type=int, default=6)
    recorded.add_option(p)
    a = p.parse_args(argv)
    rng = np.random.default_rng(0)
    x, y = np.round(rng.uniform(0, 100, a.points), 3), np.round(rng.uniform(0, 80, a.points), 3)
    z = np.round(10 + 0.04 * x - 0.03 * y + 3 * np.sin(np.pi * x / 120) * np.cos(np.pi * y / 160)
                 + rng.normal(0, 0.02, a.points), 3)
    pts = [(Fraction(f"{u:.3f}"), Fraction(f"{v:.3f}"), Fraction(f"{w:.3f}")) for u, v, w in zip(x, y, z)]
    d = (a.degree, a.degree)

    def peer():
        vx = np.polynomial.chebyshev.chebvander((2 * x - 100) / 100, a.degree)
        vy = np.polynomial.chebyshev.chebvander((2 * y - 80) / 80, a.degree)
        np.linalg.lstsq((vx[:, :, None] * vy[:, None, :]).reshape(len(x), -1), z, rcond=None)

    tmp = Path(tempfile.mkdtemp())
    (tmp / "points.csv").write_text("x,y,z\n" + "".join(f"{u:.3f},{v:.3f},{w:.3f}\n" for u, v, w in zip(x, y, z)))

    def command():
        subprocess.run([sys.executable, "-m", "lagsym", "fit", str(tmp / "points.csv"), "--degree", str(a.degree),
                        "-o", str(tmp / "surface.json")], cwd=ROOT, check=True, capture_output=True)

    cases = {"numpy lstsq (float, the peer)": peer,
             "fit_coefficients (exact)": lambda: fit_coefficients(pts, d),
             "fit_surface (exact, with residuals and report)": lambda: fit_surface(pts, d),
             "the whole `lagsym fit` command": command}
    times: dict[str, list[float]] = {k: [] for k in cases}
    for _ in range(a.runs):
        for name, run in cases.items():
            t = time.perf_counter()
            run()
            times[name].append(time.perf_counter() - t)
    base = statistics.median(times["numpy lstsq (float, the peer)"])
    print(f"{a.points} points, degree {a.degree}x{a.degree}, {a.runs} runs")
    print("| what | min s | median s | median / peer |")
    print("|---|---|---|---|")
    for name, ts in times.items():
        print(f"| {name} | {min(ts):.3f} | {statistics.median(ts):.3f} | {statistics.median(ts) / base:.1f}x |")
    fit = statistics.median(times["fit_surface (exact, with residuals and report)"])
    whole = statistics.median(times["the whole `lagsym fit` command"])
    recorded.record("fit", task=f"the exact least-squares fit of {a.points:,} scattered decimal points, degree "
                    f"{a.degree}x{a.degree}, with its residuals and report (`fit_surface`)",
                    peer="`numpy.linalg.lstsq` in floats on the same points (no exact result)", ratio=base / fit,
                    detail=f"medians of {a.runs} runs: {fit:.2f} s against {base * 1000:.1f} ms; the whole `lagsym "
                    f"fit` command {whole:.2f} s", argv=argv, path=a.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
