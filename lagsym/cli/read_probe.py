"""``lagsym read-probe RESULTS -o points.json``: a probing program's output read into surface points."""

from __future__ import annotations

from ..io import read_text
from ..probe import points_json, read_results, surface_points
from ._common import add_file_points_limit, emit

DESCRIPTION = """Read the text a 'lagsym probe' program sent back -- Fanuc/Haas DPRNT
output received over the serial line, or LinuxCNC's log file -- check that
every node is there, take the probe's tip radius off, and write a points
file (JSON: units, the points, and a "probe" record of the file it came
from, its SHA-256, the tip radius and the compensation) that 'lagsym fit'
reads.  'lagsym fit' also reads the results file directly.

The positions are those of the tip's centre.  The tip radius is taken off
along the normal of a least-squares fit of the centres (the contact points,
exact but for that fit's slope), and each contact's height is carried back
to its node along a fit of the contacts, so the points keep the probed grid
(--degree for both fits; by default chosen by cross-validation).  The
estimated error of that step is reported.

A node missing or given twice, a line cut mid-way, or results that stop
without their END line (the control raised an alarm, or the line was cut)
are refused with one line naming the node (exit status 2); nothing is written.

examples:
  lagsym read-probe examples/probe-results.txt -o probed-points.json
  lagsym fit probed-points.json -o probed-surface.json"""


def add_arguments(p) -> None:
    p.add_argument("results", help="the probing program's output (DPRNT text or a LinuxCNC log)")
    p.add_argument("--degree", default="auto", metavar="P[xQ]",
                   help="the degree of the fit whose normals take the tip radius off (default auto)")
    p.add_argument("-o", "--output", metavar="FILE", help="write the points file here instead of standard output")
    add_file_points_limit(p)


def run(args, out, err) -> int:
    name, text = read_text(args.results)
    results = read_results(text, name)
    sp = surface_points(results, None if args.degree == "auto" else args.degree)
    emit(points_json(sp), args.output, out)
    report = out if args.output and args.output != "-" else err
    report.write(f"{name}: {len(sp.points)} nodes, {sp.describe()}\n")
    return 0
