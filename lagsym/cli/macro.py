"""``lagsym macro FILE``: a parametric program that computes the surface on the control (variable programming)."""

from __future__ import annotations

from dataclasses import replace

from ..errors import InputError
from ..io import read_points
from ..machine import MachineSettings, RasterSpec, Tool
from ..macro import (FORMS, MACRO_DIALECTS, PRECISIONS, macro_program, planned_points, points_at, program_stats,
                     sample_positions)
from ..gcode.limits import VARIABLE_PROFILES
from ..macro.program import MAX_MACRO_POINTS
from ._common import (add_file_points_limit, add_exact_limit, add_conditioning_argument, guarded_surface, read_piecewise, dialect_help, FEED_MM_MIN, HEIGHT_MM, PROGRAM_NUMBER, SMALL_MM, SPINDLE_RPM, STEP_MM, STOCK_MM, TOOL_MM,
                      DECIMALS, add_program_arguments, count, emit, program_settings)

STATS_POINTS = 2_000_000  # above this --stats estimates the point list from a sample

DESCRIPTION = """Write a parametric (macro) program for the surface through the control points in
FILE.  The program loops over integer-counted rows and points of a zig-zag
raster over the control points' box (scaled by --scale, moved by --origin) and
computes each height on the control from the normalized Horner form of the
exact polynomial, so its size does not depend on the step.  The last row and
the last point of a row are clamped to the box edge.

The arithmetic of the control (--precision: 8 significant digits for a Fanuc
16/18-class control, 15 for IEEE double) is checked before writing: a program
predicted to be off by more than --tolerance is refused.

examples:
  lagsym macro examples/paper-example-4.json --scale 20 --tool-diameter 4 --stepover 0.5 --step 0.2 \\
      --safe-z 100 --dialect fanuc --program 1000 -o O1000.nc --stats
  lagsym macro examples/paper-example-1.json --dialect linuxcnc --tool-diameter 0 --scale 10 \\
      --origin 0,0,-400 -o surface.ngc
  lagsym macro examples/paper-example-2.json --dialect heidenhain --scale 10 --tool-diameter 2 \\
      --variable-base 20 -o 1000.h"""


def add_arguments(p) -> None:
    add_exact_limit(p)
    add_file_points_limit(p)
    p.add_argument("file", help="points file: JSON or CSV with x,y,z")
    add_conditioning_argument(p)
    p.add_argument("--dialect", choices=MACRO_DIALECTS, default="fanuc", help=f"the control: {dialect_help(MACRO_DIALECTS)}")
    p.add_argument("--precision", type=int, choices=PRECISIONS,
                   help="significant digits of the control's arithmetic "
                        "(default 8 for fanuc and heidenhain, 15 for linuxcnc)")
    p.add_argument("--form", choices=FORMS,
                   help="horner (shortest) or lagrange (tensor-product basis, most accurate); "
                        "default lagrange at 8 digits, horner at 15")
    p.add_argument("--tolerance", type=SMALL_MM, default=0.001, metavar="MM",
                   help="largest arithmetic error accepted on the control, mm (default 0.001)")
    p.add_argument("--variable-base", type=count(1, 999), metavar="N",
                   help="first variable number: Fanuc #100 (default) or #500, Heidenhain Q1 (default)")
    p.add_argument("--variables", choices=VARIABLE_PROFILES, default="full",
                   help="the control's variable ranges: full (Fanuc #100-#199, #500-#999; default) or small "
                        "(#100-#149, #500-#531, smaller Fanuc controls); a program that does not fit is refused")
    p.add_argument("--origin", default="0,0,0", metavar="X,Y,Z", help="work offset added, mm")
    p.add_argument("--units", choices=("mm", "inch"), default="mm",
                   help="program units (default mm); lengths and feeds given without a unit (5mm, 0.2in, "
                        "600mm/min, 24in/min) are read in these units")
    p.set_defaults(_program_units=True)
    p.add_argument("--direction", choices=("x", "y"), default="x", help="rows run along x (default) or y")
    p.add_argument("--stepover", type=STEP_MM, default=0.5, metavar="MM", help="side step between rows, mm (default 0.5)")
    p.add_argument("--step", type=STEP_MM, default=0.2, metavar="MM", help="forward step along a row, mm (default 0.2)")
    p.add_argument("--tool-shape", choices=("ball", "flat"), default="ball",
                   help="cutter shape (default ball); a flat end is refused: use lagsym toolpath for it")
    p.add_argument("--tool-diameter", type=TOOL_MM, default=6.0, metavar="MM",
                   help="cutter diameter, mm; 0 programs the surface itself (default 6)")
    p.add_argument("--feed", type=FEED_MM_MIN, default=600.0, metavar="MM_MIN", help="cutting feed (default 600)")
    p.add_argument("--plunge-feed", type=FEED_MM_MIN, default=200.0, metavar="MM_MIN", help="plunge feed (default 200)")
    p.add_argument("--spindle", type=SPINDLE_RPM, default=3000.0, metavar="RPM", help="spindle speed (default 3000)")
    p.add_argument("--safe-z", type=HEIGHT_MM, default=50.0, metavar="MM",
                   help="clearance height for rapid moves, above the whole path (default 50)")
    p.add_argument("--stock", type=STOCK_MM, default=0.0, metavar="MM", help="stock to leave (default 0)")
    p.add_argument("--program", type=PROGRAM_NUMBER, default=1000, metavar="N", help="program number 1-9999 (default 1000)")
    p.add_argument("--decimals", type=DECIMALS, metavar="N", help="decimals in positions (default 3 mm, 4 inch)")
    add_program_arguments(p.add_argument_group("machine and program"))
    p.add_argument("--stats", action="store_true",
                   help="compare the program's size with the equivalent point list, and their 9600-baud transfer times")
    p.add_argument("--max-points", type=count(1, 10**13), default=MAX_MACRO_POINTS, metavar="N",
                   help=f"refuse a raster of more than N points, with its size, path length and cutting time "
                        f"(default {MAX_MACRO_POINTS:.0e})")
    p.add_argument("-o", "--output", metavar="FILE", help="write the program to FILE instead of standard output")


def settings_from(args, grid) -> tuple[MachineSettings, RasterSpec, Tool]:
    """The machine, raster and tool the arguments describe, for the surface read from ``grid``."""
    settings = program_settings(args, grid, dialect=args.dialect, stock_to_leave_mm=args.stock)
    raster = RasterSpec(direction=args.direction, stepover_mm=args.stepover, step_mm=args.step)
    return settings, raster, Tool(shape=args.tool_shape, diameter_mm=args.tool_diameter)


def run(args, out, err) -> int:
    piecewise = read_piecewise(args.file)
    if piecewise is not None:
        a, b = piecewise.shape
        raise InputError(f"{args.file}: a macro evaluates one polynomial on the control, and this piecewise surface "
                         f"has {a * b} pieces, which the control would have to pick between at every point: lagsym "
                         f"writes no such program; use 'lagsym toolpath {args.file}' (a point list)")
    surface, notes = guarded_surface(read_points(args.file), args, err)
    settings, raster, tool = settings_from(args, surface.grid)
    settings = replace(settings, notes=notes)
    program = macro_program(surface, settings, raster, tool, precision=args.precision, tolerance_mm=args.tolerance,
                            variable_base=args.variable_base, form=args.form, variables=args.variables,
                            max_points=args.max_points)
    emit(program.text, args.output, out)
    if args.stats:
        counted = program.loops.raster
        if counted.size <= STATS_POINTS:
            stats = program_stats(program, planned_points(surface, settings, raster, tool), settings)
        else:  # a sample, scaled: a list of millions of points is not worth building to count it
            sample = points_at(surface, settings, tool, *sample_positions(counted, 1001))
            stats = program_stats(program, sample, settings, count=counted.size)
        report = (stats.text() + f"\npredicted arithmetic error at {program.precision} digits: "
                  f"{program.predicted_error_mm:.2g} mm\n")
        (out if args.output and args.output != "-" else err).write(report)
    return 0
