"""``lagsym verify SURFACE PROGRAM``: simulate a program's cut and compare it with the exact surface.

``lagsym verify --job JOB.toml PROGRAM`` simulates a whole job's program from its block instead.
"""

from __future__ import annotations

from ..errors import ExitStatus, InputError
from ..gcode import parse_moves
from ..gcode.moves import MAX_MOVE_POINTS
from ..io import read_points, read_program
from ..lagrange import lagrange_surface
from ..machine import TOOL_SHAPES, Placement, Tool, mm_per_surface_unit
from ..verify import MAX_CELLS, MAX_CONTACTS, MAX_LEFT_MM, program_resolution_mm, simulate_cut
from ._common import add_file_points_limit, add_exact_limit, exact_limit, CORNER_MM, SCALE, TOOL_MM, count, number, origin, read_piecewise
from ._progress import progress_bar

DESCRIPTION = """Simulate the material the moves of PROGRAM remove with the given tool, on a
height map over the box of the control points in SURFACE, and compare the
result with the exact surface: the worst gouge (the cut below the surface),
the deepest rapid (G00) into the part, the most material left anywhere on the
part (its edges included) and where, the scallop between passes (normal to
the surface, a tool radius or more from the edges) and the area the tool never
reached.  Any point-list program can be checked this way, lagsym's or not,
with G02/G03 arcs (I J K centres, G17/G18/G19) too.  SURFACE may be a
piecewise surface ('lagsym piecewise'): each point is compared with the
piece whose cell holds it, and the curvature in the material-left bound is
bounded piece by piece (its second derivatives jump at the borders).

exit status: 0 the program passes; 1 it gouges or a rapid goes into the part
(deeper than the gouge limit), or it leaves more material than --max-left
(or a scallop above --max-scallop); 2 bad input (an unreadable file, a
program with canned cycles or arcs given by a radius R).

With --job the first file is a job file (TOML, as for lagsym job): the
program is simulated from the job's block, each part of it (from one M06 to
the next) with the cutter its T number names in the job, and verify reports
what each tool removed, any rapid move through material, the worst gouge and
the material left above the surface (largest, where, and a histogram).  The
job gives the tools, scale and origin, so those options are refused with it.
It exits 1 on a gouge, a rapid through material, or, when --max-left is
given, more material left than that.

On a terminal, a progress bar on standard error shows the moves swept.

examples:
  lagsym verify examples/paper-example-4.json O1000.nc --scale 20 --tool-diameter 6 --max-left 0.12
  lagsym verify examples/paper-example-1.json part.ngc --scale 10 --tool-diameter 6 --cell 0.1
  lagsym verify pieces.json pieces.nc --tool-diameter 6 --max-left 0.5
  lagsym verify --job examples/example-4-job.toml job.ngc --cell 0.5"""


# Options the job file gives instead, refused with --job (with their defaults without it).
_SINGLE_TOOL = {"tool_shape": "ball", "tool_diameter": 6.0, "corner_radius": None, "scale": 1.0, "origin": "0,0,0",
                "max_contacts": MAX_CONTACTS}


def add_arguments(p) -> None:
    add_exact_limit(p)
    add_file_points_limit(p)
    p.add_argument("surface", metavar="SURFACE",
                   help="points file: JSON or CSV with x,y,z, or a 'lagsym piecewise' surface (with --job: the job file)")
    p.add_argument("program", help="G-code program (point list: G00/G01 moves, G02/G03 arcs with I J K)")
    p.add_argument("--job", action="store_true",
                   help="SURFACE is a job file (TOML): simulate the whole job from its block, tool by tool")
    p.add_argument("--tool-shape", choices=TOOL_SHAPES, help="ball (default), flat or bull (bull nose: give --corner-radius)")
    p.add_argument("--corner-radius", type=CORNER_MM, metavar="MM",
                   help="corner radius of a bull-nose cutter (--tool-shape bull), less than half its diameter")
    p.add_argument("--tool-diameter", type=TOOL_MM, metavar="MM", help="cutter diameter (default 6)")
    p.add_argument("--scale", type=SCALE, help="model scale, as for toolpath: a points file in inches is 25.4 mm per unit at scale 1 (default 1)")
    p.add_argument("--origin", metavar="X,Y,Z", help="work offset the program was made with, mm (default 0,0,0)")
    p.add_argument("--cell", type=number(1e-3, 1_000.0, "mm"), metavar="MM",
                   help="height-map cell size (default: box side / 400; with --job, block side / 400)")
    p.add_argument("--gouge-limit", type=number(0.0, 1_000.0, "mm"), metavar="MM",
                   help="depth from which a cut counts as a gouge (default: what the program's rounding can "
                        "cause: half a unit of its last decimal, and as much sideways times the steepest slope; "
                        "with --job, program rounding plus simulation resolution)")
    p.add_argument("--max-left", type=number(0.0, 1_000.0, "mm"), metavar="MM",
                   help=f"material left anywhere above which the program fails (default {MAX_LEFT_MM}; with "
                        f"--job, checked only when given)")
    p.add_argument("--max-scallop", type=number(0.0, 1_000.0, "mm"), metavar="MM",
                   help="scallop between passes (normal to the surface) above which the program fails "
                        "(default: reported, not checked; not with --job)")
    p.add_argument("--max-cells", type=count(1, 10**10), default=MAX_CELLS, metavar="N",
                   help=f"refuse a height map of more than N cells (default {MAX_CELLS:.2g})")
    p.add_argument("--max-moves", type=count(1, 10**9), default=MAX_MOVE_POINTS, metavar="N",
                   help=f"refuse a program whose moves make more than N points, each arc read as pieces that "
                        f"sag 1e-5 mm, counted as it is read (default {MAX_MOVE_POINTS:.2g})")
    p.add_argument("--max-contacts", type=count(1, 10**14), metavar="N",
                   help=f"refuse a simulation of more than N segments swept times cells under the tool "
                        f"(default {MAX_CONTACTS:.2g})")


def run(args, out, err) -> int:
    if args.job:
        return _run_job(args, out, err)
    for key, default in _SINGLE_TOOL.items():
        if getattr(args, key) is None:
            setattr(args, key, default)
    surface = read_piecewise(args.surface) or lagrange_surface(read_points(args.surface), max_mb=exact_limit(args))
    place = Placement(mm_per_surface_unit(surface.grid.units, args.scale), origin(args.origin))
    text = read_program(args.program)
    moves = parse_moves(text, source=args.program, max_points=args.max_moves)
    tool = Tool(args.tool_shape, args.tool_diameter, args.corner_radius)
    with progress_bar(err) as progress:
        report = simulate_cut(surface, moves, tool, place, cell_mm=args.cell,
                              program_resolution_mm=program_resolution_mm(text), gouge_limit_mm=args.gouge_limit,
                              max_cells=args.max_cells, max_contacts=args.max_contacts,
                              max_left_mm=MAX_LEFT_MM if args.max_left is None else args.max_left,
                              max_scallop_mm=args.max_scallop, progress=progress)
    out.write("\n".join(report.summary()) + "\n")
    return ExitStatus.WARNING if report.fails else ExitStatus.OK


def _run_job(args, out, err) -> int:
    from ..job import read_job
    from ..machined import machine_job

    if args.max_scallop is not None:
        raise InputError("--max-scallop is for a single program; with --job verify checks the material left "
                         "(--max-left)")
    given = [key for key in _SINGLE_TOOL if getattr(args, key) is not None]
    if given:
        option = "--" + given[0].replace("_", "-")
        raise InputError(f"{option} is not for --job: the job file {args.surface} names the tools, scale and origin")
    spec = read_job(args.surface)
    text = read_program(args.program)
    with progress_bar(err) as progress:
        part = machine_job(spec, text, source=args.program, cell_mm=args.cell, gouge_limit_mm=args.gouge_limit,
                           max_cells=args.max_cells, progress=progress)
    out.write("\n".join(part.summary()) + "\n")
    too_much = args.max_left is not None and part.left_mm > args.max_left
    if too_much:
        out.write(f"more material left than --max-left {args.max_left:g} mm\n")
    return ExitStatus.WARNING if part.gouges or part.crashes or too_much else ExitStatus.OK
