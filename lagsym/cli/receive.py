"""``lagsym receive --port PORT -o FILE``: take a program the control punches out."""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

from ..dnc import receive_program
from ..dnc.store import create_exclusive, save_beside
from ..errors import InputError, OutputError
from ..io import check_output, event_log, write_text
from ..probe.results import is_probe_results, read_results
from ._common import number
from ._lines import say
from .send import add_line_arguments, check_log, line_settings

MAX_WAIT_S = 86_400.0  # a day: the longest --timeout or --idle-timeout
SECONDS = number(0.0, MAX_WAIT_S, "s", above=True)

DESCRIPTION = """Wait for a program from a CNC control (PUNCH or OUTPUT on the control) and
write it to FILE, or to standard output.  The program runs from DC2 (or its
first character) to DC4, its closing %, ETX, or a silence of --idle-timeout
seconds; leader and control codes are dropped and blocks end in LF.  The
file is created only when the whole program has arrived, exclusively and
never through a symbolic link: a FILE that appeared meanwhile is kept and
the program saved beside it (FILE.received-2.nc, exit 2); an existing file
is replaced only with --overwrite.  Once the port is open it says so: then
press PUNCH; on a terminal, characters, blocks and rate show as they
arrive.  Exit status 3 on a line fault, a busy port, a timeout, a program
without its closing %, garbage (check the baud rate and format: they must
match the control's), Ctrl-C, SIGTERM or SIGHUP.

The output of a 'lagsym probe' program (POPEN, DPRNT lines, PCLOS) is taken
by its header line as probe results, without % around it: every node is
checked as 'lagsym read-probe' checks it before the file is written, and
results with a node missing or a line cut (the control stopped, or the line
did) are refused in one line naming the node, exit status 2, nothing written.

examples:
  lagsym receive --port /dev/ttyUSB0 --profile fanuc -o from-control.nc
  lagsym receive --port socket://dnc-gateway.shop.lan:4001 --profile haas --timeout 300 -o O2000.nc"""


def add_arguments(p) -> None:
    add_line_arguments(p)
    p.add_argument("-o", "--output", metavar="FILE", help="write the program to FILE instead of standard output")
    p.add_argument("--overwrite", action="store_true", help="replace FILE if it exists (default: refuse)")
    p.add_argument("--timeout", type=SECONDS, default=60.0, metavar="SECONDS",
                   help="how long to wait for the control to start, above 0 up to 86400 (default 60)")
    p.add_argument("--idle-timeout", type=SECONDS, default=5.0, metavar="SECONDS",
                   help="silence that ends a program without DC4 or closing %%, above 0 up to 86400 (default 5)")


def run(args, out, err) -> int:
    to_file = args.output and args.output != "-"
    if to_file and os.path.lexists(args.output) and not args.overwrite:
        raise InputError(f"{args.output} exists; give another -o FILE, or --overwrite to replace it")
    if to_file:
        check_output(args.output)  # before the control punches: a program that cannot be saved would be lost
    settings = line_settings(args)

    def ready() -> None:
        if not args.quiet:
            say(err, f"waiting on {args.port} for {args.timeout:g} s: start the output (PUNCH) on the control now")
            err.flush()

    with event_log(args.log) as log, progress_bar(err, args.quiet) as bar:
        text = receive_program(args.port, settings, start_timeout_s=args.timeout, idle_timeout_s=args.idle_timeout,
                               log=log, ready=ready, progress=bar)
    results = read_results(text, args.port) if is_probe_results(text) else None  # checked whole before saving
    if to_file:
        save(text, args.output, args.overwrite)
    else:
        out.write(text)
    check_log(log, f"received {text.count(chr(10))} lines into {args.output if to_file else 'standard output'}")
    if not args.quiet and to_file:
        say(err, f"received {text.count(chr(10))} lines ({len(text)} bytes) into {args.output}")
    if results is not None and not args.quiet:
        err.write(f"probe results: {len(results.points)} nodes, tip radius {float(results.tip_radius):g} "
                  f"{results.units}, every node there: read them with lagsym read-probe\n")
    return 0


def save(text: str, output: str, overwrite: bool) -> None:
    """Create ``output`` (replace it with ``overwrite``); a file that appeared meanwhile is kept, never replaced."""
    if overwrite:
        write_text(output, text)
        return
    try:
        if create_exclusive(Path(output), text.encode("ascii")):
            return
    except OSError as e:
        raise OutputError(f"cannot write {output}: {e.strerror or e}") from None
    path = Path(output)
    other = save_beside(path.parent, path.stem, path.suffix, text.encode("ascii"))
    raise OutputError(f"{output} appeared while lagsym waited and was kept; the program is saved as {other} "
                      "instead")


@contextlib.contextmanager
def progress_bar(err, quiet: bool):
    """Characters, blocks and rate of the arriving program on ``err`` (a terminal only), as ``send`` shows them."""
    if quiet:
        yield None
        return
    from rich.console import Console
    from rich.progress import Progress, SpinnerColumn, TextColumn

    console = Console(file=err, stderr=True)
    columns = (SpinnerColumn(), TextColumn("{task.description}"), TextColumn("{task.fields[state]}"))
    with Progress(*columns, console=console, transient=False, disable=not console.is_terminal) as bar:
        task = bar.add_task("receiving", state="waiting")

        def update(p) -> None:
            bar.update(task, state=f"{p.chars} characters, {p.blocks} blocks, {p.rate_chars_s:.0f} characters/s")

        yield update
