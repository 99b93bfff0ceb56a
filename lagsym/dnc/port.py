"""The serial port: opening it and every call a transfer makes on it (the only module in lagsym that imports serial).

:class:`Port` is the few operations :mod:`lagsym.dnc.transfer` needs: read
what the control sent, write, look at the driver's output queue and CTS, and
close.  A lost line shows as one of :data:`LINE_ERRORS`; a write that waited
longer than its timeout as :data:`WriteTimeout`.  The kernel's IXON stays off
on purpose: lagsym reads DC1/DC3 itself (see :mod:`lagsym.dnc.transfer`).
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import select
import termios
import time

import serial

from ..errors import TransferError
from .lock import other_openers, release_lock_file, take_lock_file
from .settings import PARITIES, LineSettings, check_port

__all__ = ["Port", "LINE_ERRORS", "WriteTimeout"]

LINE_ERRORS = (serial.SerialException, OSError, termios.error)
WriteTimeout = serial.SerialTimeoutException


class Port:
    """An open serial line to a control.

    Parameters
    ----------
    name : str
        A device (``/dev/ttyUSB0``, ``COM3``) or a pyserial URL
        (``socket://host:port``, ``rfc2217://host:port``, ``loop://``).
    settings : LineSettings
        Baud rate, character format, hardware flow control and DTR.
    write_timeout : float or None
        Longest a write may wait, in seconds.

    Raises
    ------
    InputError
        For a URL that cannot name a port (see :func:`~lagsym.dnc.settings.check_port`).
    TransferError
        If the port cannot be opened.
    """

    def __init__(self, name: str, settings: LineSettings, write_timeout: float | None):
        check_port(name, "port")
        self._lock_file = None
        local = "://" not in name
        if local:  # the lock file and the look for other openers, before touching the line (see lagsym.dnc.lock)
            self._lock_file, holder = take_lock_file(name)
            others = [holder] if holder else other_openers(name)
            if others:
                release_lock_file(self._lock_file)
                raise TransferError(f"cannot open {name}: the port is in use by another program ({'; '.join(others)}); "
                                    "close it and try again")
        ser = None
        try:
            ser = serial.serial_for_url(name, do_not_open=True)
            ser.baudrate = settings.baud
            ser.bytesize = settings.bytesize
            ser.parity = PARITIES[settings.parity]
            ser.stopbits = settings.stopbits if settings.stopbits == 1.5 else int(settings.stopbits)
            ser.xonxoff = False  # lagsym reads DC1/DC3 itself; see the module notes
            ser.rtscts = settings.flow == "rtscts"
            ser.dsrdtr = settings.flow == "dtrdsr"
            ser.timeout = 0
            if "://" not in name:
                ser.exclusive = True  # a second reader would take the control's DC1 and stall the transfer
            if not name.lower().startswith("rfc2217://"):
                # pyserial's RFC 2217 client refuses a write timeout when it opens (its writes wait on the
                # network); the sender's own stall check bounds them there.
                ser.write_timeout = write_timeout
            ser.dtr = settings.dtr
            ser.open()
            if local and type(ser) is serial.Serial:
                try:  # the kernel refuses any further open (but root's): a cat started later cannot steal DC3
                    fcntl.ioctl(ser.fd, termios.TIOCEXCL)
                except OSError:
                    pass  # a device without it (not a terminal): flock and the lock file still hold
        except (ValueError, KeyError, *LINE_ERRORS) as e:  # KeyError: pyserial formatting its own URL message
            release_lock_file(self._lock_file)
            raise TransferError(_open_failure(name, e)) from None
        except BaseException:  # Ctrl-C or a signal while opening: nothing left open or locked
            if ser is not None:
                with contextlib.suppress(Exception):
                    ser.close()
            release_lock_file(self._lock_file)
            raise
        self._ser = ser
        # A local device can be waited on: the sender sleeps until the control says something or the line needs
        # more, instead of polling.  A URL port (RFC 2217, socket, loop) buffers in pyserial and is polled.
        self._fd = ser.fd if type(ser) is serial.Serial else None

    def read(self, size: int) -> bytes:
        """What has arrived, up to ``size`` bytes, without waiting."""
        return self._ser.read(size)

    def write(self, data: bytes) -> int:
        """Queue ``data``; the number of bytes taken."""
        written = self._ser.write(data)
        return len(data) if written is None else written

    def wait(self, timeout_s: float) -> None:
        """Wait up to ``timeout_s`` seconds, returning as soon as the control has sent something (where the port can tell)."""
        if self._fd is None:
            time.sleep(timeout_s)
            return
        try:
            select.select([self._fd], [], [], timeout_s)
        except (OSError, ValueError):  # a line lost meanwhile: the next read says so
            time.sleep(timeout_s)

    def out_waiting(self) -> int:
        """Bytes in the driver's output queue, or 0 where the port cannot tell."""
        try:
            return int(self._ser.out_waiting)
        except (AttributeError, NotImplementedError, ValueError, TypeError):
            return 0

    def cts(self) -> bool:
        """Whether the control holds CTS high; True where the port cannot tell."""
        return self.signal("cts")

    def signal(self, name: str) -> bool:
        """Whether the control holds ``cts``, ``dsr`` or ``cd`` high; True where the port cannot tell."""
        try:
            return bool(getattr(self._ser, name))
        except (AttributeError, NotImplementedError, *LINE_ERRORS):
            return True

    def can_sense(self, name: str) -> bool:
        """Whether this port reports the signal ``name`` at all (a pseudo-terminal has no modem lines)."""
        try:
            getattr(self._ser, name)
        except (AttributeError, NotImplementedError, *LINE_ERRORS):
            return False
        return True

    def close(self) -> None:
        """Close the port; a line already lost needs no closing."""
        if self._fd is not None:
            try:  # the flag outlives this open while the far end keeps the device open (a pty relay)
                fcntl.ioctl(self._fd, termios.TIOCNXCL)
            except (OSError, ValueError):
                pass
        try:
            self._ser.close()
        except LINE_ERRORS:
            pass
        release_lock_file(self._lock_file)
        self._lock_file = None


def _open_failure(name: str, e: BaseException) -> str:
    reason = str(e).strip() or type(e).__name__
    busy = (getattr(e, "errno", None) in (errno.EBUSY, errno.EAGAIN, errno.EWOULDBLOCK)
            or "exclusively lock" in reason)
    if busy:
        return (f"cannot open {name}: the port is in use by another program (another lagsym, a terminal or a "
                "DNC service); close it and try again")
    return (f"cannot open {name}: {reason}; check the cable, the device name or URL, "
            "and that no other program holds the port")
