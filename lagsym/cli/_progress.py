"""The progress bars of the long commands (``toolpath``, ``rough``, ``job``, ``verify``, ``simulate``).

The library reports its work to a :class:`lagsym.progress.Progress` callable;
this module turns the reports into rich bars on standard error, one line a
stage, and only when standard error is a terminal that can draw them (not
``TERM=dumb``).  Piped or redirected, nothing is drawn and rich is not even
imported, and standard output is never touched; standard error gets one line
only when a stage that is a wait begins (compiling the cutter kernel after an
install), so a silent command is never mistaken for a hung one.  The bars are transient: when the work ends they are
erased and the command's own lines follow.  ``NO_COLOR`` leaves them plain
(rich honours it).
"""

from __future__ import annotations

import contextlib
import os

from ..progress import ANNOUNCED
from ._lines import say

__all__ = ["progress_bar", "draws_bars"]


def draws_bars(err) -> bool:
    """Whether bars go to the stream ``err``: a terminal, and not a dumb one."""
    isatty = getattr(err, "isatty", None)
    try:
        terminal = bool(isatty and isatty())
    except (OSError, ValueError):  # a closed or detached stream
        terminal = False
    return terminal and os.environ.get("TERM", "") != "dumb"


def _announcer(err):
    """Where no bar is drawn, the stages that are a wait (:data:`~lagsym.progress.ANNOUNCED`) still get one line
    when they begin, so a silent command is never a hung one; everything else is left unsaid."""
    said = set()

    def announce(done: int, total: int | None, stage: str) -> None:
        if stage.rpartition(": ")[2] in ANNOUNCED and stage not in said:
            said.add(stage)
            say(err, f"lagsym: {stage} ...")
            err.flush()

    return announce


@contextlib.contextmanager
def progress_bar(err):
    """A :class:`~lagsym.progress.Progress` drawing on ``err`` while the block runs, or None where nothing is drawn."""
    if not draws_bars(err):
        yield _announcer(err)
        return
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TaskProgressColumn, TextColumn, TimeElapsedColumn

    columns = (TextColumn("{task.description}"), BarColumn(), TaskProgressColumn(), MofNCompleteColumn(),
               TimeElapsedColumn())
    # stdout and stderr are left alone: a program written to standard output must reach it unchanged.  Drawn
    # on each report, not by a refresh thread: the toolpath planner forks its workers only while no other
    # thread runs, and a bar must not cost it the other core.
    with Progress(*columns, console=Console(file=err), transient=True, redirect_stdout=False,
                  redirect_stderr=False, auto_refresh=False) as bars:
        tasks = {}

        def update(done: int, total: int | None, stage: str) -> None:
            if stage not in tasks:
                tasks[stage] = bars.add_task(stage, total=total)
            bars.update(tasks[stage], completed=done, total=total)
            bars.refresh()

        yield update
