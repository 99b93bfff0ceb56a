"""``lagsym send FILE --port PORT``: upload or drip-feed a program to a control over RS-232."""

from __future__ import annotations

import argparse
import contextlib
from pathlib import Path

import math

from ..dnc import (
    CARRIERS,
    FLOW_CONTROLS,
    MODES,
    PARITIES,
    PROFILES,
    LineSettings,
    check_port,
    parse_filler,
    find_block,
    parse_program,
    profile,
    send_program,
)
from ..errors import InputError, LogLost
from ..io import event_log, read_program
from ..machine import LINE_ENDINGS
from ._lines import say

DESCRIPTION = """Send the program in FILE to a CNC control over a serial line, with XON/XOFF
handled by lagsym itself (paced to the line rate, at most a few characters
past the control's DC3), a progress bar of what has really left the line,
and a fault message that names the last block that surely arrived and the
--start-block that resumes a drip feed.

Block N is the N-th non-empty line after the leading % (the O-number line
is block 1).  --start-block N sends the program's modal set-up first (units,
plane, absolute mode, work offset, tool, spindle, coolant, a safe Z and the
approach to where the program was), then block N onwards.

The port is a device or a pyserial URL: /dev/ttyUSB0, COM3,
socket://host:4001, rfc2217://host:4001, loop://; a device is opened
exclusively.  Exit status 3 on a line fault, a stall, a busy port, Ctrl-C,
SIGTERM or SIGHUP; the message says which --start-block resumes.  A block
surely reached the control only when the control's answers prove it (an XOFF
after the XON that ended a pause: everything sent before that pause), or a
--carrier signal or hardware flow control watched the line; the summary and
the faults word apart what left the port and what surely arrived.  A drip feed the control never answered at all is a fault
(exit 3) unless --no-handshake-expected; so are answers no control sends
(check the baud rate and format).

examples:
  lagsym send O1000.nc --port /dev/ttyUSB0 --baud 9600 --bytesize 7 --parity even --stopbits 2 --flow xonxoff
  lagsym send big.nc --port /dev/ttyUSB0 --mode drip --profile fanuc
  lagsym send big.nc --port socket://dnc-gateway.shop.lan:4001 --mode drip --start-block 4120
  lagsym send big.nc --port /dev/ttyUSB0 --profile fanuc --mode drip --carrier dsr --start-at N4120
  lagsym send O1000.nc --port loop:// --profile fanuc --baud 115200 --quiet"""


def add_line_arguments(p) -> None:
    """The serial line options ``send`` and ``receive`` share; the defaults they print are :class:`LineSettings`'s."""
    d = LineSettings()
    p.add_argument("--port", required=True, type=port_name,
                   help="device (/dev/ttyUSB0, COM3) or pyserial URL (socket://host:port, rfc2217://host:port, "
                        "loop://)")
    g = p.add_argument_group("line settings (a --profile fills them in; any option given overrides it)")
    g.add_argument("--profile", choices=tuple(PROFILES), help="usual settings of a control family (see docs/dnc.md)")
    g.add_argument("--baud", type=int, help=f"bits per second (default {d.baud})")
    g.add_argument("--bytesize", type=int, choices=(5, 6, 7, 8), help=f"data bits (default {d.bytesize})")
    g.add_argument("--parity", choices=tuple(PARITIES), help=f"parity (default {d.parity})")
    g.add_argument("--stopbits", type=float, choices=(1, 1.5, 2), help=f"stop bits (default {d.stopbits:g})")
    g.add_argument("--flow", choices=FLOW_CONTROLS, help=f"flow control (default {d.flow})")
    g.add_argument("--eol", choices=tuple(LINE_ENDINGS), help=f"end of block (default {d.line_ending})")
    g.add_argument("--leader", metavar="SPEC", help="characters before the program: a count of NULs or e.g. 50*NUL")
    g.add_argument("--trailer", metavar="SPEC", help="characters after the program, e.g. 20, ETX or 10*NUL,ETX")
    g.add_argument("--percent", action=argparse.BooleanOptionalAction, default=None,
                   help="frame the program with %% lines (default on)")
    g.add_argument("--dtr", action=argparse.BooleanOptionalAction, default=None, help="assert DTR (default on)")
    g.add_argument("--carrier", choices=CARRIERS, help="a signal the control holds up while connected (DSR, DCD or "
                                                       "CTS): its drop is a lost line (default none)")
    g.add_argument("--tv-check", action=argparse.BooleanOptionalAction, default=None,
                   help="pad blocks to an even character count, for a control with TV check (default off)")
    g.add_argument("--iso-check", action=argparse.BooleanOptionalAction, default=None,
                   help="only ISO 840 tape code characters, in what is sent and received (default off)")
    p.add_argument("--quiet", action="store_true", help="no progress bar and no summary")
    p.add_argument("--log", metavar="FILE", help="append a line per event (XOFF, XON, faults) to FILE; a log that "
                                                 "cannot be written is refused before the port opens")


def port_name(text: str) -> str:
    """An argparse ``type=`` for ``--port``: a device, or a URL with a host, a port number 1-65535 and known options."""
    try:
        return check_port(text, "")
    except InputError as e:
        raise argparse.ArgumentTypeError(str(e).strip()) from None


def check_log(log, done: str) -> None:
    """After a transfer: a log that stopped part way means the transfer is not on record (exit 3)."""
    if log is not None and log.lost is not None:
        raise LogLost(f"{done}, but the log {log.path} was lost ({log.lost}): the transfer is not on record; "
                      "free space for the log, and check on the control what arrived")


def line_settings(args):
    """The :class:`~lagsym.dnc.LineSettings` the options ask for."""
    overrides = {}
    for option, field in (("baud", "baud"), ("bytesize", "bytesize"), ("parity", "parity"), ("stopbits", "stopbits"),
                          ("flow", "flow"), ("eol", "line_ending"), ("percent", "percent"), ("dtr", "dtr"),
                          ("carrier", "carrier"), ("tv_check", "tv_check"), ("iso_check", "iso_check"),
                          ("buffer_chars", "buffer_chars"), ("memory_chars", "memory_chars")):
        value = getattr(args, option, None)
        if value is not None:
            overrides[field] = value
    for option in ("leader", "trailer"):
        value = getattr(args, option, None)
        if value is not None:
            try:
                overrides[option] = parse_filler(value)
            except InputError as e:
                raise InputError(f"--{option} {value!r}: {e}") from None
    if getattr(args, "stall_timeout", None) is not None:
        overrides["stall_timeout_s"] = seconds_or_forever(args.stall_timeout)
    if getattr(args, "overrun_chars", None) is not None:
        overrides["overrun_chars"] = args.overrun_chars
    if getattr(args, "wait_for_xon", False):
        overrides["wait_for_xon"] = True
    if getattr(args, "realtime", False):
        overrides["realtime"] = True
    if getattr(args, "no_handshake_expected", False):
        overrides["handshake_expected"] = False
    if args.profile:
        return profile(args.profile, **overrides)
    return LineSettings(**overrides)


@contextlib.contextmanager
def progress_bar(err, quiet: bool, what: str):
    """A rich progress bar on ``err`` fed by :class:`~lagsym.dnc.TransferProgress` values, or None."""
    if quiet:
        yield None
        return
    from rich.console import Console
    from rich.progress import BarColumn, DownloadColumn, Progress, TextColumn, TimeRemainingColumn, TransferSpeedColumn

    console = Console(file=err, stderr=True)
    columns = (TextColumn("{task.description}"), BarColumn(), TextColumn("{task.fields[blocks]}"), DownloadColumn(),
               TransferSpeedColumn(), TimeRemainingColumn(), TextColumn("{task.fields[state]}"))
    with Progress(*columns, console=console, transient=False, disable=not console.is_terminal) as bar:
        task = bar.add_task(what, total=None, blocks="", state="")

        def update(p) -> None:
            bar.update(task, total=p.bytes_total, completed=p.bytes_done,
                       blocks=f"{p.blocks_done}/{p.blocks_total} blocks", state="XOFF" if p.paused else "")

        yield update


def seconds_or_forever(text: str) -> float:
    """A ``--stall-timeout``: seconds, or ``forever``."""
    if text.strip().lower() in ("forever", "inf", "none"):
        return math.inf
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"--stall-timeout {text!r} must be a number of seconds or 'forever'") from None
    if not 0 < value < math.inf:
        raise InputError(f"--stall-timeout {text!r} must be a positive number of seconds or 'forever'")
    return value


def add_arguments(p) -> None:
    p.add_argument("file", help="the program (G-code or Heidenhain text)")
    add_line_arguments(p)
    d = LineSettings()
    t = p.add_argument_group("transfer")
    t.add_argument("--mode", choices=MODES, default="upload",
                   help="upload: store in the control's memory (needed for macro programs); drip: feed while it runs")
    t.add_argument("--start-block", type=int, default=1, metavar="N",
                   help="resume a drip feed at block N, after the program's modal set-up (as a fault message says)")
    t.add_argument("--safe-z", metavar="Z", help="retract height for a resume, in program units "
                                                  "(default: the highest rapid Z before block N)")
    t.add_argument("--start-at", metavar="N-OR-TEXT",
                   help="resume at the block the control shows: its N number (N4120) or its text")
    t.add_argument("--stall-timeout", type=str, metavar="SECONDS",
                   help=f"give up when XOFF or CTS low lasts longer; 'forever' for a long M00 or feed hold "
                        f"(default {d.stall_timeout_s:g})")
    t.add_argument("--buffer-chars", type=int, metavar="N",
                   help=f"the control's drip-feed buffer, which a fault's resume block allows for "
                        f"(default {d.buffer_chars})")
    t.add_argument("--memory-chars", type=int, metavar="N",
                   help="the control's program memory: a larger upload is refused (default: not checked)")
    t.add_argument("--overrun-chars", type=int, metavar="N",
                   help=f"most characters in flight: about half what the control takes past XOFF (default "
                        f"{d.overrun_chars}; a Fanuc takes ~10; a larger N keeps a fast line busy)")
    t.add_argument("--wait-for-xon", action="store_true", help="wait for the control's DC1 before sending")
    t.add_argument("--no-handshake-expected", action="store_true",
                   help="a drip feed the control never answers with XOFF/XON is not a fault (a control that reads "
                        "faster than the line); without it such a feed ends with exit 3")
    t.add_argument("--realtime", action="store_true",
                   help="send at real-time priority (SCHED_FIFO), so a busy computer keeps a small window "
                        "busy at a high baud rate; needs root, CAP_SYS_NICE or an rtprio limit")


def run(args, out, err) -> int:
    program = parse_program(read_program(args.file), source=args.file)
    settings = line_settings(args)
    start = args.start_block
    if args.start_at is not None:
        if start != 1:
            raise InputError("give --start-block or --start-at, not both")
        start = find_block(program, args.start_at)
    with event_log(args.log) as log, progress_bar(err, args.quiet, f"{args.mode} {Path(args.file).name}") as bar:
        result = send_program(args.port, program, settings, mode=args.mode, start_block=start,
                              safe_z=args.safe_z, progress=bar, log=log)
    check_log(log, f"sent {result.blocks} blocks to {args.port}")
    if not args.quiet:
        say(out, f"sent {result.blocks} blocks ({result.bytes} bytes) to {args.port} in {result.elapsed_s:.1f} s, "
                 f"{100 * result.throughput:.1f}% of the line rate, {result.xoff_count} XOFF")
        if not result.confirmed and result.sure_to_end:
            out.write(f"the control answered XON/XOFF {result.answers} times, which show that it took every block\n")
        elif not result.confirmed and result.answers:
            sure = (f"block {result.last_sure_block} surely reached it" if result.last_sure_block
                    else "no block surely reached it (only an XOFF after an XON shows what it took)")
            out.write(f"the control answered XON/XOFF {result.answers} times, which show that {sure}; the blocks "
                      "after it left the port but nothing shows that the control holds them: check that it holds "
                      "the last block (a --carrier signal watches the line)\n")
        elif not result.confirmed:
            out.write("the control confirmed nothing: it never answered XON/XOFF, so nothing shows it took the "
                      "program; check it holds the last block (a --carrier signal watches the line)\n")
    return 0
