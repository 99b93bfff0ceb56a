"""Drop-cutter against the exact surface (lagsym) versus OpenCAMLib on STL triangulations of it.

Both place the same cutter (ball end, or with ``--corner R`` a bull nose, OpenCAMLib's
BullCutter) over the same (x, y) positions of a raster
on the paper's Example 4, scaled to millimetres.  The "exact" value is
lagsym's drop-cutter with a much finer search (``lattice=24, starts=8``).
OpenCAMLib sees the surface as triangles, so its cutter locations carry the
mesh's chordal error, and they can lie below the exact value (a gouge).
Each is timed ``--runs`` times, alternating (a busy spell of a shared machine
falls on all alike); the table gives the min and the median, and the ratios
of the mins and of the medians.

    python3 benchmarks/bench_dropcutter.py [--points 4000] [--mesh 50 100 200] [--corner 1] [--runs 3]

Needs ``opencamlib`` (``pip install opencamlib``; wheels for Python 3.11).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import results as recorded

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from lagsym.evaluate import evaluate_points  # noqa: E402
from lagsym.io import read_points  # noqa: E402
from lagsym.lagrange import lagrange_surface  # noqa: E402
from lagsym.toolpath import drop_cutter  # noqa: E402

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "paper-example-4.json"


def stl_surface(ocl, surface, n: int, scale: float):
    """An n x n grid of the exact surface, two triangles a cell, in mm."""
    x0, x1, y0, y1 = (float(v) for v in surface.grid.bounds)
    xs, ys = np.linspace(x0, x1, n + 1), np.linspace(y0, y1, n + 1)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    gz = evaluate_points(surface, gx, gy)
    pts = [[ocl.Point(gx[i, j] * scale, gy[i, j] * scale, gz[i, j] * scale) for j in range(n + 1)]
           for i in range(n + 1)]
    stl = ocl.STLSurf()
    for i in range(n):
        for j in range(n):
            a, b, c, d = pts[i][j], pts[i + 1][j], pts[i + 1][j + 1], pts[i][j + 1]
            stl.addTriangle(ocl.Triangle(a, b, c))
            stl.addTriangle(ocl.Triangle(a, c, d))
    return stl


def ocl_drop(ocl, stl, diameter: float, x, y, floor: float, corner: float | None = None):
    cutter = ocl.BallCutter(diameter, 4 * diameter) if corner is None else ocl.BullCutter(diameter, corner, 4 * diameter)
    bdc = ocl.BatchDropCutter()
    bdc.setSTL(stl)
    bdc.setCutter(cutter)
    for a, b in zip(x, y):
        bdc.appendPoint(ocl.CLPoint(float(a), float(b), floor))
    bdc.run()
    return np.array([p.z for p in bdc.getCLPoints()])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=4000, help="cutter locations (default 4000)")
    ap.add_argument("--mesh", type=int, nargs="+", default=[50, 100, 200], help="cells per side of the STL meshes")
    ap.add_argument("--scale", type=float, default=20.0)
    ap.add_argument("--diameter", type=float, default=6.0)
    ap.add_argument("--corner", type=float, help="corner radius (mm): a bull nose instead of a ball end")
    ap.add_argument("--runs", type=int, default=3, help="timed runs of each (default 3)")
    recorded.add_option(ap)
    args = ap.parse_args(argv)
    import opencamlib as ocl

    surface = lagrange_surface(read_points(EXAMPLE))
    x0, x1, y0, y1 = (float(v) for v in surface.grid.bounds)
    rows = max(int(np.sqrt(args.points / 2.5)), 2)
    cols = max(args.points // rows, 2)
    gx, gy = np.meshgrid(np.linspace(x0, x1, cols), np.linspace(y0, y1, rows))
    x, y = gx.ravel(), gy.ravel()
    r = args.diameter / 2 / args.scale
    shape = {"shape": "ball"} if args.corner is None else {"shape": "bull", "corner": args.corner / args.scale}
    name = "ball" if args.corner is None else f"bull nose R{args.corner:g}"

    drop_cutter(surface, x[:1], y[:1], r, **shape)  # the compiled kernel loaded, as OpenCAMLib's mesh is built, untimed
    exact = drop_cutter(surface, x, y, r, lattice=24, starts=8, margin=False, **shape) * args.scale
    floor = float(np.min(surface.grid.z_array)) * args.scale - 100.0
    meshes = {n: stl_surface(ocl, surface, n, args.scale) for n in args.mesh}
    runs = {"lagsym": lambda: drop_cutter(surface, x, y, r, **shape) * args.scale}
    for n, stl in meshes.items():
        runs[n] = lambda stl=stl: ocl_drop(ocl, stl, args.diameter, x * args.scale, y * args.scale, floor, args.corner)
    times: dict = {k: [] for k in runs}
    values = {}
    for _ in range(args.runs):
        for k, fn in runs.items():
            t = time.perf_counter()
            values[k] = fn()
            times[k].append(time.perf_counter() - t)
    best = {k: min(v) for k, v in times.items()}
    median = {k: statistics.median(v) for k, v in times.items()}

    print(f"Example 4 at scale {args.scale:g}: {len(x)} cutter locations, {name} D{args.diameter:g} mm, "
          f"{ocl.max_threads()} OpenCAMLib threads, {args.runs} runs each (min / median)")
    print(f"{'method':<28}{'time s':>15}{'vs lagsym':>19}{'max |err| mm':>15}{'below exact mm':>16}")
    for k in runs:
        err = values[k] - exact
        label = "lagsym exact drop-cutter" if k == "lagsym" else f"OpenCAMLib STL {k}x{k}x2"
        ratio = f"{best[k] / best['lagsym']:.2f}x / {median[k] / median['lagsym']:.2f}x"
        print(f"{label:<28}{f'{best[k]:.3f} / {median[k]:.3f}':>15}{ratio:>19}{np.abs(err).max():>15.2e}"
              f"{max(0.0, float(-err.min())):>16.2e}")
    coarse = min(args.mesh)
    err = values[coarse] - exact
    recorded.record("dropcutter" if args.corner is None else "dropcutter-bull",
                    task=f"drop-cutter, {name} D{args.diameter:g} mm at {len(x):,} positions on Example 4",
                    peer=f"OpenCAMLib on its coarsest mesh here, {coarse}x{coarse}", ratio=median[coarse] / median["lagsym"],
                    detail=f"medians of {args.runs}: {median['lagsym']:.3f} s against {median[coarse]:.3f} s; the mesh "
                    f"{float(np.abs(err).max()):.2g} mm off the exact value, lagsym {float(np.abs(values['lagsym'] - exact).max()):.2g} mm",
                    argv=argv, path=args.results)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
