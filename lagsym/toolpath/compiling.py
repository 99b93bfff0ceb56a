"""Numba's compile events watched: a first run after an install says it compiles rather than seeming to hang.

Numba compiles the cutter kernel (:mod:`.kernel`) on first use and keeps the
machine code in its cache; later processes load it in a fraction of a
second.  Only a compilation starts :func:`told_if_compiling`'s timer, so a
load from the cache tells nothing.
"""

from __future__ import annotations

import contextlib
import threading

from numba.core import event

__all__ = ["told_if_compiling"]


class _CompileWatch(event.Listener):
    """Starts a timer at the first compilation it hears of: Numba's cache held no machine code for the kernel."""

    def __init__(self, tell, after: float):
        self.tell, self.after, self.timer = tell, after, None

    def on_start(self, _event) -> None:
        if self.timer is None:
            self.timer = threading.Timer(self.after, self.tell)
            self.timer.daemon = True
            self.timer.start()

    def on_end(self, _event) -> None:
        pass


@contextlib.contextmanager
def told_if_compiling(tell, after: float = 2.0):
    """Call ``tell()`` once if, inside the block, Numba compiles and the block has not ended ``after`` seconds later.

    A first run after an install (or after the cache beside this file was
    removed) compiles the kernel, which takes far longer than loading it: the
    caller says so rather than seeming to hang.  A load from the cache
    compiles nothing and tells nothing.  The timer is stopped and joined
    before the block is left, so no thread outlives it (the planner forks its
    workers only while no other thread runs).
    """
    watch = _CompileWatch(tell, after)
    try:
        with event.install_listener("numba:compile", watch):
            yield
    finally:
        if watch.timer is not None:
            watch.timer.cancel()
            watch.timer.join()
