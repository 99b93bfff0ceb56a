"""The control's alarms: :class:`ControlAlarm` for the caller, :class:`BlockAlarm` inside one block."""

from __future__ import annotations

from ..errors import ProgramError

__all__ = ["ControlAlarm", "BlockAlarm", "alarm_at", "feed_zero"]


class ControlAlarm(ProgramError):
    """The control would stop here: ``alarm`` names the condition, ``line`` the block (1-based)."""

    def __init__(self, alarm: str, message: str, line: int = 0, block: str = ""):
        self.alarm, self.line, self.block = alarm, line, block
        where = f" at line {line}: {block.strip()[:60]!r}" if line else ""
        super().__init__(f"alarm {alarm}: {message}{where}")


class BlockAlarm(Exception):
    """An alarm found while reading or running one block, before the line is known.

    The reader and the executor catch it and raise :class:`ControlAlarm`
    with the line and text of the block.
    """

    def __init__(self, alarm: str, message: str):
        super().__init__(alarm, message)
        self.alarm, self.message = alarm, message


def alarm_at(error: Exception, block) -> ControlAlarm:
    """The :class:`ControlAlarm` for a :class:`BlockAlarm` or an arithmetic error raised by ``block``."""
    if isinstance(error, BlockAlarm):
        return ControlAlarm(error.alarm, error.message, block.line, block.text)
    return ControlAlarm("111", f"calculated data out of range ({type(error).__name__})", block.line, block.text)


def feed_zero(feed) -> BlockAlarm:
    """The alarm of a feed move with no feed: ``F0``, or no ``F`` since the start (a Fanuc's PS0011; LinuxCNC
    refuses it too)."""
    return BlockAlarm("11", f"a G01 move at feed {feed:g}: no F word since the start, or F0 (the control stops with "
                            "'feed zero')")
