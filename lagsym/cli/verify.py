"""``lagsym verify SURFACE PROGRAM``: simulate a program's cut and compare it with the exact surface."""

from __future__ import annotations

from ..errors import ExitStatus
from ..gcode import parse_moves
from ..io import read_points, read_program
from ..lagrange import lagrange_surface
from ..machine import TOOL_SHAPES, Placement, Tool, mm_per_surface_unit
from ..verify import MAX_CELLS, MAX_CONTACTS, simulate_cut
from ._common import CORNER_MM, SCALE, TOOL_MM, count, number, origin

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
    p.add_argument("--tool-shape", choices=TOOL_SHAPES, default="ball", help="ball (default), flat or bull (bull nose: give --corner-radius)")
    p.add_argument("--corner-radius", type=CORNER_MM, metavar="MM",
                   help="corner radius of a bull-nose cutter (--tool-shape bull), less than half its diameter")
    p.add_argument("--tool-diameter", type=TOOL_MM, default=6.0, metavar="MM", help="cutter diameter (default 6)")
    p.add_argument("--scale", type=SCALE, default=1.0, help="model scale, as for toolpath: a points file in inches is 25.4 mm per unit at scale 1 (default 1)")
    p.add_argument("--origin", default="0,0,0", metavar="X,Y,Z", help="work offset the program was made with, mm")
    p.add_argument("--cell", type=number(1e-3, 1_000.0, "mm"), metavar="MM", help="height-map cell size (default: box side / 400)")
    p.add_argument("--gouge-limit", type=number(0.0, 1_000.0, "mm"), metavar="MM",
                   help="depth from which a cut counts as a gouge "
                        "(default: program rounding plus simulation resolution)")
    p.add_argument("--max-cells", type=count(1, 10**10), default=MAX_CELLS, metavar="N",
                   help=f"refuse a height map of more than N cells (default {MAX_CELLS:.2g})")
    p.add_argument("--max-contacts", type=count(1, 10**14), default=MAX_CONTACTS, metavar="N",
                   help=f"refuse a simulation of more than N tool positions times cells under the tool "
                        f"(default {MAX_CONTACTS:.2g})")


def run(args, out, err) -> int:
    surface = lagrange_surface(read_points(args.surface))
    place = Placement(mm_per_surface_unit(surface.grid.units, args.scale), origin(args.origin))
    text = read_program(args.program)
    moves = parse_moves(text, source=args.program)
    report = simulate_cut(surface, moves, Tool(args.tool_shape, args.tool_diameter, args.corner_radius), place, cell_mm=args.cell,
                          gouge_limit_mm=args.gouge_limit, max_cells=args.max_cells, max_contacts=args.max_contacts)
    out.write("\n".join(report.summary()) + "\n")
    return ExitStatus.WARNING if report.gouges else ExitStatus.OK
