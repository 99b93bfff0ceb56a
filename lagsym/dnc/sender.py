"""The sender's loop over an open port: pacing to the line rate, XON/XOFF, hardware signals and the accounting.

The sender does its own XON/XOFF: it paces writes to the line rate
(characters per second = baud / bits per character), keeps at most
``LineSettings.overrun_chars`` characters on their way at any moment, and
reads the line for DC3 (XOFF) and DC1 (XON) before every write.  Between
writes it waits on the port (``select``), so a DC3 or DC1 wakes it at once,
and it tops the line up by a quarter of the window at a time: one character
for the default 4, 16 for a window of 64, so that a control with room for
many characters past its DC3 can be fed at 115200 baud by a machine that
wakes the sender late now and then.  The kernel's
IXON is left off on purpose: it would swallow DC3 before lagsym could see it,
and many USB adapters keep sending after it anyway.  A Fanuc accepts only
about 10 characters past DC3 before alarm 087, so the default keeps 4 or
fewer in flight, which leaves room for the DC3 to travel back.

Two counts are kept apart.  What the sender knows for itself: the bytes the
operating system took (written) and the bytes that have *left the port* (by
the line clock and the driver's output queue, plus a short settling time).
What the control holds, which only the control can show.  The way back has no
bound the sender can rely on: an answer waits in the computer's own delivery
(the kernel's input work, a USB adapter's latency timer) for as long as a
loaded machine makes it wait, so when an answer was sent cannot be told from
when it was read, and an answer vouches only for what the protocol proves.
An XOFF (DC3) that follows an XON (DC1) proves that the control's buffer rose
from its XON mark to its XOFF mark in between, so it took at least that span
after its XON; and the sender wrote nothing while it waited for that XON.
So an XOFF that comes after an XON which ended a pause vouches for every
byte written before that pause (if no more arrived after the control's
XOFF than the span between its marks: beyond its headroom a control
alarms).  A block *surely reached the control* only so, or with a watched
carrier or CTS/DSR signal that stayed up.  A control that dies while its
line stays up (a pseudo-terminal relay, a UART that drains into nothing)
takes everything the port sends and answers nothing, so only the answers
count.  A drip feed that the control never answered at all is a fault
(``LineSettings.handshake_expected``).

In a drip feed a block that reached the control is not yet a block that ran:
up to ``LineSettings.buffer_chars`` characters may wait in the control's
buffer, and a reset clears them.  A fault therefore names the last block
that surely reached the control and a ``--start-block`` that is safe either
way: computed from what surely arrived, never from what only left the port,
with the blocks that may have run named as those that may be repeated.

Characters from the control other than DC1 and DC3 (and the harmless DC2,
DC4, NUL and the line ends, spaces and ``%`` that end a punch) are what a
line at the wrong baud rate or character format makes of the control's
DC3: the send stops with a fault that says to check them, since the
control cannot read what is sent either.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from ..errors import TransferError, stopped_by
from .blocks import DC1, DC2, DC3, DC4
from .results import LineFault, TransferProgress, TransferResult
from .settings import CARRIER_LOSS_S, LineSettings

__all__ = ["Sender"]

_POLL_S = 0.002  # longest wait between looks at a port that cannot be waited on, or at CTS/DSR
_WAIT_S = 0.02  # longest wait on a port that wakes the sender when the control speaks
_PROGRESS_S = 0.1
# A byte counts as arrived only this long after the line clock says it left: longer through a network
# serial server, which holds what it has not yet put on its line.
_SETTLE_S = 0.05
_SETTLE_NETWORK_S = 0.25
_HARDWARE = {"rtscts": "cts", "dtrdsr": "dsr"}
_CARRIER_POLL_S = 0.1
# NUL: an idle line or a break; CR, LF, space and %: the tail of a punch or request just before the send.
_HARMLESS = frozenset((DC1, DC2, DC3, DC4, 0x00, 0x0A, 0x0D, 0x20, 0x25))
_UNFLOW_KEPT = 4096  # of those, the most handed on with a punch that stops a send


class Sender:
    """One send over an open port: pacing, flow control, accounting.  Not reused."""

    def __init__(self, line, segments, settings: LineSettings, mode: str, port: str, *,
                 progress: Callable[[TransferProgress], None] | None, log: Callable[[str], None] | None,
                 resumable_from: int = 2, stray: Callable[[bytes], None] | None = None):
        self.line, self.settings, self.mode, self.port = line, settings, mode, port
        self.stray = stray  # given what the control sent that is not flow control (a service keeps it)
        self.unflow = bytearray()  # the harmless characters so far that were no flow control: a punch's DC2 and %
        self.resumable_from = resumable_from  # no resume before this block can approach the part
        self.progress, self.log = progress, log or (lambda _m: None)
        self.data = b"".join(b for _, b in segments)
        self.ends: list[tuple[int, int]] = []  # (end offset, block number) of program blocks
        offset = 0
        for number, chunk in segments:
            offset += len(chunk)
            if number is not None:
                self.ends.append((offset, number))
        self.blocks_total = len(self.ends)
        self.first_block = self.ends[0][1] if self.ends else 1
        self.cps = settings.chars_per_s
        network = "://" in port and not port.startswith("loop://")
        self.settle_s = _SETTLE_NETWORK_S if network else _SETTLE_S
        self.pos = 0  # bytes the operating system took
        self.left = 0  # bytes that have left the port (line clock, output queue, settling time)
        self.known = 0  # bytes that surely reached the control (the answers prove it)
        self.resumed: int | None = None  # bytes written when an XON last ended a pause
        self.answers = 0  # flow-control answers heard from the control (DC1, DC3)
        # A watched carrier or CTS/DSR signal vouches for the control throughout; loop:// echoes what it got.
        self.vouched = bool(settings.carrier != "none" or _HARDWARE.get(settings.flow))
        self.echo = port.lower().startswith("loop://")
        self.echoed = 0
        self.line_free = 0.0  # when the last written byte will have left the line
        self.paused = settings.wait_for_xon
        self.pause_since = 0.0
        self.pause_reason = "the control sent no DC1 (XON) to start the transfer within {t}"
        self.xoffs = 0
        self.max_in_flight = 0
        self.queue_stuck_since: float | None = None
        self.last_queue = 0
        self.queued = 0  # the driver's output queue, read once a turn of the loop
        self.hardware = _HARDWARE.get(settings.flow)
        self.carrier = None if settings.carrier == "none" else settings.carrier
        for sig in (self.hardware, self.carrier):
            if sig and not line.can_sense(sig):
                raise TransferError(f"{port} reports no {sig.upper()} line, which the settings rely on "
                                    f"({'flow ' + settings.flow if sig == self.hardware else 'carrier ' + sig}); "
                                    "use a port with modem lines or change the setting")
        self.carrier_down_since: float | None = None
        self.carrier_checked = -1.0

    def in_flight(self, now: float) -> int:
        """Bytes written but not yet gone from the line, by the line clock and the driver's queue."""
        clock = max(0.0, (self.line_free - now) * self.cps)
        return max(math.ceil(clock), self.queued)

    def unsettled(self, now: float) -> int:
        """Bytes that may not have reached the far side yet: in flight, or left less than the settling time ago."""
        return max(self.in_flight(now), self.in_flight(now - self.settle_s))

    def blocks_within(self, count: int) -> int:
        """How many program blocks end within the first ``count`` bytes."""
        done = 0
        for end, _number in self.ends:
            if end > count:
                break
            done += 1
        return done

    def last_block_within(self, count: int) -> int:
        """The number of the last program block wholly within the first ``count`` bytes."""
        done = self.blocks_within(count)
        return self.ends[done - 1][1] if done else self.first_block - 1

    def last_sure_block(self) -> int:
        return self.last_block_within(self.known)

    def last_left_block(self) -> int:
        return self.last_block_within(self.left)

    def last_sent_block(self) -> int:
        return self.last_block_within(self.pos)

    def report(self, start: float, now: float) -> None:
        if self.progress:
            self.progress(TransferProgress(self.blocks_within(self.left), self.blocks_total, self.left,
                                           len(self.data), now - start, self.paused))

    def last_run_block(self) -> int:
        """The last block that surely ran: surely arrived, with the control's buffer's worth of characters behind it."""
        return self.last_block_within(self.known - (self.settings.buffer_chars if self.mode == "drip" else 0))

    def whereabouts(self) -> str:
        """What surely reached the control, and apart from it what only left the port or the computer."""
        last, left, sent = self.last_sure_block(), self.last_left_block(), self.last_sent_block()
        where = f"block {last} surely reached the control" if last else "no block surely reached the control"
        if left > last:
            where += f"; blocks {last + 1} to {left} left the port, but no answer of the control " \
                     "shows that it holds them"
        if sent > max(left, last):
            where += f" (blocks {max(left, last) + 1} to {sent} were on their way and may have arrived too)"
        return where

    def fault(self, what: str, todo: str) -> LineFault:
        """The fault, with the last block that surely arrived and (drip) the block that resumes safely."""
        last = self.last_sure_block()
        where = self.whereabouts()
        sent = self.last_sent_block()
        repeat = None
        if self.mode == "drip":
            resume = self.last_run_block() + 1
            if resume < self.resumable_from:  # before the program has placed the tool: from the start
                resume = 1
            if resume <= sent:
                repeat = (max(resume, self.first_block), sent)
                if resume <= last:
                    where += (f"; the control's buffer ({self.settings.buffer_chars} characters) may still hold "
                              f"blocks {repeat[0]} to {last} unexecuted")
            hint = (f"{todo}, then resume with --start-block {resume}" if resume > 1
                    else f"{todo}, then send again")
            if repeat:
                hint += (f" (safe whether or not a reset cleared the buffer: blocks {repeat[0]} to {sent} are "
                         "repeated if they had already run)")
            if last and last >= self.ends[-1][1] and repeat is None:
                resume = None
                hint = f"{todo}; every block arrived, only the closing framing may be missing"
            message = f"{what} on {self.port}; {where}; {hint}"
        else:
            resume = None
            message = (f"{what} on {self.port}; {where}; the upload is incomplete: {todo}, "
                       "then send the whole program again")
        self.log(f"fault: {message}")
        return LineFault(message, last, resume, sent, repeat, self.last_left_block())

    def interrupted(self, e: KeyboardInterrupt) -> LineFault:
        """The fault for Ctrl-C, SIGTERM or SIGHUP."""
        what = stopped_by(e)
        return self.fault(what, "when the control is ready")

    def poll(self, now: float) -> None:
        """Read what the control sent; a read that fails is a lost line."""
        incoming = self.line.read(4096)
        # Everything that had left the line before this look has left the port; whether the control took it
        # only its answers show.
        self.left = max(self.left, self.pos - self.unsettled(now))
        if self.vouched:
            self.known = self.left
        if self.echo and incoming:  # loop:// gives back what it took
            self.echoed += len(incoming)
            self.known = max(self.known, min(self.echoed, self.pos))
            self.answers += 1
            return
        for index, byte in enumerate(incoming):
            if byte in (DC1, DC3) and self.settings.flow == "xonxoff":
                self.answers += 1
                if byte == DC3 and self.resumed is not None:
                    # Its buffer rose by the span between its marks since the XON that ended the last pause:
                    # past what had been written before that pause.  When it was sent is not known.
                    self.known = max(self.known, self.resumed)
            elif byte not in _HARMLESS:
                if self.stray is not None:
                    self.stray(bytes(self.unflow[-_UNFLOW_KEPT:]) + incoming[index:])
                raise self.fault(f"the control answered 0x{byte:02X}, a character no control sends during a "
                                 f"transfer (line noise, or a baud rate or format that does not match): check the "
                                 f"baud rate and format ({self.settings.baud} baud, {self.format_text()}) against "
                                 "the control's", "set the same baud rate and format on both sides and clear the "
                                 "control")
            else:
                self.unflow.append(byte)
                if len(self.unflow) > 2 * _UNFLOW_KEPT:
                    del self.unflow[:-_UNFLOW_KEPT]
            if byte == DC3 and self.settings.flow == "xonxoff":
                if not self.paused:
                    self.paused, self.pause_since = True, now
                    self.pause_reason = "the control held XOFF (DC3) for more than {t}"
                    self.xoffs += 1
                    self.max_in_flight = max(self.max_in_flight, self.in_flight(now))
                    self.log(f"XOFF after {self.pos} bytes")
            elif byte == DC1 and self.settings.flow == "xonxoff":
                if self.paused:
                    self.log(f"XON after {now - self.pause_since:.3f} s")
                    self.resumed = self.pos  # nothing was written while paused
                self.paused = False
        if self.hardware:
            ready = self.line.signal(self.hardware)
            reason = f"{self.hardware.upper()} stayed low (control not ready) for more than {{t}}"
            if not ready and not self.paused:
                self.paused, self.pause_since, self.pause_reason = True, now, reason
                self.log(f"{self.hardware.upper()} low after {self.pos} bytes")
            elif ready and self.paused and self.pause_reason == reason:
                self.log(f"{self.hardware.upper()} high after {now - self.pause_since:.3f} s")
                self.paused = False
        if self.carrier and now - self.carrier_checked >= _CARRIER_POLL_S:
            self.carrier_checked = now  # a network port may wait on the server to tell its modem lines
            self.check_carrier(now)

    def format_text(self) -> str:
        s = self.settings
        return f"{s.bytesize}{s.parity[0].upper()}{s.stopbits:g}"

    def check_carrier(self, now: float) -> None:
        """The carrier signal down for :data:`CARRIER_LOSS_S` is a lost line, whatever the port still says."""
        if self.line.signal(self.carrier):
            self.carrier_down_since = None
        elif self.carrier_down_since is None:
            self.carrier_down_since = now
        elif now - self.carrier_down_since >= CARRIER_LOSS_S:
            raise self.fault(f"the control dropped {self.carrier.upper()} (the line or the control went away)",
                             "check the cable and that the control is on and in DNC or READ mode")

    def check_queue(self, now: float) -> None:
        """An output queue that does not shrink means nothing reads the line."""
        queued = self.queued
        if queued and queued >= self.last_queue:
            if self.queue_stuck_since is None:
                self.queue_stuck_since = now
            elif now - self.queue_stuck_since > self.settings.stall_timeout_s:
                raise self.fault(f"nothing read the line for {self.settings.stall_text} "
                                 f"({queued} bytes stuck in the output queue)",
                                 "check the cable and that the control is reading")
        else:
            self.queue_stuck_since = None
        self.last_queue = queued

    def run(self) -> TransferResult:
        """Send everything; Long because the pacing loop reads, checks and writes in one place, in order."""
        start = time.monotonic()
        self.pause_since = start
        self.line_free = start
        last_report = -1.0
        limit = self.settings.overrun_chars
        # Top up once a quarter of the window has left: few wake-ups, and three quarters of it as margin
        # against a late one (the default window of 4 tops up after each character).
        low = limit - max(1, limit // 4)
        total = len(self.data)
        # Waiting on the port returns when the control speaks; where it cannot be waited on, poll.
        longest = _POLL_S if self.hardware else _WAIT_S
        self.log(f"sending {total} bytes, {self.blocks_total} blocks, at {self.cps:.1f} characters/s")
        while True:
            now = time.monotonic()
            self.queued = self.line.out_waiting()
            self.poll(now)
            if now - last_report >= _PROGRESS_S:
                self.report(start, now)
                last_report = now
            self.check_queue(now)
            if self.paused:
                if now - self.pause_since > self.settings.stall_timeout_s:
                    raise self.fault(self.pause_reason.format(t=self.settings.stall_text),
                                     "clear the control (reset any alarm) and put it back in DNC or READ mode")
                self.line.wait(longest)
                continue
            in_flight = self.in_flight(now)
            if self.pos >= total:
                if in_flight == 0:
                    finished = now  # the last byte has left the line
                    break
                self.line.wait(min(longest, in_flight / self.cps))
                continue
            if in_flight > low:
                self.line.wait(min(longest, (in_flight - low) / self.cps))
                continue
            written = self.line.write(self.data[self.pos:self.pos + limit - in_flight])
            # The clock starts when the write has returned, not at the top of the turn: a sender descheduled
            # in between would otherwise count characters as gone that have not yet left.
            self.line_free = max(self.line_free, time.monotonic()) + written / self.cps
            self.pos += written
        # A healthy look once the last byte has settled, so the last block counts as delivered.
        time.sleep(self.settle_s)
        now = time.monotonic()
        self.poll(now)
        self.left = self.pos
        if self.vouched:
            self.known = self.pos
        self.report(start, now)
        elapsed = finished - start
        if self.mode == "drip" and self.settings.handshake_expected and not self.vouched and not self.answers:
            raise self.fault("the control never answered with flow control (no DC3 or DC1) during the whole "
                             f"drip feed of {self.blocks_total} blocks, so nothing shows that it took any of them "
                             "(a control that stopped or died while the line stayed up takes everything and says "
                             "nothing)", "check what the control holds; for a control that never sends XOFF give "
                             "--no-handshake-expected")
        self.log(f"done: {total} bytes in {elapsed:.2f} s, {self.xoffs} XOFF, {self.answers} answers from the "
                 f"control, which show that block {self.last_sure_block()} surely reached it")
        return TransferResult(self.blocks_total, total, elapsed, self.xoffs, self.max_in_flight, self.cps,
                              confirmed=self.vouched, answers=self.answers, last_sure_block=self.last_sure_block(),
                              sure_to_end=self.blocks_within(self.known) == self.blocks_total)
