"""``lagsym sample FILE``: the interior data of the surface, sampled densely, to CSV, NumPy or a mesh file."""

from __future__ import annotations

import contextlib

from ..conditioning import FLOAT_ERROR_LIMIT, float_error_bound
from ..export import FORMATS, MESH_MAX_POINTS, format_of, write_csv, write_sample
from ..errors import InputError
from ..io import read_points
from ..lagrange import lagrange_surface
from ..sampling import MAX_AXIS_POINTS, MAX_POINTS, Box, iter_blocks, sample_grid
from ._common import add_file_points_limit, add_exact_limit, exact_limit, add_conditioning_argument, conditioning_notes, count, exact, read_piecewise

DESCRIPTION = f"""Sample the exact Lagrange surface through the control points in FILE on a
regular grid and write the interior data, numerically stable at any density.

Domain: the control points' box, or --x0 --x1 --y0 --y1 (outside the control
points is extrapolation: only with --extrapolate).  Density: --nx and --ny
grid lines (edges included; default 101 each), or a largest spacing --step
(both directions) or --dx and --dy.  Output by the extension of -o:
{', '.join(FORMATS)}; CSV to standard output without -o.
Point tables (.csv, .npy) stream in blocks, so memory stays bounded for any
number of points; meshes are built whole (at most {MESH_MAX_POINTS} points).

A warning goes to standard error when floating-point rounding could exceed
1e-12 of the data range (an ill-conditioned node set) or when extrapolating.

FILE may be a piecewise surface ('lagsym piecewise'): each point is taken
from the bicubic piece whose cell holds it (outside the box, extrapolated
from the nearest edge piece); the same formats and options apply.

examples:
  lagsym sample examples/paper-example-4.json --nx 400 --ny 400 -o interior.csv
  lagsym sample examples/paper-example-4.json --step 0.05 -o part.stl
  lagsym sample examples/paper-example-1.json --x0 0 --x1 6 --extrapolate -o wide.npy
  lagsym sample pieces.json --step 0.1 -o pieces.stl"""

DEFAULT_COUNT = 101
PROGRESS_POINTS = 250_000  # smaller jobs finish before a bar is worth drawing


def add_arguments(p) -> None:
    add_exact_limit(p)
    add_file_points_limit(p)
    p.add_argument("file", help="points file: JSON or CSV with x,y,z, or a 'lagsym piecewise' surface")
    add_conditioning_argument(p)
    d = p.add_argument_group("density (counts or spacing)")
    d.add_argument("--nx", type=count(2, MAX_AXIS_POINTS), metavar="N", help="grid lines in x, edges included (default 101; alone, also ny)")
    d.add_argument("--ny", type=count(2, MAX_AXIS_POINTS), metavar="N", help="grid lines in y, edges included (default: as --nx)")
    d.add_argument("--step", type=exact(0, 1e300, above=True), metavar="S", help="largest spacing in both directions, e.g. 0.05")
    d.add_argument("--dx", type=exact(0, 1e300, above=True), metavar="S", help="largest spacing in x (with --dy)")
    d.add_argument("--dy", type=exact(0, 1e300, above=True), metavar="S", help="largest spacing in y (with --dx)")
    b = p.add_argument_group("domain (default: the control points' box)")
    for name in ("x0", "x1", "y0", "y1"):
        b.add_argument(f"--{name}", type=exact(), metavar="V", help=f"{name} of the sampled box")
    b.add_argument("--extrapolate", action="store_true", help="allow a box reaching outside the control points")
    p.add_argument("-o", "--output", metavar="FILE", help=f"output file, format by extension: {', '.join(FORMATS)}")
    p.add_argument("--max-points", type=count(1, 10**15), default=MAX_POINTS, metavar="N",
                   help=f"refuse a sample of more than N points (default {MAX_POINTS:.0e})")
    p.add_argument("--accept-rounding", action="store_true",
                   help="write the samples even when their rounding error may exceed the data range")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")


def _progress(err, total: int, quiet: bool):
    """A rich progress bar on ``err`` for a large job on a terminal, else a context yielding None."""
    if quiet or total < PROGRESS_POINTS or not (hasattr(err, "isatty") and err.isatty()):
        return contextlib.nullcontext(None)
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    @contextlib.contextmanager
    def bar():
        with Progress(TextColumn("sampling"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                      console=Console(file=err), transient=True) as prog:
            task = prog.add_task("sample", total=total)
            yield lambda done: prog.update(task, completed=done)

    return bar()


def run(args, out, err) -> int:
    if args.output and args.output != "-":
        format_of(args.output)  # an unknown extension fails before any work
    piecewise = read_piecewise(args.file)
    surface = piecewise if piecewise is not None else lagrange_surface(read_points(args.file), max_mb=exact_limit(args))
    nx, ny = args.nx, args.ny
    spacing = args.step is not None or args.dx is not None or args.dy is not None
    if not spacing:
        nx = nx if nx is not None else (ny if ny is not None else DEFAULT_COUNT)
        ny = ny if ny is not None else nx
    grid = sample_grid(surface, nx, ny, step=args.step, dx=args.dx, dy=args.dy,
                       box=(args.x0, args.x1, args.y0, args.y1), extrapolate=args.extrapolate,
                       max_points=args.max_points)
    b = surface.grid.bounds
    if not Box(*b).contains(grid.box):
        err.write(f"lagsym: warning: the box x {float(grid.box.x0):g}..{float(grid.box.x1):g}, "
                  f"y {float(grid.box.y0):g}..{float(grid.box.y1):g} reaches outside the control points "
                  f"(x {float(b[0]):g}..{float(b[1]):g}, y {float(b[2]):g}..{float(b[3]):g}): "
                  f"the surface there is extrapolated and follows no data\n")
    if piecewise is not None:  # local bicubics: no amplification to guard against, rounding of their own size
        return _write(args, surface, grid, out, err)
    rel = float_error_bound(surface, grid.box.floats())
    if rel > 1 and not args.accept_rounding:
        raise InputError(f"{args.file}: rounding error of the samples may reach {rel:.1e} times the data range, so the "
                         f"heights could be anything; use fewer or Chebyshev-spaced nodes, exact values from "
                         f"'lagsym equation', or --accept-rounding to write them anyway")
    conditioning_notes(surface.grid, args, err, surface)
    if rel > FLOAT_ERROR_LIMIT:
        err.write(f"lagsym: warning: rounding error of the samples may reach {rel:.1e} of the data range "
                  f"(trusted limit {FLOAT_ERROR_LIMIT:g}): the {surface.grid.shape[0]} x {surface.grid.shape[1]} nodes are "
                  f"ill-conditioned (see 'lagsym check'); use fewer or Chebyshev-spaced nodes, "
                  f"or exact values from 'lagsym equation'\n")
    return _write(args, surface, grid, out, err)


def _write(args, surface, grid, out, err) -> int:
    with _progress(err, grid.size, args.quiet) as progress:
        if args.output and args.output != "-":
            write_sample(args.output, surface, grid, progress=progress)
        else:
            write_csv(out, iter_blocks(surface, grid), progress)
    return 0
