"""``lagsym check FILE``: what the paper's section 4 warns about, measured for this file."""

from __future__ import annotations

import json

from ..conditioning import check_curve, check_surface
from ..errors import ExitStatus
from ..grid import CurvePoints
from ..lagrange import lagrange_curve, lagrange_surface
from ._common import add_exact_limit, exact_limit, add_points_arguments, load_points

DESCRIPTION = """Measure what the paper's section 4 warns about for the points in FILE:
degree in each direction (above the paper's line of 6 a warning only on
nodes that amplify errors more than tenfold: Chebyshev-like nodes are well
conditioned at any degree), the spacing ratio between the directions, the
Lebesgue constant of each node set, the surface's amplification of errors in
its points (their product; a fitted surface file's own figure), which the
commands that machine or export a surface refuse above 100, and the overshoot
of the interpolant between the nodes (sampled, and at most, certified from its
Bezier form).  Warnings go to standard output; the
exit status is 0, or 1 with --strict when there is a warning.

examples:
  lagsym check examples/paper-example-4.json
  lagsym check examples/paper-example-1.json --strict --format json"""


def add_arguments(p) -> None:
    add_exact_limit(p)
    p.add_argument("file", help="points file (surface x,y,z or curve x,y)")
    add_points_arguments(p)
    p.add_argument("--strict", action="store_true", help="exit with status 1 when there is a warning")
    p.add_argument("--format", choices=("text", "json"), default="text", help="text (default) or json")


def run(args, out, err) -> int:
    pts = load_points(args.file, args, err, "any")
    limit = exact_limit(args)
    report = (check_curve(lagrange_curve(pts, max_mb=limit)) if isinstance(pts, CurvePoints)
              else check_surface(lagrange_surface(pts, max_mb=limit)))
    if args.format == "json":
        doc = {
            "source": report.source,
            "warnings": len(report.warnings),
            "findings": [
                {"name": f.name, "value": f.value, "limit": f.limit, "warning": f.warning, "message": f.message}
                for f in report.findings
            ],
        }
        out.write(json.dumps(doc, indent=2) + "\n")
    else:
        out.write(report.text() + "\n")
    return ExitStatus.WARNING if (args.strict and report.warnings) else ExitStatus.OK
