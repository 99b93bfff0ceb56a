"""A simulated CNC control at the far end of a real pseudo-terminal pair made by socat.

A pty has no baud rate, so the control paces itself: it takes characters
from its end no faster than the line rate of its baud, holds them in a small
buffer that the "machine" empties at ``drain_cps``, sends DC3 at the high
water mark and DC1 at the low one, and records every byte.  It counts
overflow the way a Fanuc raises alarm 087: characters that arrive after its
DC3 beyond ``tolerance``.  Time the simulation itself lost to the scheduler
is not charged to the sender (a real control's UART interrupt answers at once).
"""

from __future__ import annotations

import errno
import fcntl
import multiprocessing
import os
import shutil
import signal
import subprocess
import tempfile
import termios
import time

import serial

__all__ = ["PtyPair", "KernelPty", "SimControl", "punch", "program_text", "chars_per_s"]

DC1, DC2, DC3, DC4 = b"\x11", b"\x12", b"\x13", b"\x14"
_LOOP_S = 0.0005


def chars_per_s(baud: int, bytesize: int = 7, parity: str = "even", stopbits: float = 2) -> float:
    """Characters per second on a line."""
    return baud / (1 + bytesize + (parity != "none") + stopbits)


class PtyPair:
    """Two linked pseudo-terminals from socat: ``near`` for lagsym, ``far`` for the simulated control."""

    def __init__(self, directory: str | None = None):
        if shutil.which("socat") is None:
            raise RuntimeError("socat is not installed (apt-get install socat)")
        self._tmp = tempfile.mkdtemp(prefix="lagsym-pty-", dir=directory)
        self.near = os.path.join(self._tmp, "near")
        self.far = os.path.join(self._tmp, "far")
        self._owner = os.getpid()
        self.proc = subprocess.Popen(
            ["socat", "-t", "0", f"pty,raw,echo=0,link={self.near}", f"pty,raw,echo=0,link={self.far}"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 10
        while not (os.path.exists(self.near) and os.path.exists(self.far)):
            if self.proc.poll() is not None or time.monotonic() > deadline:
                self.close()
                raise RuntimeError("socat did not make the pty pair")
            time.sleep(0.01)

    def hang_up(self) -> None:
        """Cut the line: both ends see a hang-up at once (callable from the control's process too)."""
        try:
            os.kill(self.proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        if os.getpid() == self._owner:
            self.proc.wait()

    def close(self) -> None:
        self.hang_up()
        shutil.rmtree(self._tmp, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class KernelPty:
    """A pty pair straight from the kernel: ``near`` for lagsym, the master ``fd`` for the simulated control.

    Unlike the socat pair, no relay process stands between the two ends, so a
    DC3 is readable at ``near`` the moment the control writes it, as it is at
    a real UART.  On a loaded machine the relay can take 100 ms to pass a DC3
    back, which would be charged to the sender as overflow; the overflow
    measurements use this pair.
    """

    def __init__(self):
        self.fd, self._slave = os.openpty()
        self.near = os.ttyname(self._slave)
        self.far = self.fd

    def close(self) -> None:
        for fd in (self.fd, self._slave):
            try:
                os.close(fd)
            except OSError:
                pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class _FdPort:
    """The few pyserial calls the control makes, on a pty master descriptor."""

    def __init__(self, fd: int):
        self.fd = fd
        os.set_blocking(fd, False)

    @property
    def in_waiting(self) -> int:
        return int.from_bytes(fcntl.ioctl(self.fd, termios.FIONREAD, b"\0\0\0\0"), "little")

    def read(self, n: int) -> bytes:
        try:
            return os.read(self.fd, n)
        except BlockingIOError:
            return b""
        except OSError as e:
            if e.errno == errno.EIO:  # no one has the near end open
                return b""
            raise

    def write(self, data: bytes) -> int:
        return os.write(self.fd, data)

    def close(self) -> None:
        os.close(self.fd)


class SimControl:
    """The control: reads at its line rate, buffers, says XOFF/XON, records, and can misbehave on request.

    It runs in a process of its own, so that its pace does not depend on the
    sender's interpreter.  Its record (``received``, ``overflow``, ``xoffs``,
    ``max_after_xoff``, ``pending_at_xoff``, ``dropped``, ``starved_s``) is
    read once it has stopped; reading it stops it.  ``starved_s`` is the time
    the machine found the buffer empty between the first and the last
    character (the program not yet all there); ``pending_at_xoff`` the most
    characters still in the pty, written but not yet carried by the line,
    when a DC3 went out (less those a real line would have carried while the
    simulation itself was descheduled).

    Parameters
    ----------
    path : str or int
        Its end of the pty pair: a path (socat's pair) or a master descriptor (:class:`KernelPty`).
    baud, bytesize, parity, stopbits
        The line, for the pacing.
    buffer_chars, high_water, low_water : int
        The input buffer and the marks at which DC3 and DC1 go out.
    drain_cps : float or None
        How fast the machine empties the buffer; None: at once (never XOFF).
    tolerance : int
        Characters accepted after DC3 before counting overflow (a Fanuc: about 10).
    ignore_xon : bool
        Send DC3 and never DC1.
    drop_on_xoff : int or None
        At this XOFF, wait ``drop_settle_s`` and then cut the line.
    drop_after_bytes : int or None
        Cut the line as soon as this many bytes have arrived.
    xon_after_s : float or None
        Send DC1 this long after starting, as a Fanuc does when READ is pressed.
    hold_on_xoff : bool or int
        A feed hold at the first XOFF (or at XOFF number ``hold_on_xoff``):
        the machine stops emptying the buffer, so it never asks for more.
        ``executed`` counts the characters the machine took from the buffer.
    discard_after_bytes : int or None
        Keep reading the line but record nothing after this many bytes: a
        control that stopped taking the program while its port stays up.
    garble_answers : bool
        Answer with what a line at another baud rate makes of DC3 and DC1
        (characters no control sends), as a control set up differently does.
    late_answers_s : float
        Each DC3 and DC1 reaches the sender this long after the control sent
        it, as a loaded computer's own delivery (its kernel's input work, a USB
        adapter's latency timer) can hold it back.
    pair : PtyPair
        What to hang up when cutting the line.
    """

    def __init__(self, path: str, pair: PtyPair | None = None, **params):
        ctx = multiprocessing.get_context("fork")
        self.cps = chars_per_s(params.get("baud", 9600), params.get("bytesize", 7), params.get("parity", "even"),
                               params.get("stopbits", 2))
        self._count = ctx.Value("q", 0, lock=False)
        self._halt = ctx.Event()
        self._ready = ctx.Event()
        self._results, child_end = ctx.Pipe(duplex=False)
        socat_pid = pair.proc.pid if pair is not None else None
        args = (path, params, socat_pid, self._count, self._halt, self._ready, child_end)
        self._proc = ctx.Process(target=_control_main, args=args, daemon=True)
        self._record: dict | None = None
        self._master = path if isinstance(path, int) else None

    def start(self) -> None:
        """Start the control and wait until its end of the line is open (opening it clears its input)."""
        self._proc.start()
        if not self._ready.wait(10):
            self._proc.kill()
            raise RuntimeError("the simulated control did not open its end of the line")
        if self._master is not None:
            os.close(self._master)  # the control's process holds the master now; its close hangs up the line

    @property
    def arrived(self) -> int:
        """Bytes arrived so far (readable while the control runs)."""
        return self._count.value

    def wait_for(self, count: int, timeout: float = 30.0) -> bool:
        """Wait until ``count`` bytes have arrived."""
        deadline = time.monotonic() + timeout
        while self._count.value < count and time.monotonic() < deadline and self._proc.is_alive():
            time.sleep(0.01)
        return self._count.value >= count

    def stop(self) -> dict:
        """Stop the control (if the line has not already ended it) and return its record."""
        if self._record is None:
            self._halt.set()
            if not self._results.poll(15):
                self._proc.kill()
                raise RuntimeError("the simulated control did not stop")
            self._record = self._results.recv()
            self._proc.join(5)
            if self._record["error"] and not self._record["dropped"]:
                raise RuntimeError(f"the simulated control failed: {self._record['error']}")
        return self._record

    def __getattr__(self, name):
        if name in ("received", "overflow", "max_after_xoff", "xoffs", "dropped", "first_byte_at", "last_byte_at",
                    "executed", "starved_s", "pending_at_xoff"):
            return self.stop()[name]
        raise AttributeError(name)

    def lines(self) -> list[str]:
        """Complete lines received (a partial last line, cut by a drop, is discarded), without leader NULs."""
        text = self.received.replace(b"\x00", b"").decode("ascii")
        return text.replace("\r\n", "\n").split("\n")[:-1]


def _control_main(path, params, socat_pid, count, halt, ready, results) -> None:
    control = _Control(path, socat_pid, count, halt, **params)
    ready.set()
    try:
        control.run()
    except (serial.SerialException, OSError) as e:
        control.error = str(e)
    if control.xoff:
        control.close_episode()
    results.send({"received": bytes(control.received), "overflow": control.overflow, "xoffs": control.xoffs,
                  "max_after_xoff": control.max_after_xoff, "dropped": control.dropped, "error": control.error,
                  "first_byte_at": control.first_byte_at, "last_byte_at": control.last_byte_at,
                  "executed": len(control.received) - int(control.buffered + 0.999),
                  "starved_s": control.starved_at_last, "pending_at_xoff": control.pending_at_xoff,
                  "episodes": control.episodes})


class _Control:
    def __init__(self, path, socat_pid, count, halt, baud=9600, bytesize=7, parity="even", stopbits=2,
                 buffer_chars=256, high_water=192, low_water=64, drain_cps=None, tolerance=10, ignore_xon=False,
                 drop_on_xoff=None, drop_settle_s=1.0, drop_after_bytes=None, xon_after_s=None, hold_on_xoff=False,
                 discard_after_bytes=None, garble_answers=False, late_answers_s=0.0):
        self.cps = chars_per_s(baud, bytesize, parity, stopbits)
        self.buffer_chars, self.high, self.low = buffer_chars, high_water, low_water
        self.drain_cps, self.tolerance, self.ignore_xon = drain_cps, tolerance, ignore_xon
        self.drop_on_xoff, self.drop_settle_s, self.drop_after_bytes = drop_on_xoff, drop_settle_s, drop_after_bytes
        self.socat_pid, self.count, self.halt = socat_pid, count, halt
        self.xon_after_s = xon_after_s
        self.hold_on_xoff, self.discard_after_bytes = hold_on_xoff, discard_after_bytes
        # DC3 (0x13) and DC1 (0x11) sent at 4800 baud and read at 9600 come out as other characters.
        self.xoff_byte, self.xon_byte = (b"\xe6", b"\x9e") if garble_answers else (DC3, DC1)
        self.late_s, self.on_the_way = late_answers_s, []  # answers sent, not yet delivered: (when due, byte)
        self.buffered = 0.0
        self.count_in = 0  # every character taken from the line, recorded or not
        self.port = _FdPort(path) if isinstance(path, int) else serial.Serial(path, baudrate=baud, timeout=0)
        self.received = bytearray()
        self.overflow = 0
        self.max_after_xoff = 0
        self.xoffs = 0
        self.dropped = False
        self.error = None
        self.xoff = False
        self.after = 0  # characters since the high-water crossing
        self.excused = 0.0  # characters that arrived while the simulation itself was descheduled
        self.first_byte_at = None
        self.last_byte_at = None
        self.starved_s = 0.0  # time the machine found the buffer empty since the first character
        self.starved_at_last = 0.0  # the same up to the last character: while the program remained
        self.episodes = []  # per XOFF: (characters after DC3, excused, left in the pty, rest of the read at DC3)
        self.pending_now = self.tail = 0
        self.pending_at_xoff = 0  # most characters still waiting in the pty (on the wire) when DC3 went out

    def close_episode(self) -> None:
        self.overflow += max(0, int(self.after - self.excused) - self.tolerance)
        self.episodes.append((self.after, int(self.excused), self.pending_now, self.tail))

    def cut(self) -> None:
        self.dropped = True
        try:
            self.port.close()
        finally:
            if self.socat_pid is not None:
                try:
                    os.kill(self.socat_pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass

    def answer(self, byte: bytes, line_t: float) -> float:
        """Send DC3 or DC1, then take what the line had brought by then; the new ``line_t``.

        A real control answers from what it holds the moment it answers;
        this simulation runs late now and then on a loaded machine, so what
        arrived (by the line's clock) before its answer went out is taken
        after it and counted as held then.  A control that stops taking the
        program (``discard_after_bytes``) stops only after its last answer:
        an answer vouches for everything that had come before it.
        """
        sent = time.monotonic()
        if self.late_s:
            self.on_the_way.append((sent + self.late_s, byte))
        else:
            self.port.write(byte)
        if self.drop_after_bytes is not None:
            return line_t
        more = min(self.port.in_waiting, int((sent - line_t) * self.cps))
        if more > 0:
            extra = self.port.read(more)
            line_t += len(extra) / self.cps
            self.last_byte_at = time.monotonic()
            for value in extra:
                self.count_in += 1
                self.hold(value)
            if self.discard_after_bytes is not None:
                self.discard_after_bytes = max(self.discard_after_bytes, self.count_in)
            self.count.value = len(self.received)
        return line_t

    def hold(self, value: int) -> None:
        """One character from the line into the buffer, counted as past the DC3 while one is out."""
        self.received.append(value)
        self.buffered += 1
        if self.xoff:
            self.after += 1

    def dead(self) -> bool:
        """Past ``discard_after_bytes``: the control takes what comes and answers nothing."""
        return self.discard_after_bytes is not None and self.count_in > self.discard_after_bytes

    def run(self) -> None:
        line_t = 0.0  # when the wire will have delivered everything read so far
        was_pending = False
        drop_at = None
        last = time.monotonic()
        xon_at = None if self.xon_after_s is None else last + self.xon_after_s
        while not self.halt.is_set():
            now = time.monotonic()
            gap = now - last
            last = now
            while self.on_the_way and self.on_the_way[0][0] <= now:
                self.port.write(self.on_the_way.pop(0)[1])
            if xon_at is not None and now >= xon_at:
                self.port.write(DC1)  # READ pressed: the control asks for the program
                xon_at = None
            if drop_at is not None and now >= drop_at:
                self.received += self.port.read(4096)  # whatever was still on the way arrives before the cut
                self.count.value = len(self.received)
                self.cut()
                return
            held = self.hold_on_xoff and self.xoffs >= self.hold_on_xoff
            deficit = 0.0  # characters the machine wanted in this gap beyond what the buffer held
            if not held:
                if self.drain_cps is not None:
                    deficit = self.drain_cps * gap - self.buffered
                self.buffered = 0.0 if self.drain_cps is None else max(0.0, -deficit)
            pending = self.port.in_waiting
            if pending and not was_pending:
                line_t = max(line_t, now - gap)  # an idle line starts again when the data came, about the last look
            n = min(pending, int((now - line_t) * self.cps)) if pending else 0
            was_pending = pending > n
            if deficit > 0 and self.first_byte_at is not None:
                # What the line brings in this look arrived during the gap: only the rest is a starved machine.
                self.starved_s += max(0.0, deficit - n) / self.drain_cps
            crossed = False
            if n:
                data = self.port.read(n)
                line_t += len(data) / self.cps
                now = time.monotonic()
                self.first_byte_at = self.first_byte_at or now
                self.last_byte_at = now
                self.starved_at_last = self.starved_s
                for at, byte in enumerate(data, 1):
                    self.count_in += 1
                    if self.discard_after_bytes is not None and self.count_in > self.discard_after_bytes:
                        continue
                    self.hold(byte)
                    if not self.xoff and self.buffered >= self.high:
                        crossed = self.xoff = True
                        self.after = 0
                    if self.drop_after_bytes is not None and len(self.received) >= self.drop_after_bytes:
                        # What is already on its way arrives (a UART would have taken it while the
                        # simulation was not running), the rest of this read first; what comes after the
                        # cut is lost.
                        self.received += data[at:] + self.port.read(self.port.in_waiting or 1)
                        self.count.value = len(self.received)
                        self.cut()
                        return
                self.count.value = len(self.received)
                # A control that died in this read (past discard_after_bytes) sends no DC3 for it.
                if crossed and not self.dead():
                    line_t = self.answer(self.xoff_byte, line_t)
                    self.pending_now, self.tail = self.port.in_waiting, self.after
                    # Time the simulation lost between its previous look and this DC3 (descheduled before
                    # or after the read) is its own lateness, not the sender's: excuse what came in then.
                    late_s = time.monotonic() - (last - gap) - 2 * _LOOP_S
                    self.excused = max(0.0, late_s) * self.cps
                    # A real line would have carried the excused characters to the control by now: only the
                    # rest was still on its way when the DC3 went out.
                    self.pending_at_xoff = max(self.pending_at_xoff, self.pending_now - int(self.excused))
                    self.xoffs += 1
                    if self.drop_on_xoff is not None and self.xoffs == self.drop_on_xoff:
                        drop_at = time.monotonic() + self.drop_settle_s
                if self.xoff:
                    self.max_after_xoff = max(self.max_after_xoff, self.after)
            if self.xoff and not self.ignore_xon and drop_at is None and not self.dead() and self.buffered <= self.low:
                self.close_episode()
                self.xoff = False
                line_t = self.answer(self.xon_byte, line_t)
            time.sleep(_LOOP_S)


def punch(path: str, data: bytes, baud: int = 9600, bytesize: int = 7, parity: str = "even", stopbits: float = 2,
          delay_s: float = 0.3) -> None:
    """Send ``data`` from the control's end at the line rate, as a control punching a program does."""
    cps = chars_per_s(baud, bytesize, parity, stopbits)
    with serial.Serial(path, baudrate=baud, timeout=0) as port:
        time.sleep(delay_s)
        start = time.monotonic()
        sent = 0
        while sent < len(data):
            due = int((time.monotonic() - start) * cps) + 1
            if due > sent:
                sent += port.write(data[sent:min(due, len(data))])
            time.sleep(0.001)
        port.flush()
        time.sleep(0.2)


def program_text(blocks: int, seed: int = 1) -> str:
    """A plausible drip-feed program of ``blocks`` blocks (about 30 characters each)."""
    lines = ["O1000", "G21 G17 G90 G54", "T1 M6", "S3000 M3", "G0 Z50.", "G0 X0. Y0.", "G1 Z-1. F600."]
    x = 0
    k = 0
    while len(lines) < blocks - 2:
        k += 1
        x += 1
        y = (k * 37 + seed) % 1000
        lines.append(f"G1 X{x * 0.125:.3f} Y{y * 0.051:.3f} Z{-1 - (k % 7) * 0.01:.3f}")
    lines += ["G0 Z50.", "M30"]
    return "%\n" + "\n".join(lines) + "\n%\n"


# A short program with every modal group a resume set-up restores.
PROGRAM = """%
O1000
G21 G17 G90 G54
T2 M6
S4000 M3
G0 Z25.
G0 X0. Y0.
M8
G1 Z-1. F300.
G1 X10. Y0. F600.
G2 X20. Y10. I10. J0.
G1 X30.
G0 Z25.
M30
%
"""


def wait_until(check, timeout: float = 30.0) -> bool:
    """Whether ``check()`` came true within ``timeout`` seconds, asked every 50 ms."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if check():
            return True
        time.sleep(0.05)
    return False
