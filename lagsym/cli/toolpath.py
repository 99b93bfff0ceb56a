"""``lagsym toolpath FILE``: a zig-zag raster of gouge-free cutter locations, written as a point-list program."""

from __future__ import annotations

from dataclasses import replace

from ..controls import names
from ..io import read_points, write_text
from ..machine import (BOUNDARIES, DEFAULT_TOLERANCE_MM, DIRECTIONS, TOOL_SHAPES, UNITS, MachineSettings, RasterSpec,
                       Tool)
from ..post.program import point_program, write_program
from ..toolpath.plan import MAX_PLAN_POINTS
from ..toolpath.waterline import BAND_DEG, STRATEGIES

from ._common import (add_file_points_limit, add_exact_limit, add_conditioning_argument, guarded_surface, read_piecewise, dialect_help, CORNER_MM, FEED_MM_MIN, HEIGHT_MM, PROGRAM_NUMBER, SMALL_MM, SPINDLE_RPM, STEP_MM, STOCK_MM,
                      TOOL_MM, DECIMALS, add_program_arguments, count, cusp_note, program_settings)
from ._lines import say
from ._progress import progress_bar

DESCRIPTION = """Plan a zig-zag raster over the exact surface through the control points in
FILE and write it as a point-list G-code program.  FILE may also hold a
piecewise surface ('lagsym piecewise'): the tool is dropped on every piece
within its reach, so it rests on the pieces across their borders too.  Cutter locations come from
drop-cutter against the exact surface, so the tool never cuts below it, also
where the surface is more concave than the tool.  The programmed point is the
tool tip; the tool stays down between rows.

On a terminal, a progress bar on standard error shows the planning.

examples:
  lagsym toolpath examples/paper-example-4.json --scale 20 --tool-diameter 6 \\
      --stepover 0.4 --step 0.2 --feed 600 --safe-z 80 --dialect fanuc -o O1000.nc
  lagsym toolpath examples/paper-example-1.json --scale 10 --scallop 0.01 --tolerance 0.005 --safe-z 400 \\
      --dialect linuxcnc -o part.ngc
  lagsym toolpath examples/paper-example-4.json --scale 20 --strategy steep-shallow --scallop 0.05 \\
      --tolerance 0.01 --safe-z 100 --dialect linuxcnc -o steep.ngc"""

POINT_DIALECTS = names(point_lists=True)


def add_arguments(p) -> None:
    add_exact_limit(p)
    add_file_points_limit(p)
    p.add_argument("file", help="points file: JSON or CSV with x,y,z, a 'lagsym fit' surface or a "
                                "'lagsym piecewise' surface")
    add_conditioning_argument(p)
    p.add_argument("-o", "--output", metavar="FILE", help="write the program to FILE instead of standard output")
    p.add_argument("--dialect", choices=POINT_DIALECTS, default="fanuc",
                   help=f"the control: {dialect_help(POINT_DIALECTS)}")
    g = p.add_argument_group("raster")
    g.add_argument("--strategy", choices=STRATEGIES, default="raster",
                   help="raster (default: the zig-zag), waterline (contours at constant heights on the slopes "
                        "steeper than a threshold, spaced from the local slope) or steep-shallow (raster where the "
                        "slope across the rows is below the threshold, contours above it, overlapping); "
                        "waterline and steep-shallow need --scallop and a ball end")
    g.add_argument("--milling", choices=("climb", "conventional"), default="climb",
                   help="direction of the contours with the spindle clockwise (default climb)")
    g.add_argument("--direction", choices=DIRECTIONS, default="x", help="rows along x (default) or y")
    g.add_argument("--stepover", type=STEP_MM, metavar="MM", help="side step between rows (default 0.5)")
    g.add_argument("--step", type=STEP_MM, metavar="MM",
                   help="longest move along a row (default 0.2, or none with --tolerance alone); points are "
                        "added where the path bends")
    g.add_argument("--scallop", type=SMALL_MM, metavar="MM",
                   help="rows spaced so that a ball-end cutter's cusp, measured normal to the surface, is at "
                        "most this (on slopes too), instead of --stepover")
    g.add_argument("--tolerance", type=SMALL_MM, metavar="MM",
                   help=f"chordal error of the moves: points are added where the path bends and, without "
                        f"--step, left out where it is straight (default {DEFAULT_TOLERANCE_MM})")
    g.add_argument("--boundary", choices=BOUNDARIES, default="past",
                   help="past (default: the tool axis goes beyond the box as far as the tool still touches "
                        "the part, so the whole part is finished), centre (the axis stays in the box) or "
                        "inside (the whole tool stays in the box)")
    g.add_argument("--arcs", action="store_true",
                   help="replace runs of moves along a row by G02/G03 arcs in the row's plane (G18 for rows "
                        "along x, G19 along y) where one stays within --tolerance above the cutter path and "
                        "never below it; the report gives the blocks before and after")
    t = p.add_argument_group("cutter")
    t.add_argument("--tool-shape", choices=TOOL_SHAPES, default="ball", help="ball (default), flat or bull (bull nose: give --corner-radius)")
    t.add_argument("--corner-radius", type=CORNER_MM, metavar="MM",
                   help="corner radius of a bull-nose cutter (--tool-shape bull), less than half its diameter")
    t.add_argument("--tool-diameter", type=TOOL_MM, default=6.0, metavar="MM",
                   help="cutter diameter (default 6; 0 gives the uncompensated path on the surface)")
    m = p.add_argument_group("machine and program")
    add_program_arguments(m)
    m.add_argument("--origin", default="0,0,0", metavar="X,Y,Z", help="work offset added to every point, mm")
    m.add_argument("--units", choices=UNITS, default="mm",
                   help="program units: mm (G21, default) or inch (G20); lengths and feeds given without a unit "
                        "(5mm, 0.2in, 600mm/min, 24in/min) are read in these units")
    p.set_defaults(_program_units=True)
    m.add_argument("--feed", type=FEED_MM_MIN, default=600.0, metavar="MM/MIN", help="cutting feed (default 600)")
    m.add_argument("--plunge-feed", type=FEED_MM_MIN, default=200.0, metavar="MM/MIN", help="plunge feed (default 200)")
    m.add_argument("--spindle", type=SPINDLE_RPM, default=3000.0, metavar="RPM", help="spindle speed (default 3000)")
    m.add_argument("--safe-z", type=HEIGHT_MM, default=50.0, metavar="MM", help="retract height (default 50)")
    m.add_argument("--stock-to-leave", type=STOCK_MM, default=0.0, metavar="MM", help="material left on the surface")
    m.add_argument("--program", type=PROGRAM_NUMBER, default=1000, metavar="N", help="program number O N (default 1000)")
    m.add_argument("--decimals", type=DECIMALS, metavar="N", help="decimals in coordinates (default 3 for mm, 4 for inch)")
    m.add_argument("--max-points", type=count(1, 10**12), default=MAX_PLAN_POINTS, metavar="N",
                   help=f"refuse a plan of more than N fine drop-cutter samples (default {MAX_PLAN_POINTS:.0e})")
    m.add_argument("--title", help="comment at the top of the program (default: the points file's name)")


def settings_from(args, dialect: str, grid) -> MachineSettings:
    """The machine settings the arguments describe, for the surface read from ``grid``."""
    return program_settings(args, grid, dialect=dialect, stock_to_leave_mm=args.stock_to_leave)


def run(args, out, err) -> int:
    from ..toolpath import plan_strategy, plan_toolpath

    piecewise = read_piecewise(args.file)
    if piecewise is not None:  # local pieces: each point moves the surface near it only, so no guard rail
        grid, surface, notes = piecewise.grid, piecewise, ()
    else:
        grid = read_points(args.file)
        surface, notes = guarded_surface(grid, args, err)
    settings = replace(settings_from(args, args.dialect, grid), notes=notes)
    tool = Tool(args.tool_shape, args.tool_diameter, args.corner_radius)
    stepover = args.stepover if args.stepover is not None else (None if args.scallop is not None else 0.5)
    step = args.step if args.step is not None else (None if args.tolerance is not None else 0.2)
    raster = RasterSpec(args.direction, stepover, step, args.scallop, args.tolerance, args.boundary, args.arcs)
    with progress_bar(err) as progress:
        if args.strategy == "raster":
            tp = plan_toolpath(surface, tool, raster, settings.placement, settings.program,
                               max_points=args.max_points, stock_to_leave_mm=settings.stock_to_leave_mm,
                               progress=progress)
        else:
            tp = plan_strategy(surface, tool, raster, settings.placement, settings.program,
                               strategy=args.strategy, milling=args.milling, max_points=args.max_points,
                               stock_to_leave_mm=settings.stock_to_leave_mm, progress=progress)
    title = args.title if args.title is not None else str(grid.source).rsplit("/", 1)[-1]
    text = write_program(point_program(tp, settings, title=title))
    if args.output and args.output != "-":
        write_text(args.output, text, newline="")
        if tp.note is not None:
            say(err, f"{args.output}: {len(tp)} cutter locations in {int(tp.rows.max()) + 1} passes, "
                      f"{tp.levels} levels, contours on slopes over {tp.threshold_deg - BAND_DEG:.0f} degrees, "
                      f"moves within {raster.chordal_tolerance_mm:g} mm of the cutter path and never below it, "
                      f"passes spaced for a cusp of at most {tp.cusp_mm:g} mm "
                      f"normal to the surface outside hollows tighter than the ball "
                      f"({100 * tp.hollow_share:.1f} % of the grid)")
            return 0
        say(err, f"{args.output}: {len(tp)} cutter locations (from {tp.fine_points} samples) in "
                  f"{int(tp.rows.max()) + 1} rows, side step {tp.stepover_mm:.4f} mm, largest lift for chordal "
                  f"error {tp.lift_mm.max():.4f} mm (tolerance {raster.chordal_tolerance_mm:g} mm)"
                  + cusp_note(tp) + _arc_note(tp))
    else:
        out.write(text)
    return 0


def _arc_note(tp) -> str:
    """With arcs: how many, and the feed moves before and after."""
    if tp.arcs is None:
        return ""
    moves = len(tp) - 1
    return (f"; {len(tp.arcs)} arcs ({tp.arcs.plane}): {moves} feed moves before, "
            f"{moves - tp.arcs.blocks_saved()} after")
