"""A million measured points from a file, fitted exactly: the whole `lagsym fit` command against a float peer.

The points are distinct places on a 0.001 mm lattice over 100 x 80 mm,
heights of a smooth part plus 0.01 mm noise, every coordinate a decimal of
three places as a scanner or a CMM writes them, in a CSV file with a header.
Each run is a fresh process, taken in turn so a busy spell of a shared
machine falls on both alike:

- ``lagsym fit points.csv --degree 8 -o surface.json``: reading the file
  exactly, the exact least-squares fit, its report (residuals, amplification,
  convex hull) and the surface file;
- the peer: ``numpy.loadtxt`` of the same file and ``numpy.linalg.lstsq`` in
  floating point on the Chebyshev Vandermonde matrix (no exact result).

The peer's time over lagsym's is recorded (``fit-file`` in
``benchmarks/results.json``), with both medians and lagsym's peak memory.

Run:  python3 benchmarks/bench_fit_file.py [--runs 3] [--points 1000000] [--degree 8]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import results as recorded
from runs import arguments

ROOT = Path(__file__).resolve().parent.parent

PEER = """
import sys
import numpy as np
d, degree = np.loadtxt(sys.argv[1], delimiter=",", skiprows=1), int(sys.argv[2])
x, y, z = d.T
vx = np.polynomial.chebyshev.chebvander((2 * x - 100) / 100, degree)
vy = np.polynomial.chebyshev.chebvander((2 * y - 80) / 80, degree)
np.linalg.lstsq((vx[:, :, None] * vy[:, None, :]).reshape(len(x), -1), z, rcond=None)
"""


def write_points(path: Path, n: int) -> None:
    rng = np.random.default_rng(0)
    keys = np.unique(rng.integers(0, 100_001 * 80_001, int(n * 1.01)))
    keys = rng.permutation(keys)[:n]
    xi, yi = keys // 80_001, keys % 80_001
    x, y = xi / 1000, yi / 1000
    zi = np.round(1000 * (10 + 0.04 * x - 0.03 * y + 3 * np.sin(np.pi * x / 120) * np.cos(np.pi * y / 160)
                          + rng.normal(0, 0.01, n))).astype(np.int64)
    cells = (f"{a // 1000}.{a % 1000:03d},{b // 1000}.{b % 1000:03d},{'-' if c < 0 else ''}{abs(c) // 1000}."
             f"{abs(c) % 1000:03d}\n" for a, b, c in zip(xi.tolist(), yi.tolist(), zi.tolist()))
    path.write_text("x,y,z\n" + "".join(cells))


def timed(argv: list[str]) -> tuple[float, int]:
    """Wall seconds and peak resident memory (bytes) of a fresh process running ``argv``."""
    t = time.perf_counter()
    proc = subprocess.Popen(argv, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t
    if status:
        raise SystemExit(f"{argv[2:4]} failed: {proc.stderr.read().decode()[-500:]}")
    return wall, usage.ru_maxrss * 1024


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--degree", type=int, default=8)
    a = arguments(__doc__, argv, ap)
    tmp = Path(tempfile.mkdtemp())
    points = tmp / "points.csv"
    write_points(points, a.points)
    runs = {"lagsym fit": [sys.executable, "-m", "lagsym", "fit", str(points), "--degree", str(a.degree), "-o",
                           str(tmp / "surface.json"), "--max-file-points", str(a.points + 1)],
            "numpy loadtxt + lstsq (float, the peer)": [sys.executable, "-c", PEER, str(points), str(a.degree)]}
    walls: dict[str, list[float]] = {k: [] for k in runs}
    peak: dict[str, int] = {k: 0 for k in runs}
    for _ in range(a.runs):
        for name, cmd in runs.items():
            wall, rss = timed(cmd)
            walls[name].append(wall)
            peak[name] = max(peak[name], rss)
    print(f"{a.points:,} points in a {points.stat().st_size / 1e6:.1f} MB file, degree {a.degree}x{a.degree}, "
          f"{a.runs} runs")
    print("| what | min s | median s | peak memory |")
    print("|---|---|---|---|")
    for name, ts in walls.items():
        print(f"| {name} | {min(ts):.2f} | {statistics.median(ts):.2f} | {peak[name] / 2 ** 30:.2f} GiB |")
    ours = statistics.median(walls["lagsym fit"])
    peer = statistics.median(walls["numpy loadtxt + lstsq (float, the peer)"])
    recorded.record("fit-file", task=f"the whole `lagsym fit` command on {a.points:,} scattered decimal points in a "
                    f"CSV file, degree {a.degree}x{a.degree}: reading them exactly, the exact fit, its report and "
                    "the surface file", peer="`numpy.loadtxt` and `numpy.linalg.lstsq` in floats on the same file "
                    "(no exact result), a fresh process too", ratio=peer / ours,
                    detail=f"medians of {a.runs} runs: {ours:.1f} s against {peer:.1f} s; lagsym's peak memory "
                    f"{peak['lagsym fit'] / 2 ** 30:.2f} GiB", argv=argv, path=a.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
