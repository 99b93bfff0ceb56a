"""``lagsym verify SURFACE PROGRAM``: simulate a program's cut and compare it with the exact surface."""

from __future__ import annotations

from ..errors import ExitStatus, InputError
from ..gcode import parse_moves
from ..io import read_points, read_program
from ..lagrange import lagrange_surface
from ..machine import TOOL_SHAPES, Placement, Tool, mm_per_surface_unit
from ._common import origin

NAME = "verify"
ORDER = 65
HELP = "simulate a G-code program's cut on a height map and report gouge, scallop and area not reached"
DESCRIPTION = """Simulate the material the moves of PROGRAM remove with the given tool, on a
height map over the box of the control points in SURFACE, and compare the
result with the exact surface: the worst gouge (the cut below the surface),
the largest scallop left above it, and the area the tool never reached.  Any
point-list program can be checked this way, lagsym's or not.

exit status: 0 no gouge; 1 the program gouges (deeper than the limit); 2 bad
input (an unreadable file, a program with arcs or canned cycles).

examples:
  lagsym verify examples/paper-example-4.json O1000.nc --scale 20 --tool-diameter 6
  lagsym verify examples/paper-example-1.json part.ngc --scale 10 --tool-diameter 6 --cell 0.1"""


def add_arguments(p) -> None:
    p.add_argument("surface", help="points file: JSON or CSV with x,y,z")
    p.add_argument("program", help="G-code program (point list: G00/G01 moves)")
    p.add_argument("--tool-shape", choices=TOOL_SHAPES, default="ball", help="ball (default) or flat end")
    p.add_argument("--tool-diameter", type=float, default=6.0, metavar="MM", help="cutter diameter (default 6)")
    p.add_argument("--scale", type=float, default=1.0, help="model scale, as for toolpath: a points file in inches is 25.4 mm per unit at scale 1 (default 1)")
    p.add_argument("--origin", default="0,0,0", metavar="X,Y,Z", help="work offset the program was made with, mm")
    p.add_argument("--cell", type=float, metavar="MM", help="height-map cell size (default: box side / 400)")
    p.add_argument("--gouge-limit", type=float, metavar="MM",
                   help="depth from which a cut counts as a gouge "
                        "(default: program rounding plus simulation resolution)")


def run(args, out, err) -> int:
    from ..verify import simulate_cut

    surface = lagrange_surface(read_points(args.surface))
    place = Placement(mm_per_surface_unit(surface.grid.units, args.scale), origin(args.origin))
    text = read_program(args.program)
    moves = parse_moves(text, source=args.program)
    report = simulate_cut(surface, moves, Tool(args.tool_shape, args.tool_diameter), place, cell_mm=args.cell, gouge_limit_mm=args.gouge_limit)
    out.write("\n".join(report.summary()) + "\n")
    return ExitStatus.WARNING if report.gouges else ExitStatus.OK
