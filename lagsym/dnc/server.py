"""A DNC server: ports that machines call (``lagsym dnc serve``).

Each port runs in a thread of its own and waits for the control to punch.
A punched program is saved under its program number (``O1234`` to
``1234.nc``), never over an existing file: a second ``1234.nc`` is saved as
``1234.received-2.nc``, and so on.  A short program numbered as the port's
request number (``O9999`` to upload, ``O9998`` to drip-feed) whose first
comment names a program (``(PRG=1234)`` or ``(O1234)``) is a request: after
``request_delay_s`` the server sends that program from the port's
``programs`` folder.  A fault on one port is logged and that port listens
again; the others go on.
"""

from __future__ import annotations

import re
import threading
import time
from collections.abc import Callable
from pathlib import Path

from ..errors import LagsymError
from ..io import write_text
from .blocks import parse_program
from .config import PortConfig, ServerConfig
from .receiver import receive_program
from .transfer import send_program

__all__ = ["serve", "program_number", "requested_program", "saved_name"]

_O_WORD = re.compile(r"^\s*[O:]\s*0*(\d+)")
_REQUEST = re.compile(r"\(\s*(?:PRG\s*=\s*|O)\s*0*(\d+)\s*\)", re.IGNORECASE)
_RETRY_S = 1.0


def program_number(text: str) -> int | None:
    """The program number of the first block that has one (``O1234`` or ``:1234``), or None.

    Examples
    --------
    >>> program_number("%\\nO0123 (PART)\\nG21\\n")
    123
    """
    for line in text.splitlines():
        m = _O_WORD.match(line.upper())
        if m:
            return int(m.group(1))
    return None


def requested_program(text: str) -> int | None:
    """The program a request names in its first comment: ``(PRG=1234)`` or ``(O1234)``.

    Examples
    --------
    >>> requested_program("%\\nO9999 (PRG=1234)\\nM30\\n%\\n"), requested_program("%\\nO9998\\n(O77)\\n%\\n")
    (1234, 77)
    """
    comment = re.search(r"\([^)]*\)", text)
    m = _REQUEST.fullmatch(comment.group(0)) if comment else None
    return int(m.group(1)) if m else None


def saved_name(folder: Path, number: int | None) -> Path:
    """Where a punched program goes: ``1234.nc``, or beside an existing one ``1234.received-2.nc``."""
    stem = str(number) if number is not None else "unnumbered"
    path = folder / f"{stem}.nc"
    k = 2
    while path.exists():
        path = folder / f"{stem}.received-{k}.nc"
        k += 1
    return path


def _find_program(folder: Path, number: int) -> Path | None:
    for name in (f"{number}.nc", f"O{number}.nc", f"{number}", f"O{number}", f"O{number:04d}.nc", f"{number}.txt"):
        if (folder / name).is_file():
            return folder / name
    return None


class _PortService:
    """One port's loop: listen, save or answer a request, log, report status."""

    def __init__(self, port: PortConfig, stop: threading.Event, log: Callable[[str], None],
                 status: Callable[[str, str], None]):
        self.port, self.stop, self.log, self.set_status = port, stop, log, status
        self.line = None

    def status(self, text: str) -> None:
        self.set_status(self.port.name, text)

    def run(self) -> None:
        from .port import Port  # serial loads when a port is served

        while not self.stop.is_set():
            try:
                if self.line is None:
                    # The port stays open between transfers: no other program can take it, and a line that
                    # hangs up when closed (a pseudo-terminal, some adapters) stays up.
                    self.line = Port(self.port.device, self.port.settings, write_timeout=None)
                self.once()
            except LagsymError as e:
                if self.stop.is_set():
                    break
                self.log(f"error: {e}")
                self.status(f"error: {e}")
                self.reopen()
                self.stop.wait(_RETRY_S)
            except Exception as e:  # one port's bug must not end the others
                self.log(f"internal error: {type(e).__name__}: {e}")
                self.reopen()
                self.stop.wait(_RETRY_S)
        self.reopen()
        self.status("stopped")

    def reopen(self) -> None:
        """Close the port after a fault; the next round opens it again."""
        if self.line is not None:
            self.line.close()
            self.line = None

    def once(self) -> None:
        self.status(f"listening on {self.port.device}")
        text = receive_program(self.port.device, self.port.settings, start_timeout_s=float("inf"),
                               log=self.log, should_stop=self.stop.is_set, line=self.line)
        number = program_number(text)
        if number is not None and number in (self.port.request_upload, self.port.request_drip):
            mode = "upload" if number == self.port.request_upload else "drip"
            self.answer(requested_program(text), mode)
            return
        self.port.received.mkdir(parents=True, exist_ok=True)
        path = saved_name(self.port.received, number)
        write_text(path, text)
        note = "" if path.name == f"{number}.nc" else f" (a {number}.nc was there already; kept)"
        self.log(f"received O{number}: {len(text)} bytes saved as {path.name}{note}")
        self.status(f"received O{number} as {path.name}")

    def answer(self, wanted: int | None, mode: str) -> None:
        if wanted is None:
            self.log(f"request for {mode} names no program (give (PRG=1234) as its first comment); nothing sent")
            self.status("request without a program; nothing sent")
            return
        path = _find_program(self.port.programs, wanted)
        if path is None:
            self.log(f"request for {mode} of O{wanted}: no such program in {self.port.programs}; nothing sent")
            self.status(f"O{wanted} not found; nothing sent")
            return
        self.log(f"request for {mode} of O{wanted} ({path.name}); sending in {self.port.request_delay_s:g} s")
        self.status(f"sending O{wanted} ({mode}) in {self.port.request_delay_s:g} s")
        if self.stop.wait(self.port.request_delay_s):
            return
        program = parse_program(path.read_text(encoding="ascii", errors="replace"), str(path))

        def progress(_p) -> None:
            if self.stop.is_set():
                raise KeyboardInterrupt  # a stopping service ends the send as Ctrl-C does, with the resume block

        result = send_program(self.port.device, program, self.port.settings, mode, progress=progress, log=self.log,
                              line=self.line)
        self.log(f"sent O{wanted} ({mode}): {result.blocks} blocks, {result.bytes} bytes in {result.elapsed_s:.1f} s")
        self.status(f"sent O{wanted} ({mode})")


def serve(config: ServerConfig, stop: threading.Event, log_for: Callable[[PortConfig], Callable[[str], None]],
          status: Callable[[str, str], None]) -> None:
    """Serve every port of ``config`` until ``stop`` is set, then return within about a second.

    ``log_for(port)`` gives the function that logs a line for that port;
    ``status(name, text)`` is called whenever a port's status changes.
    """
    threads = []
    for port in config.ports:
        service = _PortService(port, stop, log_for(port), status)
        t = threading.Thread(target=service.run, name=f"dnc {port.name}", daemon=True)
        t.start()
        threads.append(t)
    try:
        while not stop.is_set() and any(t.is_alive() for t in threads):
            stop.wait(0.2)
    finally:  # also on SIGTERM, which arrives here as Terminated
        stop.set()
        deadline = time.monotonic() + 1.5
        for t in threads:
            t.join(max(0.0, deadline - time.monotonic()))
