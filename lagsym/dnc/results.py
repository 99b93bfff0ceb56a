"""What a transfer reports: its progress, its result, and the fault that ends it."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import TransferError

__all__ = ["TransferProgress", "TransferResult", "LineFault"]


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
    """A finished transfer: what went, how long it took, how often the control said XOFF.

    ``confirmed`` is True when a hardware signal (the carrier, or CTS/DSR
    flow control) showed the control on the line throughout; over XON/XOFF
    alone only the control's answers show what it took: ``answers`` counts
    them (DC3 and DC1) and ``last_sure_block`` is the last block they prove
    it took (see :mod:`lagsym.dnc.sender`); ``sure_to_end`` says they prove
    it took every block.
    """

    blocks: int
    bytes: int
    elapsed_s: float
    xoff_count: int
    max_in_flight_at_xoff: int
    chars_per_s: float
    confirmed: bool = False
    answers: int = 0
    last_sure_block: int = 0
    sure_to_end: bool = False

    @property
    def throughput(self) -> float:
        """Bytes per second over the line rate (1.0: the line never idled)."""
        return self.bytes / self.elapsed_s / self.chars_per_s if self.elapsed_s > 0 else 0.0


class LineFault(TransferError):
    """A stall or a lost line during a send; says which block surely arrived and how to resume.

    Attributes
    ----------
    last_block : int
        The last program block that surely reached the control (0: none): it
        had left the port when the control last answered, or a watched signal
        vouched for the control.
    start_block : int or None
        The ``--start-block`` that resumes a drip feed, or None for an upload
        (which must be sent again whole).
    last_sent_block : int
        The last block written whole: blocks after ``last_block`` up to this
        one were on their way and may have arrived too.
    last_left_block : int
        The last block that had left the port (by the line clock and the
        output queue): what the computer knows it sent, not what the control
        holds.
    may_repeat : tuple of int or None
        ``(first, last)``: the blocks from ``start_block`` that had arrived
        but may not have run (they waited in the control's buffer), so a
        resume repeats them if they had run; None when there are none.
    """

    def __init__(self, message: str, last_block: int, start_block: int | None, last_sent_block: int | None = None,
                 may_repeat: tuple[int, int] | None = None, last_left_block: int | None = None):
        super().__init__(message)
        self.last_left_block = last_block if last_left_block is None else last_left_block
        self.may_repeat = may_repeat
        self.last_block = last_block
        self.start_block = start_block
        self.last_sent_block = last_block if last_sent_block is None else last_sent_block
