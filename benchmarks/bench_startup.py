"""``lagsym --version`` and ``lagsym --help`` from a cold start, against the bare interpreter and the imports it avoids.

Each run is a fresh process, as a user starts the command; the runs
alternate, so a busy spell of a shared machine falls on all alike.  The
peers: ``python -c pass`` (the interpreter alone, the floor of any Python
command), ``python -c "import numpy"`` and ``python -c "import sympy"`` (what
the command would pay if it imported the library's numeric or symbolic side
up front).  Printed: min and median of ``--runs`` runs, and the ratio of
each to ``lagsym --version``.

Run:  python3 benchmarks/bench_startup.py [--runs 9]
"""

from __future__ import annotations

import argparse
import os
import sys

import statistics

import results as recorded
from bench_equation import table


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=9)
    recorded.add_option(p)
    a = p.parse_args(argv)
    commands = {
        "lagsym --version": [sys.executable, "-m", "lagsym", "--version"],
        "lagsym --help": [sys.executable, "-m", "lagsym", "--help"],
        "python -c pass": [sys.executable, "-c", "pass"],
        'python -c "import numpy"': [sys.executable, "-c", "import numpy"],
        'python -c "import sympy"': [sys.executable, "-c", "import sympy"],
    }
    print(f"## start-up, fresh processes, {a.runs} runs each, load average {os.getloadavg()[0]:.1f}\n")
    times = table(commands, a.runs, "lagsym --version")
    ours, peer = statistics.median(times["lagsym --version"]), statistics.median(times['python -c "import sympy"'])
    recorded.record("startup", task="`lagsym --version`, a fresh process", peer="`python -c \"import sympy\"`",
                   ratio=peer / ours, detail=f"medians of {a.runs} runs: {ours:.3f} s against {peer:.3f} s",
                   argv=argv, path=a.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
