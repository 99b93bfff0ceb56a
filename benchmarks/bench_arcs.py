"""The README's finishing plan with arcs (``--arcs``) versus the same plan without them.

lagsym plans Example 4 at scale 20 with a 6 mm ball, side step 0.4 mm, step
0.2 mm (the README's finishing settings), once with the arcs fitted along its
rows and once without; the peer is the plan without arcs, so the ratio is the
share of the plan with arcs that the plan alone takes (1 would be free arcs).
Both run in this process, alternately; the times are the minimum and median
of ``--runs`` runs, the compiled drop-cutter loaded once outside the timing.

    python3 benchmarks/bench_arcs.py [--runs 3]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import results as recorded

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from lagsym.allocator import keep_freed_memory  # noqa: E402
from lagsym.evaluate import surface_evaluator  # noqa: E402
from lagsym.io import read_points  # noqa: E402
from lagsym.lagrange import lagrange_surface  # noqa: E402
from lagsym.machine import MachineSettings, RasterSpec, Tool  # noqa: E402
from lagsym.toolpath import drop_cutter, plan_toolpath  # noqa: E402

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "paper-example-4.json"
SCALE, DIAMETER, STEPOVER, STEP = 20.0, 6.0, 0.4, 0.2


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3, help="runs of each (default 3)")
    recorded.add_option(ap)
    args = ap.parse_args(argv)
    keep_freed_memory()
    surface = lagrange_surface(read_points(EXAMPLE))
    ev = surface_evaluator(surface)
    settings = MachineSettings(mm_per_unit=SCALE, dialect="fanuc")
    tool = Tool("ball", DIAMETER)
    drop_cutter(surface, 3.0, 3.0, DIAMETER / 2 / SCALE, evaluator=ev)  # the compiled kernel loaded, untimed
    walls = {False: [], True: []}
    plans = {}
    for _ in range(args.runs):
        for arcs in (False, True):
            t = time.perf_counter()
            plans[arcs] = plan_toolpath(surface, tool, RasterSpec("x", STEPOVER, STEP, arcs=arcs), settings.placement,
                                        settings.program, evaluator=ev)
            walls[arcs].append(time.perf_counter() - t)
    plain, with_arcs = statistics.median(walls[False]), statistics.median(walls[True])
    arcs = plans[True].arcs
    print(f"Example 4 at scale {SCALE:g}, ball D{DIAMETER:g} mm, side step {STEPOVER:g} mm, step {STEP:g} mm: "
          f"{len(plans[True])} cutter locations, {len(arcs)} arcs ({arcs.plane}) saving {arcs.blocks_saved()} blocks")
    print(f"plan without arcs: wall min {min(walls[False]):.2f} s, median {plain:.2f} s; with arcs: wall min "
          f"{min(walls[True]):.2f} s, median {with_arcs:.2f} s ({args.runs} runs each, load average "
          f"{os.getloadavg()[0]:.1f})")
    recorded.record("arcs", task=f"the README's finishing plan of Example 4 with arcs (ball D{DIAMETER:g} mm, "
                    f"side step {STEPOVER:g} mm, {len(arcs):,} arcs)", peer="the same plan without arcs",
                    ratio=plain / with_arcs, detail=f"wall medians of {args.runs}: {with_arcs:.2f} s against "
                    f"{plain:.2f} s", argv=argv, path=args.results)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
