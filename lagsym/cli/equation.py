"""``lagsym equation FILE``: the exact surface z = F(x, y) through a grid of control points."""

from __future__ import annotations

from ..equation import FORMATS, render
from ..io import read_points
from ..lagrange import lagrange_surface
from ._common import emit

NAME = "equation"
ORDER = 10
HELP = "print the exact Lagrange surface z = F(x, y) through a grid of control points"
DESCRIPTION = """Print the exact tensor-product Lagrange surface z = F(x, y) through the
control points in FILE (JSON or CSV), with exact rational coefficients.

examples:
  lagsym equation examples/paper-example-1.json
  lagsym equation examples/paper-example-4.json --digits 4
  lagsym equation examples/paper-example-2.json --format json"""


def add_arguments(p) -> None:
    p.add_argument("file", help="points file: JSON or CSV with x,y,z")
    add_format_arguments(p)


def add_format_arguments(p) -> None:
    p.add_argument("--format", choices=FORMATS, default="sympy",
                   help="sympy (default, parseable by sympy.sympify), latex, json, horner (nested), python")
    p.add_argument("--digits", type=int, metavar="N",
                   help="round coefficients to N significant digits, as the paper prints them")
    p.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of standard output")


def run(args, out, err) -> int:
    surface = lagrange_surface(read_points(args.file))
    emit(render(surface, args.format, args.digits), args.output, out)
    return 0
