"""Steep-and-shallow finishing versus the scallop raster for the same requested cusp, same run.

Both plan the paper's Example 4 at scale 20 with a 6 mm ball, a requested
cusp of 0.01 mm normal to the surface and a chordal tolerance of 0.005 mm:
``lagsym toolpath --scallop 0.01`` (rows spaced for the worst slope across
each row) and ``--strategy steep-shallow`` (the raster on the slopes below
the threshold, contours at constant heights above it).  The runs alternate,
raster first, so a busy spell of a shared machine falls on both; the times
are the minimum and median of ``--runs`` runs, the compiled drop-cutter
loaded once outside the timing.  Both meet 0.015 mm left normal to the
surface (``tests/test_waterline.py``, measured by an independent swept ball);
the figure recorded is the raster's plan time over steep-and-shallow's (below
1: the raster plans faster), with the cutter locations of each.

    python3 benchmarks/bench_waterline.py [--runs 3]
"""

from __future__ import annotations

import os
import statistics

import results as recorded
from runs import alternate, arguments, example4

from lagsym.machine import Placement, RasterSpec, Tool
from lagsym.toolpath import plan_strategy

SCALE, DIAMETER, CUSP, TOL = 20.0, 6.0, 0.01, 0.005


def main(argv=None) -> int:
    args = arguments(__doc__, argv)
    surface, ev = example4(SCALE, DIAMETER)
    spec = RasterSpec("x", None, None, CUSP, TOL)
    times, plans = alternate(args.runs, {strategy: lambda strategy=strategy: plan_strategy(
        surface, Tool("ball", DIAMETER), spec, Placement(SCALE), evaluator=ev, strategy=strategy)
        for strategy in ("raster", "steep-shallow")})
    r, s = plans["raster"], plans["steep-shallow"]
    for name, tp in plans.items():
        w = times[name]
        print(f"{name}: {len(tp)} cutter locations; wall min {min(w):.2f} s, median {statistics.median(w):.2f} s "
              f"({args.runs} runs, load average {os.getloadavg()[0]:.1f})")
    print(s.note)
    ratio = statistics.median(times["raster"]) / statistics.median(times["steep-shallow"])
    print(f"ratio raster / steep-shallow plan time: {ratio:.2f}; cutter locations {len(s)} against {len(r)}")
    recorded.record("steep-shallow",
                    task=f"steep-and-shallow finishing of Example 4 at scale {SCALE:g} (ball D{DIAMETER:g} mm, cusp "
                    f"{CUSP:g} mm, {len(s):,} cutter locations)",
                    peer=f"lagsym's scallop raster for the same cusp ({len(r):,} cutter locations)",
                    ratio=ratio, detail=f"wall medians of {args.runs}: "
                    f"{statistics.median(times['steep-shallow']):.2f} s against {statistics.median(times['raster']):.2f} s", argv=argv, path=args.results)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
