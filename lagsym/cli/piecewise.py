"""``lagsym piecewise POINTS -o surface.json``: exact C1 bicubic pieces through a grid too large for one polynomial."""

from __future__ import annotations

import io

from ..export.piecewisejson import write_piecewise_json
from ..surfaces.piecewise import piecewise_surface
from ._common import add_points_arguments, emit, load_points

DESCRIPTION = """Build the smooth piecewise surface through the grid of control points in
FILE: one exact bicubic polynomial per cell of the grid, for grids too large
for one polynomial (20 x 20, 50 x 50; one polynomial through them amplifies
errors in the points thousands of times, see 'lagsym check').  The slopes at
each node are those of the local Lagrange parabola through it and its two
neighbours; each cell is the bicubic Hermite patch of its corners' heights,
slopes and twists, all exact rationals.

Continuity: the surface passes through every point and is C1: across every
border between pieces the value and both first partial derivatives agree
exactly (second derivatives may jump).

The file (-o; standard output without it) is a lagsym-piecewise JSON
document that 'toolpath' machines and 'export' writes as one B-spline surface
with its knots at the borders (STEP, IGES, exact JSON).  Commands that need
one polynomial (macro, rough, job, sample, check, equation) refuse it.

examples:
  lagsym piecewise examples/part-20x20.csv -o pieces.json
  lagsym toolpath pieces.json --tool-diameter 6 --stepover 2 --step 1 -o pieces.nc
  lagsym export pieces.json -o pieces.step"""


def add_arguments(p) -> None:
    p.add_argument("file", help="points file: a grid of at least 3 x 3 points, JSON or a table with x,y,z")
    add_points_arguments(p)
    p.add_argument("-o", "--output", metavar="FILE", help="write the surface file here instead of standard output")


def run(args, out, err) -> int:
    grid = load_points(args.file, args, err)
    surface = piecewise_surface(grid)
    buf = io.StringIO()
    write_piecewise_json(buf, surface)
    emit(buf.getvalue(), args.output, out)
    (n, m), (a, b) = grid.shape, surface.shape
    report = out if args.output and args.output != "-" else err
    where = f"{args.output}: " if args.output and args.output != "-" else ""
    report.write(f"{where}{a} x {b} = {a * b} exact bicubic pieces through {n} x {m} points, {surface.continuity}: "
                 f"value and first derivatives equal across every border\n")
    return 0
