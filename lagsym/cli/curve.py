"""``lagsym curve FILE``: the exact 1-D Lagrange curve y = F(x) through a set of points."""

from __future__ import annotations

from ..equation import render
from ..io import read_curve_points
from ..lagrange import lagrange_curve
from ._common import emit
from .equation import add_format_arguments

NAME = "curve"
ORDER = 20
HELP = "print the exact Lagrange curve y = F(x) through a set of points"
DESCRIPTION = """Print the exact Lagrange interpolating polynomial y = F(x) through the
points in FILE (JSON [[x, y], ...] or CSV with x,y).

examples:
  lagsym curve examples/paper-curve-3rd.json
  lagsym curve examples/paper-curve-3rd.json --digits 4"""


def add_arguments(p) -> None:
    p.add_argument("file", help="points file: JSON or CSV with x,y")
    add_format_arguments(p)


def run(args, out, err) -> int:
    curve = lagrange_curve(read_curve_points(args.file))
    emit(render(curve, args.format, args.digits), args.output, out)
    return 0
