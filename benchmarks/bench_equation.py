"""``lagsym equation`` from a cold start, against the SymPy route printing the same text, in one run.

Each run is a fresh process, as a user starts the command:

- lagsym: ``python -m lagsym equation FILE`` (no SymPy imported);
- the SymPy route: a process that reads the same file and prints
  ``str(surface.expr)``, the text SymPy's printer gives (it imports SymPy);
- ``python -c "import sympy"``: the import alone, the floor of any SymPy route.

The texts of the first two are compared before any time is taken.  The runs
alternate, so a busy spell of a shared machine falls on all three alike;
min and median of ``--runs`` runs are printed, and the ratio of each.

Run:  python3 benchmarks/bench_equation.py [--runs 9] [--file examples/paper-example-4.json]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import results as recorded

ROOT = Path(__file__).resolve().parent.parent

SYMPY_ROUTE = ("import sys; from lagsym import read_points, lagrange_surface; "
               "print('z = ' + str(lagrange_surface(read_points(sys.argv[1])).expr))")


def _run(argv: list[str]) -> tuple[float, str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    t = time.perf_counter()
    done = subprocess.run(argv, cwd=ROOT, env=env, capture_output=True, text=True, check=True)
    return time.perf_counter() - t, done.stdout


def table(commands: dict[str, list[str]], runs: int, base: str) -> dict[str, list[float]]:
    """Time each command ``runs`` times in fresh processes, alternating; print min, median and the ratios to ``base``."""
    times: dict[str, list[float]] = {k: [] for k in commands}
    for _ in range(runs):
        for k, cmd in commands.items():
            times[k].append(_run(cmd)[0])
    base_min, base_med = min(times[base]), statistics.median(times[base])
    print(f"| command | min (s) | median (s) | ratio to {base} (min / median) |")
    print("|---|---:|---:|---:|")
    for k, ts in times.items():
        lo, med = min(ts), statistics.median(ts)
        print(f"| {k} | {lo:.3f} | {med:.3f} | {lo / base_min:.2f}x / {med / base_med:.2f}x |")
    return times


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=9)
    p.add_argument("--file", default="examples/paper-example-4.json")
    recorded.add_option(p)
    a = p.parse_args(argv)
    commands = {
        "lagsym equation": [sys.executable, "-m", "lagsym", "equation", a.file],
        "SymPy route, same text": [sys.executable, "-c", SYMPY_ROUTE, a.file],
        'python -c "import sympy"': [sys.executable, "-c", "import sympy"],
    }
    ours, theirs = _run(commands["lagsym equation"])[1], _run(commands["SymPy route, same text"])[1]
    if ours != theirs:
        raise SystemExit("the two routes printed different text")
    print(f"## `lagsym equation {a.file}`, fresh processes, {a.runs} runs each (same text checked)\n")
    times = table(commands, a.runs, "lagsym equation")
    ours, peer = statistics.median(times["lagsym equation"]), statistics.median(times["SymPy route, same text"])
    recorded.record("equation", task="`lagsym equation` of Example 4, a fresh process",
                   peer="printing the same text through SymPy", ratio=peer / ours,
                   detail=f"medians of {a.runs} runs: {ours:.3f} s against {peer:.3f} s", argv=argv, path=a.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
