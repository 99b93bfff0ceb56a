"""``lagsym simulate PROGRAM``: dry-run a macro program with the control's arithmetic and alarms."""

from __future__ import annotations

from ..controls import CONTROLS, control
from ..errors import ProgramError
from ..io import read_program
from ..simulate import (BYTES_PER_MOVE, MAX_BLOCKS, MAX_IDLE_BLOCKS, MAX_PROGRAM_LINES, SIM_DIALECTS, ControlAlarm,
                        detect_dialect, moves_csv, simulate)
from ..simulate.runaway import check_lines
from ._common import add_file_points_limit, add_exact_limit, count, emit, exact
from ._lines import say
from ._progress import progress_bar

MAX_BLOCKS_LIMIT = 100_000_000  # the moves of a run this long take at most 3.7 GB

DESCRIPTION = """Execute PROGRAM (Fanuc Custom Macro B, LinuxCNC O-words or Heidenhain FN/Q,
guessed from the text unless --dialect is given) in decimal arithmetic of
--precision significant digits, rounding after every operation as the control
does, and write the moves as CSV (line,motion,x,y,z,feed).

It stops with the alarm a real control would raise: unbalanced or over-deep
DO/END, brackets nested beyond 5, a constant axis word without a decimal
point, a variable outside the allowed range, a block too long, division by
zero.  Use it to dry-run any program before it goes to a machine.

A program that would never end stops within seconds with the runaway alarm
(exit status 2, as every alarm): at once for a loop whose condition nothing in
it changes (WHILE [1 EQ 1], a GOTO back) or when the run comes back to a block
with every variable and the position unchanged, after --max-idle-blocks
blocks without a move, or after --max-blocks blocks in all.

On a terminal, a progress bar on standard error shows the blocks executed.

A probing program (Fanuc/Haas G31, LinuxCNC G38.2) runs against --surface,
a formula z = f(x, y) or a points or surface file, touched by a ball tip of
--tip-radius: each probing move stops where the tip touches, and the text
the program prints (DPRNT, or LinuxCNC's (LOG,..)) goes to --print-output,
as the control would send it.  A probing move that starts on or in the
surface (the approach went into the part) is an alarm, and so is a LinuxCNC
G38.2 that ends without contact; a Fanuc program raises its own #3000.
Without --surface a probing move is refused, as every code the simulator does
not run.

examples:
  lagsym simulate O1000.nc --precision 8 -o moves.csv
  lagsym simulate surface.ngc --precision 15
  lagsym simulate probe.nc --surface "5 + 0.03*x + 0.001*y**2" --tip-radius 1 --print-output probe-results.txt"""


def add_arguments(p) -> None:
    p.add_argument("program", help="the program file")
    add_file_points_limit(p)
    p.add_argument("--dialect", choices=SIM_DIALECTS,
                   help="the control (default: guessed from the text: fanuc, linuxcnc or heidenhain)")
    p.add_argument("--precision", type=int, choices=(8, 15),
                   help="significant digits (default the control's: " + ", ".join(
                       f"{c.macro.default_precision} for {c.name}" for c in CONTROLS.values() if c.macro) + ")")
    p.add_argument("--max-blocks", type=count(1, MAX_BLOCKS_LIMIT), default=MAX_BLOCKS, metavar="N",
                   help=f"stop after N executed blocks as a runaway loop (default {MAX_BLOCKS}; the moves take "
                        f"at most {BYTES_PER_MOVE} bytes a block, up to {MAX_BLOCKS_LIMIT})")
    p.add_argument("--max-lines", type=count(1, 10**9), default=MAX_PROGRAM_LINES, metavar="N",
                   help=f"refuse a program of more than N lines before reading it (default {MAX_PROGRAM_LINES}; "
                        f"each takes about 11 KB while read and compiled)")
    p.add_argument("--max-idle-blocks", type=count(1, MAX_BLOCKS_LIMIT), default=MAX_IDLE_BLOCKS, metavar="N",
                   help=f"stop after N blocks in a row without a move as a runaway loop (default {MAX_IDLE_BLOCKS})")
    add_exact_limit(p)
    p.add_argument("--surface", metavar="FORMULA|FILE",
                   help="what probing moves touch: a formula in x and y, or a points or surface file (named by its "
                        "extension: .json, .csv, ...)")
    p.add_argument("--tip-radius", type=exact(0, 49.999), default=0, metavar="UNITS",
                   help="the simulated probe's ball tip radius, in program units (default 0)")
    p.add_argument("--print-output", metavar="FILE",
                   help="write the text the program prints (DPRNT, LinuxCNC log) to FILE")
    p.add_argument("-o", "--output", metavar="FILE", help="write the moves CSV to FILE instead of standard output")


def run(args, out, err) -> int:
    text = read_program(args.program)
    check_lines(text, args.max_lines, args.program)  # named here: the library does not know the file
    dialect = args.dialect or detect_dialect(text)
    precision = args.precision or control(dialect).macro.default_precision
    target = _target(args.surface, args.tip_radius, args.max_exact_mb) if args.surface else None
    try:
        with progress_bar(err) as progress:
            sim = simulate(text, dialect, precision, max_blocks=args.max_blocks,
                           max_idle_blocks=args.max_idle_blocks, progress=progress, target=target,
                           max_lines=args.max_lines)
    except ControlAlarm as e:  # the library names the block; the command names the file
        raise ProgramError(f"{args.program}: {e}") from None
    if args.print_output:
        emit("\n".join(sim.output), args.print_output, out)
    emit(moves_csv(sim), args.output, out)
    feeds = sim.moves.feeds()
    say(err, f"{args.program}: {dialect}, {precision} digits: {sim.blocks} blocks executed, "
             f"{len(sim.moves)} moves ({feeds} feed), no alarm")
    if sim.probes or sim.output:
        where = f" to {args.print_output}" if args.print_output else " (give --print-output to keep them)"
        say(err, f"{sim.probes} probing moves, {len(sim.output)} lines printed{where}")
    return 0


def _target(text: str, tip_radius, max_mb: float):
    """The probe target: a points or surface file (by its extension, as 'compare --reference'), else a formula."""
    from pathlib import Path

    from ..io import TABLE_SUFFIXES
    from ..simulate.probing import probe_target

    if Path(text).suffix.lower() in (".json",) + TABLE_SUFFIXES:
        from ..evaluate import surface_evaluator
        from ..io import read_points
        from ..lagrange import lagrange_surface

        ev = surface_evaluator(lagrange_surface(read_points(text), max_mb=max_mb))
        return probe_target(lambda x, y: ev.points(x, y), float(tip_radius), text)
    from ..formula import parse_formula

    return probe_target(parse_formula(text), float(tip_radius), "surface formula")
