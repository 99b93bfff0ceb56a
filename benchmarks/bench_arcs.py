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

import os
import statistics

import results as recorded
from runs import alternate, arguments, example4

from lagsym.machine import MachineSettings, RasterSpec, Tool
from lagsym.toolpath import plan_toolpath

SCALE, DIAMETER, STEPOVER, STEP = 20.0, 6.0, 0.4, 0.2


def main(argv=None) -> int:
    args = arguments(__doc__, argv)
    surface, ev = example4(SCALE, DIAMETER)
    settings = MachineSettings(mm_per_unit=SCALE, dialect="fanuc")
    tool = Tool("ball", DIAMETER)

    def plan(arcs):
        return lambda: plan_toolpath(surface, tool, RasterSpec("x", STEPOVER, STEP, arcs=arcs), settings.placement,
                                     settings.program, evaluator=ev)

    walls, plans = alternate(args.runs, {False: plan(False), True: plan(True)})
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
