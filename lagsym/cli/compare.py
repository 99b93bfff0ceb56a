"""``lagsym compare FILE``: the paper's deviation table for Lagrange, Hermite, Bezier and B-spline surfaces."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..compare import DEFAULT_SAMPLES, DEFAULT_TOLERANCE_MM, TABLE_FORMATS, compare_surfaces, render_table
from ..formula import parse_formula
from ..io import TABLE_SUFFIXES, read_points
from ..surfaces import HERMITE_KINDS, METHODS
from ._common import add_file_points_limit, add_exact_limit, count, emit, number

DESCRIPTION = """Build the Lagrange, Hermite, Bezier and B-spline surfaces from the control
points in FILE, sample them at the same (x, y) positions and print the paper's
deviation measures (Table 1), one column per method.

The reference z_f is the Lagrange surface (default), a formula in x and y
(numbers, x, y, pi, + - * / ** ( ) and sin cos tan exp log sqrt abs), or a
points file of measurements (a name ending in .json, .csv, .tsv, .txt, .xyz,
.dat or .asc), compared at the measured positions.

examples:
  lagsym compare examples/paper-example-4.json
  lagsym compare examples/parabola.json --reference "50 - ((x-20)**2 + (y-20)**2)/20" --degree 4
    (a paraboloid like Table 1's; the paper's own function and net are not given)
  lagsym compare examples/paper-example-1.json --reference "x**2 + 3*y" --samples 41x41 --format csv"""


def _samples(text: str) -> tuple[int, int]:
    parts = text.lower().split("x")
    try:
        counts = [int(p) for p in parts]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} should be NX or NXxNY, for example 41x41") from None
    if len(counts) == 1:
        counts *= 2
    if len(counts) != 2 or min(counts) < 2 or max(counts) > 10_000:
        raise argparse.ArgumentTypeError(f"{text!r} should be NX or NXxNY with counts from 2 to 10000")
    return counts[0], counts[1]


def _methods(text: str) -> list[str]:
    names = [t.strip().lower() for t in text.split(",") if t.strip()]
    for name in names:
        if name not in METHODS:
            raise argparse.ArgumentTypeError(f"method {name!r} is not one of {', '.join(METHODS)}")
    if not names:
        raise argparse.ArgumentTypeError(f"no methods given; choose from {', '.join(METHODS)}")
    return names


def add_arguments(p) -> None:
    p.add_argument("file", help="control points file: JSON or CSV with x,y,z")
    add_file_points_limit(p)
    p.add_argument("--reference", default="lagrange", metavar="REF",
                   help="z_f: 'lagrange' (default), a formula such as '0.5*x**2 + y', or a .json/.csv file of "
                        "measured points")
    add_exact_limit(p)
    p.add_argument("--samples", type=_samples, metavar="NXxNY",
                   help=f"sample grid over the control box (default {DEFAULT_SAMPLES[0]}x{DEFAULT_SAMPLES[1]})")
    p.add_argument("--methods", type=_methods, default=list(METHODS), metavar="LIST",
                   help=f"comma-separated columns, from {','.join(METHODS)} (default all)")
    p.add_argument("--degree", type=count(1, 30), default=3, metavar="P",
                   help="B-spline degree in each direction (default 3, capped at n-1)")
    p.add_argument("--hermite", choices=HERMITE_KINDS, default="corner",
                   help="corner: one patch on the 4 corners (default; the paper does not state its Hermite "
                        "rule, and on an evenly spaced net this patch equals the Bezier surface, which the "
                        "paper's Table 1 does not show); "
                        "piecewise: C1 patches through every point")
    p.add_argument("--tolerance", type=number(0.0, 1_000.0, "mm"), default=DEFAULT_TOLERANCE_MM, metavar="MM",
                   help=f"|d| at or below this counts as a coincided point (default {DEFAULT_TOLERANCE_MM:g})")
    p.add_argument("--format", choices=TABLE_FORMATS, default="text", help="table format (default text)")
    p.add_argument("-o", "--output", metavar="FILE", help="write the table to FILE instead of standard output")
    p.add_argument("--plot", metavar="FILE", help="also write a map of the deviation z_f - z_a per method to FILE (an image)")


def _reference(text: str):
    """'lagrange', a points file (named by its extension: .json, .csv, ...), or else a formula.

    Only the extension decides, never whether a file of that name happens to exist: ``--reference x``
    is the formula x even where a file called x lies in the current folder.
    """
    if text == "lagrange":
        return text
    if Path(text).suffix.lower() in (".json",) + TABLE_SUFFIXES:
        return read_points(text)
    return parse_formula(text)


def run(args, out, err) -> int:
    grid = read_points(args.file)
    reference = _reference(args.reference)
    if args.plot:
        from ..plot import image_format

        image_format(args.plot)  # refuse a bad image name before the work
    comparison = compare_surfaces(grid, reference, samples=args.samples, methods=args.methods,
                                  degree=args.degree, hermite=args.hermite, tolerance=args.tolerance,
                                  max_mb=args.max_exact_mb)
    if args.plot:
        from ..plot import deviation_map

        # The maps draw the table's d = z_f - z_a, titled "Lagrange - Hermite" when z_f is the Lagrange surface.
        name = "Lagrange" if reference == "lagrange" else "z_f"
        deviation_map(comparison.xs, comparison.ys, comparison.deviations, args.plot, reference=name)
    emit(render_table(comparison, args.format), args.output, out)
    return 0
