"""``lagsym fit POINTS -o surface.json``: an exact least-squares polynomial surface through measured points."""

from __future__ import annotations

import io

from ..conditioning import AMPLIFICATION_LIMIT
from ..errors import InputError
from ..export.surfacejson import write_surface_json
from ..fit import CRITERIA, MAX_DEGREE, fit_surface
from ..io import read_text
from ..values import exact_number, NotANumber
from ._common import add_file_points_limit, COLUMNS_HELP, emit, exact, measured_points
from ._lines import say

DESCRIPTION = """Fit the exact least-squares tensor-product polynomial
z = sum c[a][b] x^a y^b (a <= P, b <= Q) to the points in FILE: a grid, a
grid with points missing, or scattered x,y,z rows.  Decimals in the file are
exact and so are the coefficients.  Measured points (a probe, a CMM, a
digitiser) carry errors that an interpolant amplifies; a fit of low degree
passes close to them instead (the paper, section 2).

The degrees are given (--degree 4, or 4x3 for x and y) or chosen by
generalized cross-validation or leave-one-out (--degree auto, the default),
the choice and its score printed.  The report gives the largest and RMS
residual, a noise estimate, the points beyond --threshold (default three
times the noise estimate) and where the surface extrapolates (the part of
the box outside the points' convex hull).  The surface file (-o, a
lagsym-surface JSON document; standard output without -o, the report then on
standard error) is read by every command that reads a points file:
equation, check, sample, export, toolpath, rough, job, macro, plot.

FILE may also be the results a 'lagsym probe' program sent back (DPRNT text
or a LinuxCNC log): they are read as 'lagsym read-probe' reads them, the
probe's tip radius taken off.

examples:
  lagsym fit examples/probe-12x12.csv -o surface.json
  lagsym fit examples/probe-12x12.csv --degree 4x3 --threshold 0.05 -o surface-4x3.json
  lagsym fit examples/probe-scattered.csv --criterion loo -o scattered.json
  lagsym fit examples/probe-results.txt -o probed.json
  lagsym toolpath surface.json -o part.nc"""


def add_arguments(p) -> None:
    p.add_argument("file", help="points file: JSON or a table with x,y,z (a grid, or scattered)")
    p.add_argument("--columns", metavar="LIST", help=COLUMNS_HELP)
    add_file_points_limit(p)
    p.add_argument("--degree", default="auto", metavar="P[xQ]",
                   help=f"degree in x and y (4), or in each (4x3), 0 to {MAX_DEGREE}; "
                        f"auto (default) chooses them by --criterion")
    p.add_argument("--criterion", choices=CRITERIA,
                   help="how --degree auto chooses: gcv (default; generalized cross-validation) or loo "
                        "(leave-one-out)")
    p.add_argument("--max-degree", metavar="P[xQ]",
                   help="the highest degrees --degree auto tries (default: one less than the distinct x and "
                        "y values, at most 8)")
    p.add_argument("--weights", metavar="FILE",
                   help="one positive weight a line, in the order of the points (for example 1/sigma^2)")
    p.add_argument("--threshold", type=exact(0.0, 1e5, above=True), metavar="Z",
                   help="list the points whose residual exceeds Z, in the units of z "
                        "(default: three times the noise estimate)")
    p.add_argument("-o", "--output", metavar="FILE", help="write the surface file here instead of standard output")


def read_weights(path: str) -> list:
    """The weights of ``--weights``: one exact number a line; blank lines and ``#`` comments are skipped."""
    name, text = read_text(path)
    out = []
    for lineno, line in enumerate(text.splitlines(), 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        try:
            out.append(exact_number(line))
        except NotANumber as e:
            raise InputError(f"--weights {name}: line {lineno}: {e}") from None
    return out


def run(args, out, err) -> int:
    data = measured_points(args.file, args.columns)
    if not data.plain:
        say(err, f"{data.source}: read as {data.layout}")
    weights = read_weights(args.weights) if args.weights else None
    if args.degree != "auto" and (args.criterion or args.max_degree):
        raise InputError(f"--{'criterion' if args.criterion else 'max-degree'} chooses the degrees, and --degree "
                         f"{args.degree} gives them: leave out one or the other")
    fit = fit_surface(data.points, None if args.degree == "auto" else args.degree, criterion=args.criterion,
                      weights=weights, max_degree=args.max_degree, source=data.source, units=data.units)
    buf = io.StringIO()
    write_surface_json(buf, fit.surface, fit.coefficients, fit)
    emit(buf.getvalue(), args.output, out)
    report = out if args.output and args.output != "-" else err
    report.write(fit.report(args.threshold) + "\n")
    if fit.amplification > AMPLIFICATION_LIMIT:
        err.write(f"lagsym: warning: this fit amplifies errors in the points up to {fit.amplification:.4g} times, "
                  f"above the limit of {AMPLIFICATION_LIMIT:g}: toolpath, rough, job, macro, export and sample "
                  f"will refuse it without --accept-conditioning; lower degrees (--degree auto) amplify less\n")
    if args.output and args.output != "-":
        report.write(f"wrote {args.output}: the exact surface, read by every command that reads points\n")
    return 0
