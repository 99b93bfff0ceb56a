"""``lagsym export FILE -o surface.step``: the exact surface as a CAD file (STEP, IGES, JSON)."""

from __future__ import annotations

from ..cad import (KERNEL_MAX_DEGREE, METHODS, cad_patch, double_error_bound, exact_height, lowest_height,
                   piecewise_patch, volume)
from ..conditioning import FLOAT_ERROR_LIMIT
from ..errors import InputError
from ..export.cad import CAD_FORMATS, cad_format_of, write_cad
from ..export.cadtext import UNITS
from ..io import read_points
from ._common import (add_file_points_limit, add_exact_limit, add_conditioning_argument,
                      guarded_surface, count, read_piecewise)
from ._lines import say

DESCRIPTION = f"""Write the exact surface through the control points in FILE as a CAD file:
the Lagrange polynomial is exactly a Bezier patch of the same degrees over the
control points' box, stored as a clamped single-span B-spline (parameters u, v
are x, y).  --method bezier or bspline writes a comparison surface instead.
A piecewise surface ('lagsym piecewise') is written as one bicubic B-spline
with a double knot at every border between pieces (C1, as the pieces join).

Format by the extension of -o: {', '.join(CAD_FORMATS)}.  STEP (AP214) holds a
B_SPLINE_SURFACE_WITH_KNOTS face; IGES an entity 128; JSON the exact rational
knots and control points.  --solid --base-z Z closes the surface down to the
plane z = Z into a solid (STEP: a B-rep solid; IGES: five more surfaces to sew);
Z must lie below the whole surface.  Lengths are in the units FILE states
("units": "mm" or "inch"), else in --units.

Files store doubles: a warning goes to standard error when rounding the
control points could move the surface by more than 1e-12 of the data range
(high degrees), or when the degree passes 25, the most OpenCascade reads.

examples:
  lagsym export examples/paper-example-4.json -o surface.step
  lagsym export examples/paper-example-4.json --solid --base-z 0 -o part.step
  lagsym export examples/paper-example-4.json --solid --base-z 0 -o part.igs
  lagsym export examples/paper-example-1.json -o surface.json
  lagsym export examples/paper-example-4.json --method bspline --degree 3 -o bspline.igs"""


def add_arguments(p) -> None:
    add_exact_limit(p)
    add_file_points_limit(p)
    p.add_argument("file", help="points file: JSON or CSV with x,y,z, or a 'lagsym piecewise' surface")
    add_conditioning_argument(p)
    p.add_argument("-o", "--output", metavar="FILE", required=True,
                   help=f"output file, format by extension: {', '.join(CAD_FORMATS)}")
    p.add_argument("--method", choices=METHODS, default="lagrange",
                   help="the surface: lagrange (default), or the bezier or bspline comparison surface")
    p.add_argument("--degree", type=count(1, 30), metavar="N",
                   help="B-spline degree for --method bspline (default 3, capped at n-1 as compare caps it)")
    p.add_argument("--solid", action="store_true", help="close the surface down to the base plane into a solid")
    p.add_argument("--base-z", metavar="Z", help="height of the base plane (with --solid), below the whole surface")
    p.add_argument("--units", choices=UNITS, help="length unit when FILE states none (default mm)")


def run(args, out, err) -> int:
    cad_format_of(args.output)  # an unknown extension fails before any work
    if args.solid != (args.base_z is not None):
        raise InputError("--solid needs --base-z Z, the height of the base plane" if args.solid
                         else f"--base-z {args.base_z} is for a solid: add --solid")
    base = exact_height(args.base_z, "--base-z", args.file) if args.solid else None
    if args.degree is not None and args.method != "bspline":
        raise InputError(f"--degree {args.degree} is the degree of --method bspline; the {args.method} surface has "
                         "the degrees of its control points")
    piecewise = read_piecewise(args.file)
    if piecewise is not None and args.method != "lagrange":
        raise InputError(f"--method {args.method} builds a surface from points; {args.file} holds a piecewise "
                         "surface already: leave --method out")
    grid = read_points(args.file) if piecewise is None else piecewise.grid
    units = grid.units or args.units or "mm"
    if args.units and units != args.units:
        raise InputError(f"{args.file}: the file states \"units\": \"{units}\", not --units {args.units}")
    if piecewise is not None:  # local pieces amplify the points' errors little: no guard rail
        patch = piecewise_patch(piecewise)
    else:
        # the other methods do not interpolate, so do not amplify the points' errors
        source = guarded_surface(grid, args, err)[0] if args.method == "lagrange" else grid
        patch = cad_patch(source, args.method, degree=args.degree or 3)
    write_cad(args.output, patch, base_z=base, units=units, source=args.file)
    lo, hi = grid.z_range()
    rel = double_error_bound(patch, hi - lo)
    if rel > FLOAT_ERROR_LIMIT:
        err.write(f"lagsym: warning: rounding the control points to doubles may move the surface by up to "
                  f"{rel:.1e} of the data range (trusted limit {FLOAT_ERROR_LIMIT:g}): at degree "
                  f"({patch.degree_u}, {patch.degree_v}) the Bernstein coefficients are much larger than the "
                  f"surface; use fewer control points, or the exact values in a .json file\n")
    if max(patch.degree_u, patch.degree_v) > KERNEL_MAX_DEGREE:
        err.write(f"lagsym: warning: degree ({patch.degree_u}, {patch.degree_v}) is above {KERNEL_MAX_DEGREE}, "
                  f"the largest B-spline degree OpenCascade and several CAD systems read\n")
    n, m = patch.shape
    say(out, f"{args.output}: {patch.name} surface, degree ({patch.degree_u}, {patch.degree_v}), "
             f"{n} x {m} exact control points, {units}")
    if base is not None:
        v = volume(patch, base)
        out.write(f"solid down to z = {args.base_z}: volume {v} = {float(v):.10g} {units}^3; "
                  f"lowest height of the surface {float(lowest_height(patch).upper):.10g}\n")
    return 0
