"""``lagsym curve FILE``: the exact 1-D Lagrange curve y = F(x) through a set of points."""

from __future__ import annotations

from ..equation import render
from ..lagrange import lagrange_curve
from ._common import add_exact_limit, exact_limit, add_points_arguments, emit, load_points
from .equation import add_format_arguments, report_rounding

DESCRIPTION = """Print the exact Lagrange interpolating polynomial y = F(x) through the
points in FILE (JSON [[x, y], ...] or a table with x,y).  With --digits,
standard error says how far the rounded equation misses the points.

examples:
  lagsym curve examples/paper-curve-3rd.json
  lagsym curve examples/paper-curve-3rd.json --digits 4"""


def add_arguments(p) -> None:
    add_exact_limit(p)
    p.add_argument("file", help="points file: JSON or a table with x,y")
    add_points_arguments(p)
    add_format_arguments(p)


def run(args, out, err) -> int:
    curve = lagrange_curve(load_points(args.file, args, err, "curve"), max_mb=exact_limit(args))
    emit(render(curve, args.format, args.digits, args.max_terms), args.output, out)
    report_rounding(curve, args.digits, curve.points.units, err)
    return 0
