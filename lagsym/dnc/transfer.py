"""RS-232 transfer to and from a CNC control: upload, drip feed and receive.

The sender does its own XON/XOFF: it paces writes to the line rate
(characters per second = baud / bits per character), keeps at most
``LineSettings.overrun_chars`` characters on their way at any moment, and
reads the line for DC3 (XOFF) and DC1 (XON) before every write.  The kernel's
IXON is left off on purpose: it would swallow DC3 before lagsym could see it,
and many USB adapters keep sending after it anyway.  A Fanuc accepts only
about 10 characters past DC3 before alarm 087, so the default keeps 4 or
fewer in flight, which leaves room for the DC3 to travel back.

A block counts as *delivered* once all its bytes have had time to leave the
line (by the line clock and the driver's output queue), a short settling
time has passed, and a later look at the port found it still healthy.  A
fault names the last delivered block and the ``--start-block`` that resumes
the drip feed after it; a cut in mid-transfer also names the blocks that
were on their way and may have arrived too.

Nothing here imports serial: :func:`send_program` and
:func:`receive_program` open the line through :mod:`lagsym.dnc.port` when
they are called, so the settings, the framing and :func:`transfer_segments`
work where pyserial is not loaded.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..errors import InputError, TransferError
from ..values import choice
from .blocks import DC1, DC2, DC3, DC4, Program, frame
from .resume import resume_setup
from .settings import MODES, LineSettings

if TYPE_CHECKING:
    from .port import Port

__all__ = ["TransferProgress", "TransferResult", "LineFault", "transfer_segments", "send_program", "receive_program"]

_POLL_S = 0.002  # longest sleep between looks at the port while the line is busy
_PROGRESS_S = 0.1
# A byte counts as arrived only this long after the line clock says it left: longer through a network
# serial server, which holds what it has not yet put on its line.
_SETTLE_S = 0.05
_SETTLE_NETWORK_S = 0.25


@dataclass(frozen=True)
class TransferProgress:
    """Where a transfer stands; ``bytes_done`` counts bytes that have left the line, not bytes queued."""

    blocks_done: int
    blocks_total: int
    bytes_done: int
    bytes_total: int
    elapsed_s: float
    paused: bool

    @property
    def rate_bytes_s(self) -> float:
        """Mean rate so far."""
        return self.bytes_done / self.elapsed_s if self.elapsed_s > 0 else 0.0

    @property
    def remaining_s(self) -> float | None:
        """Time left at the mean rate so far, or None before there is a rate."""
        rate = self.rate_bytes_s
        return (self.bytes_total - self.bytes_done) / rate if rate > 0 else None


@dataclass(frozen=True)
class TransferResult:
    """A finished transfer: what went, how long it took, how often the control said XOFF."""

    blocks: int
    bytes: int
    elapsed_s: float
    xoff_count: int
    max_in_flight_at_xoff: int
    chars_per_s: float

    @property
    def throughput(self) -> float:
        """Bytes per second over the line rate (1.0: the line never idled)."""
        return self.bytes / self.elapsed_s / self.chars_per_s if self.elapsed_s > 0 else 0.0


class LineFault(TransferError):
    """A stall or a lost line during a send; says which block surely arrived and how to resume.

    Attributes
    ----------
    last_block : int
        The last program block that surely reached the control (0: none).
    start_block : int or None
        The ``--start-block`` that resumes a drip feed, or None for an upload
        (which must be sent again whole).
    last_sent_block : int
        The last block written whole: blocks after ``last_block`` up to this
        one were on their way and may have arrived too.
    """

    def __init__(self, message: str, last_block: int, start_block: int | None, last_sent_block: int | None = None):
        super().__init__(message)
        self.last_block = last_block
        self.start_block = start_block
        self.last_sent_block = last_block if last_sent_block is None else last_sent_block


def transfer_segments(program: Program, settings: LineSettings, mode: str = "upload", start_block: int = 1,
                      safe_z: str | None = None) -> list[tuple[int | None, bytes]]:
    """The exact bytes a send puts on the line, as ``(block number or None, bytes)`` segments.

    With ``start_block`` above 1 (drip only) the modal set-up from
    :func:`lagsym.dnc.resume_setup` goes first, then block ``start_block``
    onwards.

    Examples
    --------
    >>> from lagsym.dnc import parse_program
    >>> p = parse_program("O1\\nM30")
    >>> b"".join(b for _, b in transfer_segments(p, LineSettings(line_ending="crlf")))
    b'%\\r\\nO1\\r\\nM30\\r\\n%\\r\\n'
    """
    choice(mode, MODES, "mode")
    if not isinstance(start_block, int) or start_block < 1:
        raise InputError(f"--start-block {start_block!r} must be a block number from 1")
    blocks: list[tuple[int | None, str]] = []
    if start_block > 1:
        if mode != "drip":
            raise InputError("--start-block resumes a drip feed; an upload stores the whole program, so send it whole")
        blocks.extend((None, b) for b in resume_setup(program, start_block, safe_z))
    elif safe_z is not None:
        raise InputError("--safe-z only applies with --start-block above 1")
    blocks.extend((n, program.block(n)) for n in range(start_block, len(program) + 1))
    return frame(blocks, settings.eol, settings.percent, settings.leader, settings.trailer)


class _Sender:
    """One send over an open port: pacing, flow control, accounting.  Not reused."""

    def __init__(self, line: Port, segments, settings: LineSettings, mode: str, port: str,
                 progress: Callable[[TransferProgress], None] | None, log: Callable[[str], None] | None):
        self.line, self.settings, self.mode, self.port = line, settings, mode, port
        self.progress, self.log = progress, log or (lambda _m: None)
        self.data = b"".join(b for _, b in segments)
        self.ends: list[tuple[int, int]] = []  # (end offset, block number) of program blocks
        self.segment_ends: list[int] = []
        offset = 0
        for number, chunk in segments:
            offset += len(chunk)
            self.segment_ends.append(offset)
            if number is not None:
                self.ends.append((offset, number))
        self.blocks_total = len(self.ends)
        self.first_block = self.ends[0][1] if self.ends else 1
        self.cps = settings.chars_per_s
        network = "://" in port and not port.startswith("loop://")
        self.settle_s = _SETTLE_NETWORK_S if network else _SETTLE_S
        self.pos = 0  # bytes written to the port
        self.sure = 0  # bytes surely on the control's side
        self.line_free = 0.0  # when the last written byte will have left the line
        self.paused = settings.wait_for_xon
        self.pause_since = 0.0
        self.pause_reason = "the control sent no DC1 (XON) to start the transfer within {t} s"
        self.xoffs = 0
        self.max_in_flight = 0
        self.queue_stuck_since: float | None = None
        self.last_queue = 0

    def in_flight(self, now: float) -> int:
        """Bytes written but not yet gone from the line, by the line clock and the driver's queue."""
        clock = max(0.0, (self.line_free - now) * self.cps)
        return max(math.ceil(clock), self.line.out_waiting())

    def unsettled(self, now: float) -> int:
        """Bytes that may not have reached the far side yet: in flight, or left less than the settling time ago."""
        return max(self.in_flight(now), self.in_flight(now - self.settle_s))

    def blocks_surely_done(self) -> int:
        done = 0
        for end, _number in self.ends:
            if end > self.sure:
                break
            done += 1
        return done

    def last_sure_block(self) -> int:
        done = self.blocks_surely_done()
        return self.ends[done - 1][1] if done else self.first_block - 1

    def last_sent_block(self) -> int:
        sent = [number for end, number in self.ends if end <= self.pos]
        return sent[-1] if sent else self.first_block - 1

    def report(self, start: float, now: float) -> None:
        if self.progress:
            self.progress(TransferProgress(self.blocks_surely_done(), self.blocks_total, self.sure, len(self.data),
                                           now - start, self.paused))

    def fault(self, what: str, todo: str) -> LineFault:
        last = self.last_sure_block()
        where = f"block {last} surely reached the control" if last else "no block surely reached the control"
        sent = self.last_sent_block()
        if sent > last:
            where += f" (blocks {last + 1} to {sent} were on their way and may have arrived too)"
        if self.mode == "drip":
            resume = last + 1
            hint = (f"{todo}, then resume with --start-block {resume}" if resume > 1
                    else f"{todo}, then send again")
            if last and last >= self.ends[-1][1]:
                resume = None
                hint = f"{todo}; every block arrived, only the closing framing may be missing"
            message = f"{what} on {self.port}; {where}; {hint}"
        else:
            resume = None
            message = (f"{what} on {self.port}; {where}; the upload is incomplete: {todo}, "
                       "then send the whole program again")
        self.log(f"fault: {message}")
        return LineFault(message, last, resume, sent)

    def poll(self, now: float) -> None:
        """Read what the control sent; a read that fails is a lost line."""
        incoming = self.line.read(4096)
        # Everything that had left the line before this look is on the far side.
        self.sure = max(self.sure, self.pos - self.unsettled(now))
        for byte in incoming:
            if byte == DC3 and self.settings.flow == "xonxoff":
                if not self.paused:
                    self.paused, self.pause_since = True, now
                    self.pause_reason = "the control held XOFF (DC3) for more than {t} s"
                    self.xoffs += 1
                    self.max_in_flight = max(self.max_in_flight, self.in_flight(now))
                    self.log(f"XOFF after {self.pos} bytes")
            elif byte == DC1 and self.settings.flow == "xonxoff":
                if self.paused:
                    self.log(f"XON after {now - self.pause_since:.3f} s")
                self.paused = False
        if self.settings.flow == "rtscts":
            cts = self.line.cts()
            if not cts and not self.paused:
                self.paused, self.pause_since = True, now
                self.pause_reason = "CTS stayed low (control not ready) for more than {t} s"
            elif cts and self.paused and self.pause_reason.startswith("CTS"):
                self.paused = False

    def check_queue(self, now: float) -> None:
        """An output queue that does not shrink means nothing reads the line."""
        queued = self.line.out_waiting()
        if queued and queued >= self.last_queue:
            if self.queue_stuck_since is None:
                self.queue_stuck_since = now
            elif now - self.queue_stuck_since > self.settings.stall_timeout_s:
                raise self.fault(f"nothing read the line for {self.settings.stall_timeout_s:g} s "
                                 f"({queued} bytes stuck in the output queue)",
                                 "check the cable and that the control is reading")
        else:
            self.queue_stuck_since = None
        self.last_queue = queued

    def run(self) -> TransferResult:
        start = time.monotonic()
        self.pause_since = start
        self.line_free = start
        last_report = -1.0
        limit = self.settings.overrun_chars
        low = limit - 1  # top up as soon as a character has left: the most margin against late wake-ups
        seg = 0
        total = len(self.data)
        self.log(f"sending {total} bytes, {self.blocks_total} blocks, at {self.cps:.1f} characters/s")
        while True:
            now = time.monotonic()
            self.poll(now)
            if now - last_report >= _PROGRESS_S:
                self.report(start, now)
                last_report = now
            self.check_queue(now)
            if self.paused:
                if now - self.pause_since > self.settings.stall_timeout_s:
                    raise self.fault(self.pause_reason.format(t=f"{self.settings.stall_timeout_s:g}"),
                                     "clear the control (reset any alarm) and put it back in DNC or READ mode")
                time.sleep(_POLL_S)
                continue
            in_flight = self.in_flight(now)
            if self.pos >= total:
                if in_flight == 0:
                    finished = now  # the last byte has left the line
                    break
                time.sleep(min(_POLL_S, in_flight / self.cps))
                continue
            if in_flight > low:
                time.sleep(min(_POLL_S, (in_flight - low) / self.cps))
                continue
            while self.segment_ends[seg] <= self.pos:
                seg += 1
            n = min(limit - in_flight, self.segment_ends[seg] - self.pos)
            written = self.line.write(self.data[self.pos:self.pos + n])
            self.line_free = max(self.line_free, now) + written / self.cps
            self.pos += written
        # A healthy look once the last byte has settled, so the last block counts as delivered.
        time.sleep(self.settle_s)
        now = time.monotonic()
        self.poll(now)
        self.sure = self.pos
        self.report(start, now)
        elapsed = finished - start
        self.log(f"done: {total} bytes in {elapsed:.2f} s, {self.xoffs} XOFF")
        return TransferResult(self.blocks_total, total, elapsed, self.xoffs, self.max_in_flight, self.cps)


def send_program(port: str, program: Program, settings: LineSettings, mode: str = "upload", start_block: int = 1,
                 safe_z: str | None = None, progress: Callable[[TransferProgress], None] | None = None,
                 log: Callable[[str], None] | None = None) -> TransferResult:
    """Send a program to a control over a serial line.

    Parameters
    ----------
    port : str
        A device (``/dev/ttyUSB0``, ``COM3``) or a pyserial URL
        (``socket://host:port``, ``rfc2217://host:port``, ``loop://``).
    program : Program
        From :func:`lagsym.dnc.parse_program`.
    settings : LineSettings
        The line set-up, e.g. ``profile("fanuc")``.
    mode : str
        ``upload`` stores the program in the control's memory; ``drip``
        feeds it while the control runs it.
    start_block : int
        Resume a drip feed at this block (see :mod:`lagsym.dnc.blocks` for the
        numbering); the modal set-up is sent first.
    safe_z : str, optional
        Retract height for a resume, in program units.
    progress : callable, optional
        Called about ten times a second with a :class:`TransferProgress`.
    log : callable, optional
        Called with one line of text per event (XOFF, XON, fault, end).

    Returns
    -------
    TransferResult

    Raises
    ------
    LineFault
        On a stall, a lost line or Ctrl-C, naming the last block that surely
        arrived and the ``--start-block`` to resume with.
    TransferError
        If the port cannot be opened.
    InputError
        For a bad mode, start block or resume.
    """
    from .port import LINE_ERRORS, Port, WriteTimeout  # serial loads only when a line is used

    segments = transfer_segments(program, settings, mode, start_block, safe_z)
    line = Port(port, settings, write_timeout=settings.stall_timeout_s)
    sender = _Sender(line, segments, settings, mode, port, progress, log)
    try:
        return sender.run()
    except KeyboardInterrupt:
        raise sender.fault("stopped by the user", "when the control is ready") from None
    except WriteTimeout:
        raise sender.fault(f"a write waited more than {settings.stall_timeout_s:g} s",
                           "check the cable, the flow control setting and that the control is reading") from None
    except LINE_ERRORS as e:
        reason = str(e).strip() or type(e).__name__
        raise sender.fault(f"the line was lost ({reason})",
                           "reconnect the cable or the network port and clear the control") from None
    finally:
        line.close()


def receive_program(port: str, settings: LineSettings, start_timeout_s: float = 60.0, idle_timeout_s: float = 5.0,
                    progress: Callable[[int], None] | None = None, log: Callable[[str], None] | None = None) -> str:
    """Receive a program the control punches out, as text with ``\\n`` line ends.

    The program starts at DC2 or at its first printable character and ends
    at DC4, at the closing ``%`` (with ``settings.percent``), at ETX, or after
    ``idle_timeout_s`` of silence.  Leader, DC codes and NULs are dropped.

    Raises
    ------
    TransferError
        If nothing arrives within ``start_timeout_s``, the line is lost, or
        the program ends without its closing ``%``.
    """
    from .port import LINE_ERRORS, Port

    log = log or (lambda _m: None)
    line = Port(port, settings, write_timeout=1.0)
    raw = bytearray()
    started = False
    percents = 0
    ended = False
    begin = time.monotonic()
    last_data = begin
    mask = 0x7F if settings.bytesize == 7 else 0xFF
    try:
        while not ended:
            now = time.monotonic()
            chunk = line.read(4096)
            if not chunk:
                if not started and now - begin > start_timeout_s:
                    raise TransferError(f"nothing arrived on {port} in {start_timeout_s:g} s; start the output "
                                        "(PUNCH) on the control after lagsym receive is waiting")
                if started and now - last_data > idle_timeout_s:
                    log(f"line idle for {idle_timeout_s:g} s; taking the program as ended")
                    break
                time.sleep(0.01)
                continue
            last_data = now
            for byte in chunk:
                byte &= mask
                if byte == DC2:
                    started = True
                    log("DC2: the control started punching")
                    continue
                if byte in (DC4, 0x03) and started:
                    log("DC4/ETX: the control stopped punching")
                    ended = True
                    break
                if byte in (0x00, 0x7F, DC1, DC3, DC4, 0x03):
                    continue
                started = True
                if byte == ord("%"):
                    percents += 1
                raw.append(byte)
                if settings.percent and percents >= 2 and byte == ord("%"):
                    ended = True
                    break
            if progress:
                progress(len(raw))
    except LINE_ERRORS as e:
        raise TransferError(f"the line on {port} was lost after {len(raw)} bytes ({e}); "
                            "reconnect and punch the program again") from None
    finally:
        line.close()
    text = raw.decode("ascii", errors="replace").replace("\r\n", "\n").replace("\r", "\n")
    if settings.percent:
        first = text.find("%")
        if first < 0 or percents < 2:
            raise TransferError(f"the program from {port} ended without its closing % after {len(raw)} bytes; "
                                "punch it again")
        text = text[first:text.rindex("%") + 1]
    lines = [line.rstrip() for line in text.split("\n")]
    body = "\n".join(line for line in lines if line)
    if not body:
        raise TransferError(f"the program from {port} was empty; punch it again")
    return body + "\n"
