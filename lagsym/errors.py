"""The lagsym error family.

Every error lagsym raises on purpose derives from :class:`LagsymError` and from
the matching built-in exception, so callers may catch either.  Each class
carries the exit status the command line uses for it: 2 for bad input or a bad
request, 3 for hardware and line faults.
"""

from __future__ import annotations

import enum
import signal


class ExitStatus(enum.IntEnum):
    """Exit statuses of the ``lagsym`` command."""

    OK = 0
    WARNING = 1  # a check found something worth a look (``--strict``)
    BAD_INPUT = 2  # bad file, bad value, bad option
    LINE_FAULT = 3  # hardware or serial line fault; the message says what to do next
    INTERRUPTED = 130


class LagsymError(Exception):
    """Base class of every error lagsym raises on purpose."""

    exit_status: ExitStatus = ExitStatus.BAD_INPUT


class InputError(LagsymError, ValueError):
    """A file or value given to lagsym is unusable; the message names it."""


class OutputError(LagsymError, OSError):
    """A result cannot be written where it was asked for (a full disk, a folder without write permission)."""


class LogLost(OutputError):
    """A transfer ran but its event log could not be written to the end (a full disk): exit 3, a fault of the run."""

    exit_status = ExitStatus.LINE_FAULT


class GridError(InputError):
    """Control points that do not form the rectangular grid the method needs."""


class ConditioningError(InputError):
    """A surface that amplifies errors in its points beyond the limit, asked to become something physical."""


class FormulaError(InputError):
    """A reference formula that does not parse under the strict grammar."""


class ToolpathError(LagsymError, ValueError):
    """Toolpath settings that cannot give a safe path."""


class ProgramError(LagsymError, ValueError):
    """A part program that a control would refuse (an alarm), or that cannot be written."""


class RenderError(LagsymError, RuntimeError):
    """Pictures cannot be drawn here (no display and no offscreen renderer); the message says what to install."""


class Terminated(KeyboardInterrupt):
    """The process was asked to stop by a signal (SIGTERM, SIGHUP): handled as Ctrl-C is, then exit 128 + signal."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def stopped_by(e: KeyboardInterrupt) -> str:
    """``"stopped by SIGTERM"`` (the signal's name) for :class:`Terminated`, ``"stopped by the user"`` for Ctrl-C."""
    return f"stopped by {signal.Signals(e.signum).name}" if isinstance(e, Terminated) else "stopped by the user"


class TransferError(LagsymError, OSError):
    """A fault on the serial line or in the machine at the other end."""

    exit_status = ExitStatus.LINE_FAULT
