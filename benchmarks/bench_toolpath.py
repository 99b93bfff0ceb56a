"""The whole finishing plan (lagsym) versus OpenCAMLib's BatchDropCutter on the same positions.

lagsym plans the issue's raster on the paper's Example 4 at scale 20: a 6 mm ball,
side step 0.5 mm, step 0.2 mm, every move checked against the exact cutter path.
OpenCAMLib then drops the same ball at the plan's cutter locations (x, y) onto an
STL triangulation of the surface fine enough to come within about 5 um of it
(``--mesh`` cells per side; the error measured on a sample of the positions is
printed).  Both run in this process; the times are the minimum and median of
``--runs`` runs, OpenCAMLib's mesh built and lagsym's compiled drop-cutter
loaded once outside the timing.

    python3 benchmarks/bench_toolpath.py [--quick] [--runs 3] [--mesh 360]

The process first asks glibc's malloc to keep freed memory, as the
``lagsym`` command does (:func:`lagsym.allocator.keep_freed_memory`).

``--quick`` plans a side step of 2 mm instead and drops OpenCAMLib's cutter on
the first ``--ocl-points`` positions only, its time scaled by positions to all
of them.  Needs ``opencamlib`` (``pip install opencamlib``).
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import results as recorded
from runs import arguments, example4

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_dropcutter import ocl_drop, stl_surface  # noqa: E402

from lagsym.machine import MachineSettings, RasterSpec, Tool  # noqa: E402
from lagsym.toolpath import drop_cutter, plan_toolpath  # noqa: E402

SCALE, DIAMETER, STEP = 20.0, 6.0, 0.2


def _cpu() -> float:
    """CPU seconds of this process and of its finished children (a plan's worker processes)."""
    own, done = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + done.ru_utime + done.ru_stime


def _times(run, runs: int):
    """Wall and CPU seconds of ``runs`` runs: ``(wall min, wall median, cpu min, cpu median, result)``."""
    wall, cpu, result = [], [], None
    for _ in range(runs):
        t, c = time.perf_counter(), _cpu()
        result = run()
        wall.append(time.perf_counter() - t)
        cpu.append(_cpu() - c)
    return min(wall), statistics.median(wall), min(cpu), statistics.median(cpu), result


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="side step 2 mm, OpenCAMLib on a sample of the positions")
    ap.add_argument("--mesh", type=int, default=360, help="STL cells per side (default 360: within about 5 um)")
    ap.add_argument("--ocl-points", type=int, default=4000, help="with --quick, positions OpenCAMLib drops on")
    args = arguments(__doc__, argv, ap)
    import opencamlib as ocl

    surface, ev = example4(SCALE, DIAMETER)
    stepover = 2.0 if args.quick else 0.5
    raster = RasterSpec("x", stepover, STEP)
    settings = MachineSettings(mm_per_unit=SCALE)
    tool = Tool("ball", DIAMETER)
    best, median, cbest, cmedian, tp = _times(lambda: plan_toolpath(surface, tool, raster, settings.placement, settings.program, evaluator=ev, stock_to_leave_mm=settings.stock_to_leave_mm),
                                              args.runs)
    n = len(tp)
    print(f"Example 4 at scale {SCALE:g}, ball D{DIAMETER:g} mm, side step {stepover:g} mm, step {STEP:g} mm: "
          f"{n} cutter locations in {int(tp.rows.max()) + 1} rows (from {tp.fine_points} samples)")
    print(f"lagsym whole plan (drop-cutter, chordal checks, filter): wall min {best:.2f} s, median {median:.2f} s; "
          f"CPU min {cbest:.2f} s, median {cmedian:.2f} s ({args.runs} runs, load average "
          f"{os.getloadavg()[0]:.1f})")

    x, y = tp.points_mm[:, 0], tp.points_mm[:, 1]
    m = min(n, args.ocl_points) if args.quick else n
    t = time.perf_counter()
    stl = stl_surface(ocl, surface, args.mesh, SCALE)
    t_mesh = time.perf_counter() - t
    floor = float(np.min(surface.grid.z_array)) * SCALE - 100.0
    o_best, o_median, o_cbest, o_cmedian, zo = _times(lambda: ocl_drop(ocl, stl, DIAMETER, x[:m], y[:m], floor), args.runs)
    scale = n / m
    # The mesh's error: against the exact drop-cutter value at a sample of the positions inside the box.
    x0, x1, y0, y1 = (float(v) * SCALE for v in surface.grid.bounds)
    inside = np.flatnonzero((x[:m] >= x0 + 3) & (x[:m] <= x1 - 3) & (y[:m] >= y0 + 3) & (y[:m] <= y1 - 3))[::7][:600]
    exact = drop_cutter(surface, x[inside] / SCALE, y[inside] / SCALE, DIAMETER / 2 / SCALE, lattice=24, starts=8,
                        margin=False, evaluator=ev) * SCALE
    err = np.abs(zo[inside] - exact).max() if inside.size else float("nan")
    note = f", {m} positions timed, scaled by {scale:.2f}" if m < n else ""
    print(f"OpenCAMLib BatchDropCutter, STL {args.mesh}x{args.mesh}x2 ({t_mesh:.1f} s to build; max error "
          f"{err * 1000:.2f} um on {inside.size} positions), {ocl.max_threads()} threads{note}: "
          f"wall min {o_best * scale:.2f} s, median {o_median * scale:.2f} s; CPU min {o_cbest * scale:.2f} s, "
          f"median {o_cmedian * scale:.2f} s")
    print(f"ratio OpenCAMLib / lagsym: wall {o_best * scale / best:.2f} (min), {o_median * scale / median:.2f} "
          f"(median); CPU {o_cbest * scale / cbest:.2f} (min), {o_cmedian * scale / cmedian:.2f} (median)")
    recorded.record("toolpath-quick" if args.quick else "toolpath",
                    task=f"the whole finishing plan of Example 4 at scale {SCALE:g} (ball D{DIAMETER:g} mm, side step "
                    f"{stepover:g} mm, {n:,} cutter locations)",
                    peer=f"OpenCAMLib's `BatchDropCutter` at the same positions, {args.mesh}x{args.mesh} mesh",
                    ratio=o_median * scale / median, detail=f"wall medians of {args.runs}: {median:.2f} s against "
                    f"{o_median * scale:.2f} s{note}; mesh error {err * 1000:.2f} um", argv=argv, path=args.results)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
