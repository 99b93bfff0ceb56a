"""Receiving a program the control punches out: :func:`receive_program`.

The program starts at DC2 or at its first printable character and ends at
DC4, at the closing ``%``, at ETX, or after a silence.  What arrives is
checked before it is believed: characters no program holds (control codes,
8-bit bytes, and with ``iso_check`` anything outside the ISO 840 tape code)
are what a baud rate or parity that does not match the control's produces,
and the message says to check them.

A receive that fails part way raises :class:`ReceiveFault`, which carries
every byte that arrived (``wire``), so that a service can keep a failed
punch.  A service that keeps its port open passes an :class:`Inbox`: what
arrived after the end of one program (a punch-all, or punches back to back)
stays there for the next call, and ``sink`` sees every byte as it arrives.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

from ..errors import TransferError, stopped_by
from .blocks import DC1, DC2, DC3, DC4, ISO_840
from .settings import LineSettings

__all__ = ["receive_program", "ReceiveFault", "ReceiveProgress", "Inbox"]

_ETX = 0x03
_DROPPED = frozenset((0x00, 0x7F, DC1, DC3, DC4, _ETX))
_BLANKS = frozenset(b" \t\r\n")
_LINE_CODES = frozenset(b"\r\n\t")


class ReceiveFault(TransferError):
    """A receive that failed part way; ``wire`` holds every byte that arrived, ``reason`` the short why."""

    def __init__(self, message: str, wire: bytes, reason: str, line_lost: bool = False, too_long: bool = False):
        super().__init__(message)
        self.wire, self.reason, self.line_lost, self.too_long = wire, reason, line_lost, too_long


@dataclass(frozen=True)
class ReceiveProgress:
    """Where a receive stands: characters and blocks of the program so far, and the time since it started."""

    chars: int
    blocks: int
    elapsed_s: float

    @property
    def rate_chars_s(self) -> float:
        return self.chars / self.elapsed_s if self.elapsed_s > 0 else 0.0


@dataclass
class Inbox:
    """Bytes read from the line but not yet taken by a program (a service keeps one per port)."""

    pending: bytearray = field(default_factory=bytearray)


def _garbage(raw: bytes, settings: LineSettings) -> int:
    """Characters in ``raw`` that no program holds."""
    allowed = ISO_840 | set("\r\n") if settings.iso_check else None
    count = 0
    for byte in raw:
        if byte > 126 or (byte < 32 and byte not in _LINE_CODES):
            count += 1
        elif allowed is not None and chr(byte) not in allowed:
            count += 1
    return count


def _settings_text(settings: LineSettings) -> str:
    return f"{settings.baud} baud, {settings.bytesize}{settings.parity[0].upper()}{settings.stopbits:g}"


def receive_program(port: str, settings: LineSettings, *, start_timeout_s: float = 60.0,
                    idle_timeout_s: float = 5.0, progress: Callable[[ReceiveProgress], None] | None = None,
                    log: Callable[[str], None] | None = None,
                    ready: Callable[[], None] | None = None,
                    should_stop: Callable[[], bool] | None = None, line=None, inbox: Inbox | None = None,
                    sink: Callable[[bytes], None] | None = None, max_bytes: int | None = None) -> str:
    """Receive a program the control punches out, as text with ``\\n`` line ends.

    Parameters
    ----------
    start_timeout_s : float
        How long to wait for the first character; ``math.inf`` waits for ever.
    idle_timeout_s : float
        Silence that ends a program without DC4 or closing ``%``.
    ready : callable, optional
        Called once the port is open and lagsym is listening (the moment to
        press PUNCH).
    progress : callable, optional
        Called with a :class:`ReceiveProgress` after every read once the program has started.
    should_stop : callable, optional
        Looked at between reads; True gives up the wait (a service stopping),
        and a program part way in is a :class:`ReceiveFault` with what arrived.
    line : lagsym.dnc.port.Port, optional
        A port already open (a service keeps its port), used and left open.
    inbox : Inbox, optional
        Read first, and left holding what arrived after the program's end.
    sink : callable, optional
        Called with every byte of this program as it arrives (a service streams it to disk).
    max_bytes : int, optional
        A program longer than this is a :class:`ReceiveFault`.

    Raises
    ------
    TransferError
        If nothing arrives in time, the line is lost, the program ends
        without its closing ``%``, what arrived is garbage (a baud rate or
        parity mismatch), or on Ctrl-C, SIGTERM or SIGHUP.
    """
    from .port import LINE_ERRORS, Port

    owned = line is None
    punch = _Punch(inbox or Inbox(), sink, max_bytes)
    try:
        if owned:  # inside: a signal while the port opens stops the receive as one after it does
            line = Port(port, settings, write_timeout=1.0)
        if ready:
            ready()
        _collect(line, port, settings, punch, start_timeout_s=start_timeout_s, idle_timeout_s=idle_timeout_s,
                 progress=progress, log=log or (lambda _m: None), should_stop=should_stop)
    except KeyboardInterrupt as e:
        what = stopped_by(e)
        raise ReceiveFault(f"receive on {port} {what}; nothing was saved ({len(punch.wire)} bytes had arrived): "
                           "start lagsym receive again, then punch the program again", bytes(punch.wire),
                           what) from None
    except TransferError:
        raise
    except LINE_ERRORS as e:
        raise ReceiveFault(f"the line on {port} was lost after {len(punch.wire)} bytes ({e}); "
                           "reconnect and punch the program again", bytes(punch.wire), f"line lost ({e})",
                           line_lost=True) from None
    finally:
        if owned and line is not None:
            line.close()
    try:
        return _program_text(bytes(punch.raw), punch.percents, port, settings)
    except TransferError as e:
        raise ReceiveFault(str(e), bytes(punch.wire), str(e)) from None


class _Punch:
    """One program arriving: every byte off the line for it (``wire``) and the program's own (``raw``)."""

    def __init__(self, inbox: Inbox, sink, max_bytes):
        self.inbox, self.sink, self.max_bytes = inbox, sink, max_bytes
        self.wire = bytearray()
        self.raw = bytearray()
        self.percents = 0
        self.blocks = 0  # lines with program text ended so far (not the % lines)
        self.in_block = False

    def take(self, chunk: bytes) -> None:
        self.wire += chunk
        if self.sink is not None:
            self.sink(chunk)

    def give_back(self, rest: bytes) -> None:
        """Bytes after the program's end, for the next program."""
        self.inbox.pending[:0] = rest


def _collect(line, port, settings, punch: _Punch, *, start_timeout_s, idle_timeout_s, progress, log,
             should_stop) -> None:
    """Fill ``punch`` with the program's bytes (leader and control codes dropped) and count its ``%``."""
    raw = punch.raw
    started = ended = False
    begin = last_data = time.monotonic()
    mask = 0x7F if settings.bytesize == 7 else 0xFF
    while not ended:
        now = time.monotonic()
        if should_stop is not None and should_stop():
            if started:
                raise ReceiveFault(f"receive on {port} stopped after {len(punch.wire)} bytes of a program",
                                   bytes(punch.wire), "the service stopped while the program arrived")
            raise TransferError(f"receive on {port} stopped before a program arrived")
        if punch.inbox.pending:
            chunk = bytes(punch.inbox.pending)
            punch.inbox.pending.clear()
        else:
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
        used = len(chunk)
        for index, byte in enumerate(chunk):
            byte &= mask
            if byte == DC2:
                started = True
                log("DC2: the control started punching")
                continue
            if byte in (DC4, _ETX) and started:
                log("DC4/ETX: the control stopped punching")
                used = index + 1
                ended = True
                break
            if byte in _DROPPED:
                continue
            if not started and byte in _BLANKS:  # the line end after the last program's closing % (and its
                continue                          # DC4) may come in a later read: it does not start a program
            if not started:
                begin = now
            started = True
            if byte == ord("%"):
                punch.percents += 1
            elif byte in (0x0A, 0x0D):
                punch.blocks += punch.in_block
                punch.in_block = False
            elif byte not in _BLANKS:
                punch.in_block = True
            raw.append(byte)
            if settings.percent and punch.percents >= 2 and byte == ord("%"):
                used = index + 1
                ended = True
                break
        punch.take(chunk[:used])
        punch.give_back(chunk[used:])
        if punch.max_bytes is not None and len(punch.wire) > punch.max_bytes:
            raise ReceiveFault(f"the program from {port} is longer than the limit of {punch.max_bytes} bytes; "
                               "raise max_punch_bytes or split the program", bytes(punch.wire),
                               f"longer than max_punch_bytes ({punch.max_bytes})", too_long=True)
        if progress and started:
            progress(ReceiveProgress(len(raw), punch.blocks, time.monotonic() - begin))


def _program_text(raw: bytes, percents: int, port: str, settings: LineSettings) -> str:
    bad = _garbage(raw, settings)
    if bad:
        raise TransferError(f"{bad} of the {len(raw)} characters from {port} are not program text (garbage); "
                            f"check the baud rate and format ({_settings_text(settings)}): baud rate, parity, data "
                            "bits and stop bits must match the control's; then punch it again")
    text = raw.decode("ascii").replace("\r\n", "\n").replace("\r", "\n")
    from ..probe.results import is_probe_results

    if is_probe_results(text):  # a probing program's DPRNT output (POPEN .. PCLOS): no % around it
        lines = [line.rstrip() for line in text.split("\n")]
        return "\n".join(line for line in lines if line) + "\n"
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


