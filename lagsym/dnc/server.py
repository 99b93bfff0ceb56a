"""A DNC server: ports that machines call (``lagsym dnc serve``).

Each port runs in a thread of its own and waits for the control to punch;
a port does one thing at a time, so a never-ending punch occupies only its
own port.  A punched program is saved under its program number (``O1234``
to ``1234.nc``), never over an existing file: a second ``1234.nc`` is saved
as ``1234.received-2.nc``, and so on, each name taken by one exclusive
create (:mod:`lagsym.dnc.store`), so ports sharing a folder never collide.
Several programs in one ``%`` frame (a punch-all) are saved one file each;
punches back to back are all kept (what arrives after one program's end
waits for the next).  Every byte of a punch goes to disk as it arrives, into
the ``failed`` folder under the port's ``received`` folder; a program that
arrives whole is saved and that file removed, and a punch that fails (a lost
line, garbage, no closing ``%``, longer than ``max_punch_bytes``, the server
stopping) keeps it, with a ``.reason`` file beside it.

A short program numbered as the port's request number (``O9999`` to upload,
``O9998`` to drip-feed) that holds nothing but its number, a first comment
naming a program (``(PRG=1234)`` or ``(O1234)``) and an end (``M30``,
``M02``, ``M99``) is a request: after ``request_delay_s`` the server sends
that program from the port's ``programs`` folder (never through a symbolic
link).  A program with blocks of its own is saved, whatever its number.  A
fault on one port is logged and that port listens again; the others go on.
"""

from __future__ import annotations

import os
import re
import threading
import time
from collections.abc import Callable
from pathlib import Path

from ..errors import InputError, LagsymError
from ..probe.results import is_probe_results, read_results
from .blocks import parse_program
from .config import PortConfig, ServerConfig
from .receiver import Inbox, ReceiveFault, receive_program
from .results import LineFault
from .store import create_exclusive, read_no_link, save_beside
from .transfer import send_program

__all__ = ["serve", "program_number", "requested_program", "saved_name", "split_programs", "is_request"]

_O_WORD = re.compile(r"^\s*[O:]\s*0*(\d+)")
_REQUEST = re.compile(r"\(\s*(?:PRG\s*=\s*|O)\s*0*(\d+)\s*\)", re.IGNORECASE)
_END_BLOCK = re.compile(r"^(?:N\d+\s*)?M\s*(?:30|0?2|99)$", re.IGNORECASE)
_COMMENT = re.compile(r"\([^)]*\)")
# Controls number programs with 4 to 8 digits; a longer "number" is no program number (and no file name).
_MAX_DIGITS = 9
_RETRY_S = 1.0
_NOT_TEXT = bytes(range(33)) + b"\x7f"  # control codes, blank and DEL: no program character
_DRAIN_IDLE_S = 1.0  # a punch cut off at max_punch_bytes without its end ends when the line is this quiet


def program_number(text: str) -> int | None:
    """The program number of the first block that has one (``O1234`` or ``:1234``), or None.

    Examples
    --------
    >>> program_number("%\\nO0123 (PART)\\nG21\\n")
    123
    """
    digits = _number_digits(text)
    return int(digits) if digits is not None and len(digits) <= _MAX_DIGITS else None


def _number_digits(text: str) -> str | None:
    for line in text.splitlines():
        m = _O_WORD.match(line.upper())
        if m:
            return m.group(1) or "0"
    return None


def split_programs(text: str) -> list[str]:
    """The programs of a punch: one, or each of a punch-all (several O-numbers in one ``%`` frame).

    Examples
    --------
    >>> split_programs("%\\nO1\\nM30\\nO2\\nM99\\n%\\n")
    ['%\\nO1\\nM30\\n%\\n', '%\\nO2\\nM99\\n%\\n']
    """
    lines = text.splitlines()
    framed = bool(lines) and lines[0] == "%" and lines[-1] == "%"
    body = lines[1:-1] if framed else lines
    starts = [i for i, line in enumerate(body) if _O_WORD.match(line.upper())]
    if len(starts) < 2:
        return [text]
    starts[0] = 0  # what comes before the first O-number belongs to the first program
    parts = [body[a:b] for a, b in zip(starts, starts[1:] + [len(body)])]
    return ["\n".join((["%"] if framed else []) + part + (["%"] if framed else [])) + "\n" for part in parts]


def is_request(text: str) -> bool:
    """Whether a program holds nothing but its number, comments and an end: a request, not a program to keep."""
    lines = [line.strip() for line in text.splitlines() if line.strip() not in ("", "%")]
    for line in lines[1:]:
        rest = _COMMENT.sub("", line).strip()
        if rest and not _END_BLOCK.match(rest):
            return False
    return True


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


def saved_name(folder: Path, number: int | None, text: str) -> Path:
    """Save a punched program: as ``1234.nc``, or beside a name already taken as ``1234.received-2.nc``."""
    stem = str(number) if number is not None else "unnumbered"
    return save_beside(folder, stem, ".nc", text.encode("ascii"))


def _find_program(folder: Path, number: int) -> Path | None:
    for name in (f"{number}.nc", f"O{number}.nc", f"{number}", f"O{number}", f"O{number:04d}.nc", f"{number}.txt"):
        if os.path.lexists(folder / name):
            return folder / name
    return None


class _Spool:
    """A punch on its way to disk: every byte in ``failed/PORT-TIME.punch``, removed once the program is saved."""

    def __init__(self, folder: Path, port: str):
        self.folder, self.port = folder, re.sub(r"[^A-Za-z0-9_.-]", "_", port)
        self.path: Path | None = None
        self.fd: int | None = None
        self.size = 0
        self.error: str | None = None  # the disk refused: the punch is still received, in memory
        self.text = False  # whether anything but leader, line ends and control codes arrived

    def write(self, chunk: bytes) -> None:
        self.text = self.text or bool(chunk.translate(None, _NOT_TEXT))
        if self.error is not None:
            return
        try:
            self._write(chunk)
        except OSError as e:
            self.error = e.strerror or str(e)
            if self.fd is not None:
                os.close(self.fd)
                self.fd = None

    def _write(self, chunk: bytes) -> None:
        if self.fd is None:
            self.folder.mkdir(parents=True, exist_ok=True)
            stamp = time.strftime("%Y%m%d-%H%M%S")
            for k in range(1, 100_000):
                path = self.folder / (f"{self.port}-{stamp}.punch" if k == 1 else f"{self.port}-{stamp}-{k}.punch")
                try:
                    self.fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0),
                                      0o644)
                except FileExistsError:
                    continue
                self.path = path
                break
        view = memoryview(chunk)
        while view:
            view = view[os.write(self.fd, view):]
        self.size += len(chunk)

    def close(self) -> None:
        if self.fd is not None:
            try:
                os.fsync(self.fd)
            finally:
                os.close(self.fd)
                self.fd = None

    def discard(self) -> None:
        self.close()
        if self.path is not None:
            self.path.unlink(missing_ok=True)

    def keep(self, reason: str) -> Path | None:
        if not self.text:  # the line end and DC4 after a program, a leader: no punch to keep
            self.discard()
            return None
        self.close()
        if self.path is None or self.error is not None:
            return None
        try:
            create_exclusive(self.path.with_suffix(".reason"), (reason + "\n").encode("utf-8", errors="replace"))
        except OSError:
            pass  # the bytes are kept; the log line still gives the reason
        return self.path


class _PortService:
    """One port's loop: listen, save or answer a request, log, report status."""

    def __init__(self, port: PortConfig, stop: threading.Event, log: Callable[[str], None],
                 status: Callable[[str, str], None]):
        self.port, self.stop, self.log, self.set_status = port, stop, log, status
        self.line = None
        self.inbox = Inbox()  # what arrived after one program's end, for the next

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
        if self.inbox.pending:  # bytes read before the fault: kept, since no program will take them now
            spool = _Spool(self.port.received / "failed", self.port.name)
            spool.write(bytes(self.inbox.pending))
            self.inbox.pending.clear()
            kept = spool.keep("the port was closed after a fault with these bytes not yet part of a program")
            self.log(f"failed punch: {spool.size} bytes left after a fault kept in failed/{kept.name}")

    def once(self) -> None:
        self.status(f"listening on {self.port.device}")
        spool = _Spool(self.port.received / "failed", self.port.name)
        try:
            text = receive_program(self.port.device, self.port.settings, start_timeout_s=float("inf"),
                                   log=self.log, should_stop=self.stop.is_set, line=self.line, inbox=self.inbox,
                                   sink=spool.write, max_bytes=self.port.max_punch_bytes)
        except ReceiveFault as e:
            reason = e.reason
            if e.too_long:  # the rest of the runaway punch is not kept, nor taken for programs of its own
                reason += f"; the {self.drain()} bytes after the limit were discarded"
            kept = spool.keep(reason)
            where = f"kept in failed/{kept.name} with its reason" if kept else "nothing had arrived"
            if spool.error is not None:
                where = f"it could not be kept ({spool.error})"
            self.log(f"failed punch after {len(e.wire)} bytes: {reason}; {where}")
            self.status(f"failed punch ({reason}); {where}")
            if e.line_lost or self.stop.is_set():
                raise
            return  # the line itself is fine: listen again on the open port
        except BaseException as e:
            spool.keep(f"the receive ended without a program ({type(e).__name__}: {e})")
            raise
        if is_probe_results(text):
            self.save_results(text, spool)
            return
        programs = split_programs(text)
        number = program_number(programs[0])
        requests = (self.port.request_upload, self.port.request_drip)
        if len(programs) == 1 and number is not None and number in requests and is_request(text):
            spool.discard()
            mode = "upload" if number == self.port.request_upload else "drip"
            self.answer(requested_program(text), mode)
            return
        try:
            for program in programs:
                self.save(program)
        except LagsymError as e:
            spool.keep(f"could not be saved: {e}")
            raise
        spool.discard()

    def drain(self) -> int:
        """Read and drop the rest of a punch cut off at its limit, up to its end; how many bytes.

        The end is the DC4 or ETX after it, or its closing ``%`` (what follows is kept for the next punch), or
        failing those a quiet line for :data:`_DRAIN_IDLE_S`.
        """
        ends = {0x14, 0x03} | ({ord("%")} if self.port.settings.percent else set())
        mask = 0x7F if self.port.settings.bytesize == 7 else 0xFF
        count = 0
        quiet_since = time.monotonic()
        while not self.stop.is_set() and time.monotonic() - quiet_since < _DRAIN_IDLE_S:
            if self.inbox.pending:
                chunk = bytes(self.inbox.pending)
                self.inbox.pending.clear()
            else:
                chunk = self.line.read(4096)
            if not chunk:
                self.stop.wait(0.01)
                continue
            quiet_since = time.monotonic()
            end = next((i for i, byte in enumerate(chunk) if byte & mask in ends), None)
            if end is not None:
                self.inbox.pending[:0] = chunk[end + 1:]
                return count + end + 1
            count += len(chunk)
        return count

    def save_results(self, text: str, spool) -> None:
        """Keep a probing program's results (its DPRNT output) as ``probe-results.txt``, checked whole first;
        results with a node missing or a line cut are kept in ``failed/`` with the reason, as a failed punch."""
        try:
            results = read_results(text, self.port.device)
        except InputError as e:
            kept = spool.keep(f"probe results refused: {e}")
            self.log(f"failed probe results: {e}; kept in failed/{kept.name if kept else '?'}")
            self.status(f"failed probe results ({e})")
            return
        self.port.received.mkdir(parents=True, exist_ok=True)
        path = save_beside(self.port.received, "probe-results", ".txt", text.encode("ascii"))
        spool.discard()
        self.log(f"received probe results: {len(results.points)} nodes, tip radius {float(results.tip_radius):g} "
                 f"{results.units}, saved as {path.name}")
        self.status(f"received probe results as {path.name}")

    def save(self, text: str) -> None:
        """Save one program under its number; one log line saying where."""
        self.port.received.mkdir(parents=True, exist_ok=True)
        number = program_number(text)
        digits = _number_digits(text)
        path = saved_name(self.port.received, number, text)
        name = f"O{number}" if number is not None else "a program without a program number"
        if number is None and digits is not None:
            name = f"a program whose O-number has {len(digits)} digits (no control's program number)"
        wanted = f"{number}.nc" if number is not None else "unnumbered.nc"
        note = "" if path.name == wanted else f" ({wanted} was there already; kept)"
        blocks = sum(1 for line in text.splitlines() if line.strip() not in ("", "%"))
        self.log(f"received {name}: {blocks} blocks, {len(text)} bytes saved as {path.name}{note}")
        self.status(f"received {name} as {path.name}")

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
        try:
            source = read_no_link(path)
        except LagsymError as e:
            self.log(f"request for {mode} of O{wanted}: {e}; nothing sent")
            self.status(f"O{wanted} refused; nothing sent")
            return
        self.log(f"request for {mode} of O{wanted} ({path.name}); sending in {self.port.request_delay_s:g} s")
        self.status(f"sending O{wanted} ({mode}) in {self.port.request_delay_s:g} s")
        if self.stop.wait(self.port.request_delay_s):
            return
        program = parse_program(source, str(path))

        def progress(_p) -> None:
            if self.stop.is_set():
                raise KeyboardInterrupt  # a stopping service ends the send as Ctrl-C does, with the resume block

        try:
            result = send_program(self.port.device, program, self.port.settings, mode, progress=progress,
                                  log=self.log, line=self.line, stray=self.inbox.pending.extend)
        except LineFault as e:
            if not self.inbox.pending:
                raise
            # The control sent text during the send: a punch begun, kept for the receive that comes next.
            self.log(f"send of O{wanted} ({mode}) stopped: {e}; the control is punching, {len(self.inbox.pending)} "
                     "bytes kept for it")
            self.status(f"send of O{wanted} stopped: the control is punching")
            return
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
