"""``lagsym receive --port PORT -o FILE``: take a program the control punches out."""

from __future__ import annotations

import os

from ..dnc import receive_program
from ..errors import InputError
from ..io import check_output, event_log
from ._common import emit, number
from .send import add_line_arguments, check_log, line_settings

MAX_WAIT_S = 86_400.0  # a day: the longest --timeout or --idle-timeout
SECONDS = number(0.0, MAX_WAIT_S, "s", above=True)

DESCRIPTION = """Wait for a program from a CNC control (PUNCH or OUTPUT on the control) and
write it to FILE, or to standard output.  The program runs from DC2 (or its
first character) to DC4, its closing %, ETX, or a silence of --idle-timeout
seconds; leader and control codes are dropped and blocks end in LF.  The
file is written only when the whole program has arrived, and an existing
file only with --overwrite.  Once the port is open it says so: then press
PUNCH.  Exit status 3 on a line fault, a busy port, a timeout, a program
without its closing %, garbage (a baud rate or parity that does not match
the control's), Ctrl-C, SIGTERM or SIGHUP.

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
    if to_file and os.path.exists(args.output) and not args.overwrite:
        raise InputError(f"{args.output} exists; give another -o FILE, or --overwrite to replace it")
    if to_file:
        check_output(args.output)  # before the control punches: a program that cannot be saved would be lost
    settings = line_settings(args)

    def ready() -> None:
        if not args.quiet:
            err.write(f"waiting on {args.port} for {args.timeout:g} s: start the output (PUNCH) on the control now\n")
            err.flush()

    with event_log(args.log) as log:
        text = receive_program(args.port, settings, start_timeout_s=args.timeout, idle_timeout_s=args.idle_timeout,
                               log=log, ready=ready)
    emit(text, args.output, out)
    check_log(log, f"received {text.count(chr(10))} lines into {args.output if to_file else 'standard output'}")
    if not args.quiet and to_file:
        err.write(f"received {text.count(chr(10))} lines ({len(text)} bytes) into {args.output}\n")
    return 0
