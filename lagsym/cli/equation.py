"""``lagsym equation FILE``: the exact surface z = F(x, y) through a grid of control points."""

from __future__ import annotations

from ..equation import FORMATS, MAX_TERMS, render, rounding_miss
from ..lagrange import lagrange_surface
from ._common import add_exact_limit, exact_limit, DIGITS, add_points_arguments, count, emit, load_points

DESCRIPTION = """Print the exact tensor-product Lagrange surface z = F(x, y) through the
control points in FILE (JSON or a table: CSV, TSV, .xyz), with exact rational
coefficients.  With --digits, standard error says how far the rounded
equation misses the control points (computed exactly); standard output stays
one parseable equation.

examples:
  lagsym equation examples/paper-example-1.json
  lagsym equation examples/paper-example-4.json --digits 4
  lagsym equation examples/paper-example-2.json --format json"""


def add_arguments(p) -> None:
    add_exact_limit(p)
    p.add_argument("file", help="points file: JSON or a table with x,y,z")
    add_points_arguments(p)
    add_format_arguments(p)


def add_format_arguments(p) -> None:
    p.add_argument("--format", choices=FORMATS, default="sympy",
                   help="sympy (default, parseable by sympy.sympify), latex, json, horner (nested), python")
    p.add_argument("--digits", type=DIGITS, metavar="N",
                   help="round coefficients to N significant digits, as the paper prints them")
    p.add_argument("--max-terms", type=count(1, 10**9), default=MAX_TERMS, metavar="N",
                   help=f"refuse an equation of more than N terms, except with --digits (default {MAX_TERMS})")
    p.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of standard output")


def run(args, out, err) -> int:
    surface = lagrange_surface(load_points(args.file, args, err), max_mb=exact_limit(args))
    emit(render(surface, args.format, args.digits, args.max_terms), args.output, out)
    report_rounding(surface, args.digits, surface.grid.units, err)
    return 0


def report_rounding(obj, digits: int | None, units: str | None, err) -> None:
    """Say on standard error how far the equation rounded to ``digits`` misses the control points."""
    if digits is not None:
        err.write(f"# {rounding_miss(obj, digits).text(units)}\n")
