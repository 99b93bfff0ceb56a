"""``lagsym dnc serve CONFIG.toml``: a DNC server, ports that machines call to punch and to ask for programs."""

from __future__ import annotations

import contextlib
import signal
import threading
import time

from ..dnc.config import load_config
from ..dnc.server import serve
from ..errors import Terminated
from ..io import event_log
from ._lines import say

DESCRIPTION = """Serve one or more serial ports as a shop's DNC service, as configured in a
TOML file (see docs/dnc.md): a program punched from a control is saved under
its program number (O1234 as 1234.nc; an existing file is kept and the new
one saved beside it as 1234.received-2.nc, each name taken by an exclusive
create), each program of a punch-all in a file of its own; a punch that
fails is kept byte for byte in the received folder's failed/ with a .reason
file.  A short program numbered as the port's request number (O9999 to
upload, O9998 to drip-feed) holding only a first comment that names a
program, (PRG=1234) or (O1234), and an end, has that program sent back
after request_delay_s.  Each port has its own log; a status line per port
goes to standard output.  A fault on one port never stops the others.
SIGTERM, SIGHUP or Ctrl-C stops the server within 2 s.  --check reads and
checks the configuration and exits.

examples:
  lagsym dnc serve examples/dnc.toml --check"""


def add_arguments(p) -> None:
    sub = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    s = sub.add_parser("serve", help="serve the ports of CONFIG until stopped")
    s.add_argument("config", metavar="CONFIG", help="the TOML configuration")
    s.add_argument("--check", action="store_true", help="check the configuration and exit")


def run(args, out, err) -> int:
    config = load_config(args.config)
    if args.check:
        for port in config.ports:
            say(out, f"{port.name}: {port.device}, {port.settings.baud} baud, programs from {port.programs}, "
                     f"punched programs to {port.received}, log {port.log}")
        return 0
    lock = threading.Lock()

    def status(name: str, text: str) -> None:
        with lock:
            say(out, f"{time.strftime('%H:%M:%S')} {name}: {text}")
            out.flush()

    stop = threading.Event()
    with contextlib.ExitStack() as stack:
        logs = {p.name: stack.enter_context(event_log(p.log, f"{p.name}: log", _lost(status, p))) for p in config.ports}
        try:
            serve(config, stop, lambda p: logs[p.name], status)
        except KeyboardInterrupt as e:
            why = signal.Signals(e.signum).name if isinstance(e, Terminated) else "Ctrl-C"
            status("server", f"stopped by {why}")
    return 0


def _lost(status, port):
    """What the server says, once, when a port's log can no longer be written."""
    return lambda why: status(port.name, f"the log {port.log} can no longer be written ({why}); events go unrecorded")
