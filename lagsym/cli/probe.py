"""``lagsym probe -o PROBE.nc``: a probing program for a box, its nodes Chebyshev-spaced by default."""

from __future__ import annotations

from ..errors import InputError
from ..probe import PROBE_DIALECTS, SPACINGS, ProbeSettings, node_plan, probe_program
from ..values import as_exact
from ._common import WORK_OFFSET, count, dialect_help, emit, exact

DESCRIPTION = """Write a program that measures the part on the machine with a touch probe:
one probing move at each node of a grid over --box, the positions sent back
as text, which 'lagsym read-probe' (or 'lagsym fit') turns into points.

Fanuc and Haas: G31 skip moves, the results (#5061-#5063) sent out of the
serial port with POPEN/DPRNT/PCLOS ('lagsym receive' takes them), and #3000
raised when the probe does not trip within the probing distance.  LinuxCNC:
G38.2 probing moves (an error without contact), the results written to a log
file with (LOGOPEN,..)/(LOG,..)/(LOGCLOSE).

The nodes are the Chebyshev extrema of each side by default (ends included):
interpolation there amplifies errors least, so a fit on them is well
conditioned near the box's edges as well as in its middle (docs/probing.md).
--spacing even spaces them evenly; --x-nodes and --y-nodes list them.  Their
number is --degree + 1 + --margin a side, --degree the fit degree wanted.

Each node: up to --retract, across, down to the approach height (--top +
tip radius + --clearance), then the probing move at --feed down to --bottom +
tip radius - --overtravel.  The positions are those of the tip's centre: set
the probe's length offset to the tip centre.  Millimetres only (G21).

examples:
  lagsym probe --box 0,100,0,60 --top 12 --bottom 0 --tip-radius 1 -o probe.nc
  lagsym probe --dialect linuxcnc --box 0,100,0,60 --top 12 --bottom 0 --tip-radius 1 --degree 5 -o probe.ngc
  lagsym probe --box 0,100,0,60 --top 12 --bottom 0 --tip-radius 1 --spacing even --nodes 9x7 -o probe.nc"""


def add_arguments(p) -> None:
    p.add_argument("--dialect", choices=PROBE_DIALECTS, default=PROBE_DIALECTS[0],
                   help=f"the control: {dialect_help(PROBE_DIALECTS)}")
    p.add_argument("--box", metavar="X0,X1,Y0,Y1",
                   help="the region to probe, in mm (needed unless the nodes are listed)")
    p.add_argument("--degree", default="4", metavar="P[xQ]",
                   help="the fit degree wanted in x and y (default 4): degree + 1 + margin nodes a side")
    p.add_argument("--margin", type=count(0, 20), default=2, metavar="N",
                   help="nodes a side beyond degree + 1, for the least-squares fit (default 2)")
    p.add_argument("--nodes", metavar="NXxNY", help="the nodes a side, given outright (instead of --degree)")
    p.add_argument("--spacing", choices=SPACINGS[:2], default="chebyshev",
                   help="chebyshev (default: the Chebyshev extrema, ends included) or even")
    p.add_argument("--x-nodes", metavar="LIST", help="the x values to probe, comma-separated (with --y-nodes)")
    p.add_argument("--y-nodes", metavar="LIST", help="the y values to probe, comma-separated (with --x-nodes)")
    p.add_argument("--tip-radius", type=exact(0, 49.999), required=True, metavar="MM",
                   help="the probe's ball tip radius, stated in the program and its results")
    p.add_argument("--top", type=exact(-9999, 9999), required=True, metavar="Z",
                   help="the highest the part's surface may be over the box, in mm")
    p.add_argument("--bottom", type=exact(-9999, 9999), required=True, metavar="Z",
                   help="the lowest the part's surface may be, in mm")
    p.add_argument("--clearance", type=exact(0, 1000, above=True), default=2, metavar="MM",
                   help="the tip's lowest point this far above --top at the start of each probing move (default 2)")
    p.add_argument("--overtravel", type=exact(0, 1000, above=True), default=2, metavar="MM",
                   help="how far below --bottom a probing move goes before it counts as not tripped (default 2)")
    p.add_argument("--retract", type=exact(-9999, 9999), metavar="Z",
                   help="the height of the moves between nodes (default 10 mm above the approach height)")
    p.add_argument("--feed", type=exact(0, 5000, above=True), default=100, metavar="MM/MIN",
                   help="the probing feed (default 100)")
    p.add_argument("--program-number", type=count(1, 99999), default=1000, metavar="N",
                   help="the O number (Fanuc, Haas; default 1000)")
    p.add_argument("--work-offset", type=WORK_OFFSET, default="G54", metavar="WORD", help="default G54")
    p.add_argument("--log-name", default="probe-results.txt", metavar="NAME",
                   help="LinuxCNC: the log file the results go to (default probe-results.txt)")
    p.add_argument("-o", "--output", metavar="FILE", help="write the program here instead of standard output")


def _pair(text: str, option: str) -> tuple[int, int]:
    parts = text.lower().split("x")
    try:
        values = [int(v) for v in parts]
    except ValueError:
        raise InputError(f"{option} {text!r}: whole numbers, as 4 or 4x3") from None
    if len(values) not in (1, 2):
        raise InputError(f"{option} {text!r}: one number, or two as 4x3")
    return (values[0], values[-1])


def _list(text: str, option: str) -> list:
    return [as_exact(v.strip(), option) for v in text.split(",") if v.strip()]


def run(args, out, err) -> int:
    if (args.x_nodes is None) != (args.y_nodes is None):
        raise InputError("--x-nodes and --y-nodes go together")
    if args.x_nodes is not None:
        plan = node_plan(None, spacing="given", given=(_list(args.x_nodes, "--x-nodes"),
                                                       _list(args.y_nodes, "--y-nodes")))
    else:
        if not args.box:
            raise InputError("--box X0,X1,Y0,Y1 is needed (or list the nodes with --x-nodes and --y-nodes)")
        box = _list(args.box, "--box")
        if len(box) != 4:
            raise InputError(f"--box {args.box!r}: four numbers X0,X1,Y0,Y1")
        nodes = _pair(args.nodes, "--nodes") if args.nodes else None
        if nodes is not None and not all(2 <= n <= 50 for n in nodes):
            raise InputError(f"--nodes {args.nodes}: 2 to 50 a side")
        plan = node_plan(box, _pair(args.degree, "--degree"), spacing=args.spacing, margin=args.margin, nodes=nodes)
    settings = ProbeSettings(args.tip_radius, args.top, args.bottom, clearance_mm=args.clearance,
                             overtravel_mm=args.overtravel, retract_mm=args.retract, feed_mm_min=args.feed)
    text = probe_program(plan, settings, args.dialect, program_number=args.program_number,
                         work_offset=args.work_offset, log_name=args.log_name)
    emit(text, args.output, out)
    report = out if args.output and args.output != "-" else err
    report.write(f"{plan.describe()}, {len(plan)} probing moves on {args.dialect}: approach Z"
                 f"{float(settings.approach_mm):g}, probe to Z{float(settings.end_mm):g} "
                 f"(at most {float(settings.distance_mm):g} mm), tip radius {float(settings.tip_radius_mm):g} mm\n")
    return 0
