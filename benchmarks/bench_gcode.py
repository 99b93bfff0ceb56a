"""Writing and reading point-list G-code: lagsym's writer and reader against the plain per-line ways.

The peers, run in the same process on the same moves:

* writing: one f-string a line with every word (``f"G01 X{x:.3f} ..."``), the
  way most scripts write G-code (and which may print ``-0.000``);
* writing with :func:`lagsym.gcode.numbers.fixed` per number (exact decimal
  rounding, slow);
* reading: ``float()`` of every word split on spaces, without any checks.

    python3 benchmarks/bench_gcode.py [--moves 1000000]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import results as recorded

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from lagsym.gcode import parse_moves  # noqa: E402
from lagsym.machine import MachineSettings  # noqa: E402
from lagsym.gcode.numbers import fixed  # noqa: E402
from lagsym.post.program import PointProgram, write_program  # noqa: E402


def naive_write(points) -> str:
    return "\n".join(f"G01 X{x:.3f} Y{y:.3f} Z{z:.3f}" for x, y, z in points.tolist()) + "\n"


def fixed_write(points) -> str:
    return "\n".join(f"G01 X{fixed(x, 3)} Y{fixed(y, 3)} Z{fixed(z, 3)}" for x, y, z in points.tolist()) + "\n"


def naive_read(text: str) -> np.ndarray:
    out = []
    for line in text.splitlines():
        w = {p[0]: float(p[1:]) for p in line.split() if p[:1] in "XYZ"}
        if w:
            out.append((w.get("X", 0.0), w.get("Y", 0.0), w.get("Z", 0.0)))
    return np.array(out)


def timed(fn, *a):
    t = time.perf_counter()
    r = fn(*a)
    return time.perf_counter() - t, r


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--moves", type=int, default=1_000_000)
    recorded.add_option(ap)
    ap.add_argument("--fixed-sample", type=int, default=100_000, help="moves for the slow fixed() peer (scaled up)")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(6)
    # A raster-like path: x advancing, y in rows, z varying, so modal words repeat as in real programs.
    n = args.moves
    x = np.tile(np.linspace(0.0, 80.0, 400), n // 400 + 1)[:n]
    y = np.repeat(np.arange(n // 400 + 1) * 0.5, 400)[:n]
    z = 20.0 + 10.0 * np.sin(x / 9.0) * np.cos(y / 7.0) + rng.normal(0, 1e-3, n)
    pts = np.stack([x, y, z], axis=1)
    s = MachineSettings(dialect="fanuc", safe_z_mm=100.0)

    t_lag, text = timed(lambda: write_program(PointProgram(pts, s)))
    t_naive, naive_text = timed(naive_write, pts)
    k = min(args.fixed_sample, n)
    t_fixed, _ = timed(fixed_write, pts[:k])
    t_fixed *= n / k
    t_read, moves = timed(parse_moves, text)
    t_nread, _ = timed(naive_read, naive_text)
    assert len(moves.feeds) == n
    print(f"{n} moves")
    print(f"{'task':<44}{'time s':>9}{'vs lagsym':>11}")
    print(f"{'write: lagsym write_program (modal words)':<44}{t_lag:>9.2f}{1.0:>10.2f}x   {len(text) / 1e6:.1f} MB")
    print(f"{'write: f-string, every word':<44}{t_naive:>9.2f}{t_naive / t_lag:>10.2f}x"
          f"   {len(naive_text) / 1e6:.1f} MB")
    print(f"{'write: fixed() per number (extrapolated)':<44}{t_fixed:>9.2f}{t_fixed / t_lag:>10.2f}x")
    print(f"{'read: lagsym parse_moves (checked)':<44}{t_read:>9.2f}{1.0:>10.2f}x")
    print(f"{'read: split and float(), no checks':<44}{t_nread:>9.2f}{t_nread / t_read:>10.2f}x")
    recorded.record("gcode", task=f"writing {n:,} moves of point-list G-code",
                   peer="exact decimal rounding per number (`fixed()`, extrapolated)", ratio=t_fixed / t_lag,
                   detail=f"{t_lag:.2f} s ({len(text) / 1e6:.1f} MB); an f-string per line {t_naive:.2f} s, "
                          f"which may print -0.000", argv=argv, path=args.results)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
