"""``lagsym rough FILE``: z-level roughing from a block, written as a point-list program."""

from __future__ import annotations

from ..controls import VARIABLE_PROFILES, control, names
import os
from pathlib import Path

from ..io import write_text
from ..machine import DIRECTIONS, UNITS
from ._common import (add_file_points_limit, add_conditioning_argument, exact_limit, dialect_help, CORNER_MM, FEED_MM_MIN, HEIGHT_MM, LENGTH_MM, PROGRAM_NUMBER, SCALE, SPINDLE_RPM, TOOL_MM, count,
                      number, origin)
from .job import add_max_points

_STEP_MM = number(1e-3, 1_000.0, "mm")  # a step-down, side step or forward step
_DEPTH_MM = number(0.0, 1_000.0, "mm")
_LEN_MM = number(0.0, 10_000.0, "mm", above=True)  # flute length, reach
_TOOL_NUMBER = count(1, 99)

DESCRIPTION = """Rough a rectangular block down to the exact surface through the control
points in FILE: at each level (the stock top down by the step-down) a
raster whose height is never below the cutter's exact drop-cutter height
plus the stock to leave.  Every level is entered from beside the block, and
inside a level no feed move descends into material steeper than the tool's
ramp angle (--plunge-angle; 15 degrees, 3 with --not-centre-cutting), which
the header states.

With --macro the program is a parametric macro instead: the control loops
over the levels, rows and points and computes each tip height from the
surface equation, never below the drop-cutter height plus the stock (see
docs/roughing.md for the proof of its clearance); inside a row it descends
no steeper than the same ramp angle, leaving wedges on flanks that fall
along a row to the rows that run the other way.

FILE may be a piecewise surface ('lagsym piecewise'): the cutter is dropped
on every piece within its reach, as for toolpath.  --macro is refused for
it: a macro evaluates one polynomial on the control.

On a terminal, a progress bar on standard error shows the planning.

examples:
  lagsym rough examples/paper-example-4.json --scale 20 --stock-above 2 --tool-shape flat \\
      --tool-diameter 10 --stepdown 2 --stepover 5 --stock-to-leave 0.3 --safe-z 90 --dialect linuxcnc -o rough.ngc
  lagsym rough examples/paper-example-4.json --scale 20 --stock-above 2 --tool-diameter 10 --stepdown 2 \\
      --safe-z 90 --dialect fanuc --macro --program 2000 -o O2000.nc"""


def add_arguments(p) -> None:
    p.add_argument("file", help="points file: JSON or CSV with x,y,z, or a 'lagsym piecewise' surface")
    add_file_points_limit(p)
    add_conditioning_argument(p)
    p.add_argument("-o", "--output", metavar="FILE", help="write the program to FILE instead of standard output")
    p.add_argument("--dialect", choices=names(point_lists=True), default="fanuc",
                   help=f"the control: {dialect_help(names(point_lists=True))}")
    p.add_argument("--macro", action="store_true",
                   help=f"write a parametric macro ({' or '.join(names(point_lists=True, macros=True))}): the control "
                        "computes every height from the surface equation plus a proved clearance; a few kilobytes "
                        "whatever the block")
    p.add_argument("--precision", type=int, choices=(8, 15), metavar="N",
                   help="with --macro: significant digits of the control's arithmetic, 8 or 15 "
                        "(default 8 for fanuc, 15 for linuxcnc)")
    p.add_argument("--variables", choices=VARIABLE_PROFILES, metavar="PROFILE",
                   help="with --macro: the control's variable ranges, full (default; Fanuc #100-#199, #500-#999) "
                        "or small (#100-#149, #500-#531); a macro whose loops or clearance tables do not fit is "
                        "refused with the variables it needs")
    s = p.add_argument_group("stock")
    top = s.add_mutually_exclusive_group(required=True)
    top.add_argument("--stock-top", type=HEIGHT_MM, metavar="MM", help="machine Z of the block's top")
    top.add_argument("--stock-above", type=number(0.0, LENGTH_MM, "mm"), metavar="MM", help="block top this far above the surface's highest point")
    s.add_argument("--margin", type=number(0.0, LENGTH_MM, "mm"), metavar="MM", help="block beyond the control points' box on every side (default 0)")
    s.add_argument("--block", metavar="X0,X1,Y0,Y1", help="the block's extent in machine mm instead of a margin")
    r = p.add_argument_group("roughing")
    r.add_argument("--stepdown", type=_STEP_MM, default=2.0, metavar="MM", help="depth of each level (default 2)")
    r.add_argument("--stepover", type=_STEP_MM, metavar="MM", help="side step between rows (default half the tool)")
    r.add_argument("--step", type=_STEP_MM, default=0.5, metavar="MM", help="forward sampling step (default 0.5)")
    r.add_argument("--stock-to-leave", type=_DEPTH_MM, default=0.3, metavar="MM", help="material left above the surface (default 0.3)")
    r.add_argument("--pattern", choices=("raster", "offset"), default="raster",
                   help="clearing at each level: raster rows (default) or offset, concentric rectangles from the "
                        "block's outline inwards")
    r.add_argument("--direction", choices=DIRECTIONS, help="raster rows along x (default) or y")
    r.add_argument("--milling", choices=("zigzag", "climb", "conventional"),
                   help="raster: zigzag (default, stays down), or one-way climb or conventional (retracts above "
                        "the block); offset: climb (default) or conventional")
    t = p.add_argument_group("cutter")
    t.add_argument("--tool-shape", default="flat", help="flat (default), ball or bull (bull nose: give --corner-radius)")
    t.add_argument("--corner-radius", type=CORNER_MM, metavar="MM",
                   help="corner radius of a bull-nose cutter (--tool-shape bull), less than half its diameter")
    t.add_argument("--tool-diameter", type=TOOL_MM, default=10.0, metavar="MM", help="cutter diameter (default 10)")
    t.add_argument("--tool-number", type=_TOOL_NUMBER, default=1, metavar="N", help="tool and length offset number (default 1)")
    t.add_argument("--flute-length", type=_LEN_MM, metavar="MM", help="refuse a step-down longer than the flutes")
    t.add_argument("--reach", type=_LEN_MM, metavar="MM", help="tool length below the holder: refuse a deeper cut")
    t.add_argument("--plunge-angle", type=number(0.0, 90.0, "degrees", above=True), metavar="DEG",
                   help="steepest descent into material, degrees from the horizontal: steeper ones ramp down "
                        "at this angle (default 15, or 3 with --not-centre-cutting; 90: plunge)")
    t.add_argument("--not-centre-cutting", dest="centre_cutting", action="store_false",
                   help="the end mill does not cut at its centre: it never plunges, and ramps at 3 degrees "
                        "unless --plunge-angle says otherwise")
    m = p.add_argument_group("machine")
    m.add_argument("--scale", type=SCALE, default=1.0, help="millimetres per surface unit (default 1)")
    m.add_argument("--origin", default="0,0,0", metavar="X,Y,Z", help="work offset added to every point, mm")
    m.add_argument("--units", choices=UNITS, default="mm",
                   help="program units: mm (G21, default) or inch (G20); lengths and feeds given without a unit "
                        "(5mm, 0.2in, 600mm/min, 24in/min) are read in these units")
    p.set_defaults(_program_units=True)
    m.add_argument("--feed", type=FEED_MM_MIN, default=600.0, metavar="MM/MIN", help="cutting feed (default 600)")
    m.add_argument("--plunge-feed", type=FEED_MM_MIN, default=200.0, metavar="MM/MIN", help="plunge feed (default 200)")
    m.add_argument("--rapid", type=FEED_MM_MIN, default=5000.0, metavar="MM/MIN", help="rapid rate for the cycle time (default 5000)")
    m.add_argument("--spindle", type=SPINDLE_RPM, default=3000.0, metavar="RPM", help="spindle speed (default 3000)")
    m.add_argument("--coolant", choices=("off", "flood", "mist"), default="off", help="coolant (default off)")
    m.add_argument("--safe-z", type=HEIGHT_MM, default=50.0, metavar="MM", help="retract height (default 50)")
    m.add_argument("--program", type=PROGRAM_NUMBER, default=1000, metavar="N", help="program number O N (default 1000)")
    add_max_points(p)
    p.set_defaults(max_samples=None)  # None: the default limit, and --max-samples not given (refused with --macro)


def job_data(args) -> dict:
    """The job file's data the options describe: one roughing operation."""
    stock = {"top": args.stock_top} if args.stock_top is not None else {"top_above": args.stock_above}
    if args.block is not None:
        stock["block"] = list(origin_list(args.block))
    if args.margin is not None:
        stock["margin"] = args.margin
    tool = {"number": args.tool_number, "shape": args.tool_shape, "diameter": args.tool_diameter}
    for key in ("corner_radius", "flute_length", "reach", "plunge_angle"):
        if getattr(args, key) is not None:
            tool[key] = getattr(args, key)
    if not args.centre_cutting:
        tool["centre_cutting"] = False
    op = {"kind": "rough", "tool": "cutter", "spindle": args.spindle, "feed": args.feed,
          "plunge_feed": args.plunge_feed, "coolant": args.coolant, "stepdown": args.stepdown, "step": args.step,
          "stock_to_leave": args.stock_to_leave}
    for key in ("pattern", "direction", "milling"):
        if getattr(args, key) is not None:
            op[key] = getattr(args, key)
    if args.stepover is not None:
        op["stepover"] = args.stepover
    if args.macro:
        op["macro"] = True
    if args.precision is not None:
        op["precision"] = args.precision
    job = {"points": os.path.abspath(args.file), "dialect": args.dialect, "units": args.units,
            "scale": args.scale, "origin": list(origin(args.origin)), "safe_z": args.safe_z, "rapid": args.rapid,
            "program_number": args.program, "title": Path(args.file).name, "stock": stock,
            "tools": {"cutter": tool}, "operations": [op]}
    if args.variables is not None:
        job["variables"] = args.variables
    return job


def origin_list(text: str):
    from ..errors import InputError
    from ..values import in_range

    parts = text.split(",")
    if len(parts) != 4:
        raise InputError(f"--block {text!r} must be four numbers X0,X1,Y0,Y1 in mm")
    names = ("X0", "X1", "Y0", "Y1")
    return [in_range(v, f"--block {name}", -LENGTH_MM, LENGTH_MM, unit="mm") for name, v in zip(names, parts)]


def _refuse(args) -> None:
    """Options that do not apply with or without --macro, refused rather than ignored."""
    from ..errors import InputError

    if args.variables is not None and not args.macro:
        raise InputError(f"--variables {args.variables} applies to a macro only: add --macro or leave it out")
    if args.precision is not None and not args.macro:
        raise InputError(f"--precision {args.precision} applies to a macro only: add --macro or leave it out")
    if args.macro and control(args.dialect).macro is None:
        raise InputError(f"--macro: a roughing macro is written for {' or '.join(names(point_lists=True, macros=True))}, "
                         f"not {args.dialect} (no macro language)")
    if args.pattern == "offset" and args.direction is not None:
        raise InputError(f"--direction {args.direction} does not apply with --pattern offset (rectangles, no rows)")
    if args.pattern == "offset" and args.milling == "zigzag":
        raise InputError("--milling zigzag: --pattern offset cuts every rectangle one way, climb (default) or "
                         "conventional")
    if args.macro and args.pattern != "raster":
        raise InputError(f"--pattern {args.pattern}: a roughing macro runs raster rows; leave out --macro "
                         "for offset clearing")
    if args.macro and args.max_samples is not None:
        raise InputError(f"--max-samples {args.max_samples}: a roughing macro makes no drop-cutter samples; "
                         "leave it out (--max-points limits the moves the control runs)")


def run(args, out, err) -> int:
    from ..job import job_program, plan_job
    from ..job.spec import parse_job
    from ..toolpath.rough import MAX_ROUGH_SAMPLES
    from ._progress import progress_bar
    from .job import guard_job, report

    _refuse(args)
    if args.macro:
        from ..errors import InputError
        from ..macro.roughing import piecewise_macro_refusal
        from ._common import read_piecewise

        pieces = read_piecewise(args.file)
        if pieces is not None:
            raise InputError(f"--macro: {piecewise_macro_refusal(pieces, 'a roughing macro')}")
    samples = MAX_ROUGH_SAMPLES if args.max_samples is None else args.max_samples
    spec, surface = guard_job(parse_job(job_data(args), "lagsym rough", lengths_in_mm=True), args, err)
    with progress_bar(err) as progress:
        planned = plan_job(spec, args.max_points, samples, progress=progress, max_exact_mb=exact_limit(args),
                           surface=surface)
    prog = job_program(planned)
    if args.output and args.output != "-":
        write_text(args.output, prog.text, newline="")
    else:
        out.write(prog.text)
    rp = planned.operations[0].path
    err.write(f"{len(rp.levels_mm)} levels from Z{rp.levels_mm[0]:.3f} to Z{rp.levels_mm[-1]:.3f} mm\n")
    if args.macro:
        c = rp.clearance
        err.write(f"macro: {len(prog.text.encode('ascii'))} bytes; tip at min(F + stock + {rp.tool.radius_mm:g} "
                  f"|grad F| + A, B) over {c.tiles}x{c.tiles} tiles: A {c.a_mm.min():.3f} to {c.a_mm.max():.3f} mm "
                  f"(curvature up to {c.curvature_per_mm.max():.4f}/mm), B the surface's bound plus "
                  f"{c.chord_mm.min() + c.extra_mm:.3f} to {c.chord_mm.max() + c.extra_mm:.3f} mm\n")
    report(planned, prog, err)
    return 0
