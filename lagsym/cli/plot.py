"""``lagsym plot FILE``: pictures of the surface, its basis functions, or the curve through a set of points."""

from __future__ import annotations

import argparse

from ..errors import InputError
from ..grid import CurvePoints
from ..io import read_any_points
from ..lagrange import lagrange_curve, lagrange_surface
from ._common import add_file_points_limit, add_exact_limit, exact_limit, SCALE, count, measured_points, number

DESCRIPTION = """Draw the Lagrange surface through the control points in FILE, shaded and
coloured by z, with the control points and the net joining them; or, with
--show basis, every basis function L_i(x) L_k(y) as a grid of small pictures;
with --show compare, the Lagrange, Hermite, Bezier and B-spline surfaces side
by side with their deviation from the Lagrange surface (the paper's Figure 10);
with --show toolpath PROGRAM, the moves of a G-code program over the surface,
in machine millimetres (give the --scale and --origin it was made with); with
--show growth FORMULA, the largest deviation of the Lagrange and cubic B-spline
surfaces from FORMULA on n x n evenly spaced points over the box of FILE, for
the degrees 2, 4, ..., 12 (the paper's Figure 11: past degree 6 it grows);
with --show machined PROGRAM, FILE being a job file (TOML), the block after
each tool of the job's PROGRAM, simulated as lagsym verify --job does and
coloured by the material left above the surface (the counterpart of the
paper's photographs, Figures 13 and 15); with --show residuals, FILE being
measured points (a grid or scattered, or the results a 'lagsym probe' program
sent back: the probed nodes), the least-squares surface 'lagsym fit' chooses (automatic degree) and every point on a stem from it, coloured by its
residual z - p(x, y) (stems drawn longer, as the title says).
Deviations are d = z_f - z_a everywhere, as lagsym compare prints them.
A file of [x, y] points draws the curve through them (and, with --show basis,
its basis polynomials L_i(x)).

With -o FILE the picture is written as an image (.png, .jpg, .tif, .bmp), and
no display is needed.  Without -o a window opens, which needs a display.

examples:
  lagsym plot examples/paper-example-4.json -o surface.png
  lagsym plot examples/paper-example-4.json --show basis -o basis.png
  lagsym plot examples/paper-curve-3rd.json -o curve.png
  lagsym plot examples/paper-example-4.json --show compare -o compare.png
  lagsym plot examples/paper-example-1.json --size 800x600 --units in -o small.png
  lagsym plot examples/paper-example-1.json --z-exaggeration 1 -o true-proportions.png
  lagsym toolpath examples/paper-example-4.json --scale 20 --stepover 2 --step 1 --safe-z 80 -o rough.nc
  lagsym plot examples/paper-example-4.json --show toolpath rough.nc --scale 20 -o toolpath.png
  lagsym plot examples/parabola.json --show growth "1/(1 + ((x-20)**2 + (y-20)**2)/25)" -o growth.png
  lagsym job examples/example-4-job.toml -o job.ngc
  lagsym plot examples/example-4-job.toml --show machined job.ngc --cell 0.5 -o machined.png
  lagsym plot --show residuals examples/probe-12x12.csv -o residuals.png
  lagsym plot --show residuals examples/probe-results.txt -o probed.png"""

SHOW = ("surface", "basis", "compare", "toolpath", "growth", "machined", "residuals")
TAKES_A_WORD = {"toolpath": "PROGRAM", "growth": "FORMULA", "machined": "PROGRAM"}


def _size(text: str) -> tuple[int, int]:
    w, sep, h = text.lower().partition("x")
    if not sep or not w.strip().isdigit() or not h.strip().isdigit():
        raise argparse.ArgumentTypeError(f"{text!r} should be WIDTHxHEIGHT in pixels, like 1024x768")
    return int(w), int(h)


def add_arguments(p) -> None:
    add_exact_limit(p)
    add_file_points_limit(p)
    # Optional only so that '--show basis FILE' works too: --show swallows the words after it.
    p.add_argument("file", nargs="?", help="points file: JSON or CSV with x,y,z (a surface) or x,y (a curve)")
    p.add_argument("--show", nargs="+", metavar=("WHAT", "PROGRAM"), default=None,
                   help="surface (default), basis, compare, 'toolpath PROGRAM', 'growth FORMULA', "
                        "'machined PROGRAM' (FILE a job file) or residuals (FILE measured points or probe results)")
    p.add_argument("-o", "--output", metavar="FILE", help="write the picture to FILE instead of opening a window")
    p.add_argument("--units", help="length unit for the axis labels (default: the points file's, else mm)")
    p.add_argument("--size", type=_size, default=(1280, 960), metavar="WxH",
                   help="picture size in pixels (default: 1280x960)")
    p.add_argument("--z-exaggeration", type=number(0.0, 1000.0, above=True), metavar="K",
                   help="draw z K times its true size (surface, compare, toolpath; the ticks read true heights); "
                        "above 0 up to 1000; default: chosen so the height lies between a fifth of the plan and the "
                        "plan, 1 for true "
                        "proportions")
    p.add_argument("--samples", type=count(2, 2_000), metavar="N", help="samples along each axis")
    p.add_argument("--scale", type=SCALE, default=None,
                   help="with --show toolpath: the --scale the program was made with (default 1)")
    p.add_argument("--origin", default=None, metavar="X,Y,Z",
                   help="with --show toolpath: the work offset the program was made with (default 0,0,0)")
    p.add_argument("--cell", type=number(1e-3, 1_000.0, "mm"), metavar="MM",
                   help="with --show machined: height-map cell size (default: block side / 400)")


def _request(show: list[str] | None, file: str | None) -> tuple[str, str | None, str]:
    """What to draw, the word after it (a toolpath's program, a growth's formula), and the points file.

    ``--show`` takes one or more words, so it may have swallowed FILE when the
    user wrote ``--show basis FILE``; take it back from the end.
    """
    words = list(show or ["surface"])
    what = words.pop(0)
    if what not in SHOW:
        raise InputError(f"--show {what!r} is not one of: {', '.join(SHOW)}")
    wanted = 1 if what in TAKES_A_WORD else 0
    if file is None and len(words) > wanted:
        file = words.pop()
    if file is None:
        raise InputError("no points FILE given: lagsym plot FILE [--show WHAT] [-o IMAGE]")
    if len(words) != wanted:
        if what in TAKES_A_WORD:
            word = TAKES_A_WORD[what]
            raise InputError(f"--show {what} needs exactly one {word}: --show {what} {word}")
        raise InputError(f"--show {what} takes no file, but got {' '.join(words)!r}")
    return what, (words[0] if words else None), file


def run(args, out, err) -> int:
    from .. import plot

    what, program, file = _request(args.show, args.file)
    if args.output:
        plot.image_format(args.output)
    elif plot.rendering_backend() != "display":
        raise InputError("no display to open a window on: give -o FILE to write the picture to a file")
    if what == "machined":
        figure = _machined_figure(plot, file, program, args)
        if args.output:
            plot.save_figure(figure, args.output)
        else:
            figure.show(title=f"lagsym plot {file}")
        return 0
    if args.cell is not None:
        raise InputError("--cell is the height-map cell of --show machined PROGRAM")
    if what == "residuals":
        figure = _residuals_figure(plot, file, args)
        if args.output:
            plot.save_figure(figure, args.output)
        else:
            figure.show(title=f"lagsym plot {file}")
        return 0
    points = read_any_points(file)
    _check_options(what, isinstance(points, CurvePoints), args)
    units = args.units or getattr(points, "units", None) or "mm"  # the points file's units unless told
    opts = dict(units=units, window_size=args.size, off_screen=True if args.output else None)
    if args.samples is not None:
        opts["samples"] = args.samples
    if args.z_exaggeration is not None:
        opts["z_exaggeration"] = args.z_exaggeration
    if isinstance(points, CurvePoints):
        curve = lagrange_curve(points, max_mb=exact_limit(args))
        figure = plot.curve_basis_figure(curve, **opts) if what == "basis" else plot.curve_figure(curve, **opts)
    elif what == "compare":
        figure = _compare_figure(plot, points, args, opts)
    elif what == "toolpath":
        figure = _toolpath_figure(plot, points, program, args, opts)
    elif what == "growth":
        figure = _growth_figure(plot, points, program, opts)
    else:
        surface = lagrange_surface(points, max_mb=exact_limit(args))
        figure = plot.basis_figure(surface, **opts) if what == "basis" else plot.surface_figure(surface, **opts)
    if args.output:
        plot.save_figure(figure, args.output)
    else:
        figure.show(title=f"lagsym plot {file}")
    return 0


def _check_options(what: str, curve: bool, args) -> None:
    """Refuse an option the picture asked for would not use."""
    if curve and what not in ("surface", "basis"):
        raise InputError(f"--show {what} needs a surface: a file of x, y, z points")
    if what != "toolpath" and (args.scale is not None or args.origin is not None):
        raise InputError("--scale and --origin place a program on the machine: they go with --show toolpath PROGRAM")
    if what == "toolpath" and args.units not in (None, "mm"):
        raise InputError(f"--units {args.units}: a toolpath is drawn in the machine's millimetres")
    if args.z_exaggeration is not None and (curve or what in ("basis", "growth")):
        raise InputError("--z-exaggeration applies to a surface, --show compare and --show toolpath")


def _compare_figure(plot, grid, args, opts):
    """The Lagrange, Hermite, Bezier and B-spline surfaces side by side (the paper's Figure 10)."""
    from ..compare import compare_surfaces

    n = opts.pop("samples", None) or 41
    c = compare_surfaces(grid, samples=(n, n))
    surfaces = {"Lagrange": c.z_reference}
    surfaces.update({m.name: m.z for m in c.methods if m.name != "Lagrange"})
    return plot.compare_figure(c.xs, c.ys, surfaces, control_points=_control_points(grid), **opts)


def _growth_figure(plot, grid, formula, opts):
    """The largest deviation from FORMULA against the degree, over the box of the points (the paper's Figure 11)."""
    from ..formula import parse_formula

    n = opts.pop("samples", None) or 81
    growth = plot.degree_growth(parse_formula(formula), grid.bounds, samples=n)
    return plot.growth_figure(growth, **{k: v for k, v in opts.items() if k != "z_exaggeration"})


def _machined_figure(plot, job_file, program, args):
    """The block after each tool of a job, coloured by the material left (the paper's Figures 13 and 15)."""
    from ..io import read_program
    from ..job import read_job
    from ..machined import machine_job

    for option in ("scale", "origin", "units", "samples"):
        if getattr(args, option) is not None:
            raise InputError(f"--{option} is not for --show machined: the job file {job_file} places the part")
    part = machine_job(read_job(job_file), read_program(program), source=program, cell_mm=args.cell)
    opts = dict(window_size=args.size, off_screen=True if args.output else None)
    if args.z_exaggeration is not None:
        opts["z_exaggeration"] = args.z_exaggeration
    return plot.machined_figure(part, **opts)


def _residuals_figure(plot, file, args):
    """The least-squares surface of measured points (automatic degree) and its residuals as coloured stems."""
    from ..fit import fit_surface

    for option in ("scale", "origin"):
        if getattr(args, option) is not None:
            raise InputError(f"--{option} places a program on the machine: it goes with --show toolpath PROGRAM")
    data = measured_points(file)
    fitted = fit_surface(data.points, None, source=data.source, units=data.units)
    opts = dict(units=args.units or data.units or "mm", window_size=args.size,
                off_screen=True if args.output else None)
    if args.samples is not None:
        opts["samples"] = args.samples
    if args.z_exaggeration is not None:
        opts["z_exaggeration"] = args.z_exaggeration
    return plot.residuals_figure(fitted, **opts)


def _control_points(grid):
    import numpy as np

    return np.array([[float(v) for v in p] for p in grid.points()])


def _toolpath_figure(plot, grid, program, args, opts):
    """The moves of a G-code program drawn over the surface (the paper's Figures 12 and 14)."""
    import numpy as np

    from ..gcode import move_points
    from ..io import read_program
    from ..machine import Placement, mm_per_surface_unit
    from ._common import origin

    points_mm, rapid = move_points(read_program(program), source=program)
    if not len(points_mm):
        raise InputError(f"{program}: no move with a Z position to draw")
    place = Placement(mm_per_surface_unit(grid.units, 1.0 if args.scale is None else args.scale),
                      origin(args.origin or "0,0,0"))
    ends_rapid = np.concatenate([[False], rapid])  # plot marks the move that ends at each point
    opts = {k: v for k, v in opts.items() if k != "units"}  # checked in run: the machine's mm
    surface = lagrange_surface(grid, max_mb=exact_limit(args))
    return plot.toolpath_figure(surface, points_mm, rapid=ends_rapid, placement=place, **opts)
