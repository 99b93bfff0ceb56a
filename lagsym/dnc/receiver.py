"""Receiving a program the control punches out: :func:`receive_program`.

The program starts at DC2 or at its first printable character and ends at
DC4, at the closing ``%``, at ETX, or after a silence.  What arrives is
checked before it is believed: characters no program holds (control codes,
8-bit bytes, and with ``iso_check`` anything outside the ISO 840 tape code)
are what a baud rate or parity that does not match the control's produces,
and the message says to check them.
"""

from __future__ import annotations

import signal
import time
from collections.abc import Callable

from ..errors import Terminated, TransferError
from .blocks import DC1, DC2, DC3, DC4, ISO_840
from .settings import LineSettings

__all__ = ["receive_program"]

_ETX = 0x03
_DROPPED = frozenset((0x00, 0x7F, DC1, DC3, DC4, _ETX))
_BLANKS = frozenset(b" \t\r\n")
_LINE_CODES = frozenset(b"\r\n\t")


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
                    idle_timeout_s: float = 5.0, progress: Callable[[int], None] | None = None,
                    log: Callable[[str], None] | None = None,
                    ready: Callable[[], None] | None = None,
                    should_stop: Callable[[], bool] | None = None, line=None) -> str:
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
    should_stop : callable, optional
        Looked at between reads; True gives up the wait (a service stopping).
    line : lagsym.dnc.port.Port, optional
        A port already open (a service keeps its port), used and left open.

    Raises
    ------
    TransferError
        If nothing arrives in time, the line is lost, the program ends
        without its closing ``%``, what arrived is garbage (a baud rate or
        parity mismatch), or on Ctrl-C, SIGTERM or SIGHUP.
    """
    from .port import LINE_ERRORS, Port

    owned = line is None
    if owned:
        line = Port(port, settings, write_timeout=1.0)
    raw = bytearray()
    try:
        if ready:
            ready()
        raw, percents = _collect(line, port, settings, start_timeout_s=start_timeout_s,
                                 idle_timeout_s=idle_timeout_s, progress=progress, log=log or (lambda _m: None),
                                 should_stop=should_stop)
    except KeyboardInterrupt as e:
        what = f"stopped by {signal.Signals(e.signum).name}" if isinstance(e, Terminated) else "stopped by the user"
        raise TransferError(f"receive on {port} {what}; nothing was saved: start lagsym receive again, "
                            "then punch the program again") from None
    except TransferError:
        raise
    except LINE_ERRORS as e:
        raise TransferError(f"the line on {port} was lost after {len(raw)} bytes ({e}); "
                            "reconnect and punch the program again") from None
    finally:
        if owned:
            line.close()
    return _program_text(bytes(raw), percents, port, settings)


def _collect(line, port, settings, *, start_timeout_s, idle_timeout_s, progress, log, should_stop):
    """The program's bytes (leader and control codes dropped) and how many ``%`` they hold."""
    raw = bytearray()
    started = ended = False
    percents = 0
    begin = last_data = time.monotonic()
    mask = 0x7F if settings.bytesize == 7 else 0xFF
    while not ended:
        now = time.monotonic()
        if should_stop is not None and should_stop():
            raise TransferError(f"receive on {port} stopped before a program arrived")
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
            if byte in (DC4, _ETX) and started:
                log("DC4/ETX: the control stopped punching")
                ended = True
                break
            if byte in _DROPPED:
                continue
            if not started and byte in _BLANKS:  # the line end after the last program's closing % (and its
                continue                          # DC4) may come in a later read: it does not start a program
            started = True
            if byte == ord("%"):
                percents += 1
            raw.append(byte)
            if settings.percent and percents >= 2 and byte == ord("%"):
                ended = True
                break
        if progress:
            progress(len(raw))
    return raw, percents


def _program_text(raw: bytes, percents: int, port: str, settings: LineSettings) -> str:
    bad = _garbage(raw, settings)
    if bad:
        raise TransferError(f"{bad} of the {len(raw)} characters from {port} are not program text (garbage); "
                            f"check that the baud rate, parity, data bits and stop bits ({_settings_text(settings)}) "
                            "match the control's, then punch it again")
    text = raw.decode("ascii").replace("\r\n", "\n").replace("\r", "\n")
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


