"""A 50 x 50 piecewise surface's finishing plan against one polynomial's, per cutter location.

Both surfaces are made from one formula, ``10 + 5 sin(x/6) cos(y/8) + 0.02 x y``
(the formula of ``examples/part-20x20.csv``) over 98 x 98 mm, heights to three
decimals: the piecewise surface through a 50 x 50 grid 2 mm apart (49 x 49
exact bicubic pieces, ``lagsym piecewise``), the single polynomial through an
8 x 8 grid of Chebyshev extrema (degree 7, well conditioned).  Each is planned
by :func:`lagsym.toolpath.plan_toolpath` with the same cutter and steps, the
kernel loaded beforehand, each run on a fresh surface (the numeric
evaluators, every piece's included, are made in the time taken); the runs
alternate so a busy spell falls on both.  Printed: each plan's cutter
locations and its time per cutter location, CPU (worker processes included)
and wall.  Recorded: the single polynomial's wall time per cutter location
over the pieces' (the issue's target: at least 0.5, the pieces within twice
the polynomial).

Run:  python3 benchmarks/bench_piecewise.py [--runs 3]
"""

from __future__ import annotations

import math
import os
import resource
import statistics
import sys
import time
from fractions import Fraction
from pathlib import Path

import results as recorded
from runs import arguments

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from lagsym.grid import grid_from_table  # noqa: E402
from lagsym.lagrange import lagrange_surface  # noqa: E402
from lagsym.machine import RasterSpec, Tool  # noqa: E402
from lagsym.surfaces.piecewise import piecewise_surface  # noqa: E402
from lagsym.toolpath import drop_cutter, plan_toolpath  # noqa: E402
from lagsym.toolpath.dropcutter import evaluator_of  # noqa: E402

SIDE, NODES, DEGREE = 98.0, 50, 7
DIAMETER, STEPOVER, STEP = 6.0, 1.0, 0.2


def height(x: float, y: float) -> Fraction:
    """The formula's height, to three decimals (as a measured or tabulated file has it)."""
    return Fraction(round(10 + 5 * math.sin(x / 6) * math.cos(y / 8) + 0.02 * x * y, 3)).limit_denominator(1000)


def grid(nodes: list[Fraction]):
    return grid_from_table(nodes, nodes, [[height(float(x), float(y)) for y in nodes] for x in nodes])


def grids():
    """The piecewise surface's 50 x 50 grid and the single polynomial's 8 x 8 grid of Chebyshev extrema."""
    even = [Fraction(SIDE) * k / (NODES - 1) for k in range(NODES)]
    cheb = [Fraction(round(SIDE / 2 * (1 - math.cos(math.pi * k / DEGREE)), 3)).limit_denominator(1000)
            for k in range(DEGREE + 1)]
    return grid(even), grid(cheb)


def _cpu() -> float:
    """CPU seconds of this process and of its finished children (a plan's worker processes)."""
    own, done = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + done.ru_utime + done.ru_stime


def main(argv=None) -> int:
    args = arguments(__doc__, argv)
    grid_pieces, grid_single = grids()
    make = {"pieces": lambda: piecewise_surface(grid_pieces), "single": lambda: lagrange_surface(grid_single)}
    tool, raster = Tool("ball", DIAMETER), RasterSpec("x", STEPOVER, STEP)
    drop_cutter(make["single"](), 30.0, 30.0, DIAMETER / 2)  # the compiled kernel loaded, untimed
    per, wall, count = {"pieces": [], "single": []}, {"pieces": [], "single": []}, {}
    for _ in range(args.runs):
        for name in per:
            surface = make[name]()  # a fresh surface: its numeric evaluators are made in the time taken
            c, w = _cpu(), time.perf_counter()
            tp = plan_toolpath(surface, tool, raster, evaluator=evaluator_of(surface))
            per[name].append((_cpu() - c) / len(tp))
            wall[name].append((time.perf_counter() - w) / len(tp))
            count[name] = (len(tp), tp.fine_points)
    for name, v in per.items():
        print(f"{name}: {count[name][0]} cutter locations (from {count[name][1]} samples); CPU per cutter location "
              f"min {min(v) * 1e6:.0f} us, median {statistics.median(v) * 1e6:.0f} us, wall median "
              f"{statistics.median(wall[name]) * 1e6:.0f} us ({args.runs} runs, load "
              f"average {os.getloadavg()[0]:.1f})")
    p, s = statistics.median(wall["pieces"]), statistics.median(wall["single"])
    cp, cs = statistics.median(per["pieces"]), statistics.median(per["single"])
    print(f"ratio single / pieces per cutter location: wall {s / p:.2f}, CPU {cs / cp:.2f}")
    recorded.record("piecewise", task=f"finishing a {NODES}x{NODES} piecewise surface ({(NODES - 1) ** 2:,} bicubic "
                    f"pieces, ball D{DIAMETER:g} mm, side step {STEPOVER:g} mm), per cutter location",
                    peer=f"the same plan on one degree-{DEGREE} polynomial of the same formula",
                    ratio=s / p, detail=f"wall medians of {args.runs}: {p * 1e6:.0f} us against {s * 1e6:.0f} us a "
                    f"cutter location; CPU {cp * 1e6:.0f} us against {cs * 1e6:.0f} us", argv=argv, path=args.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
