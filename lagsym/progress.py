"""Progress of long work, told to whoever asked: the library counts, it never draws.

The long-running functions (:func:`~lagsym.toolpath.plan_toolpath`,
:func:`~lagsym.toolpath.rough.rough_toolpath`, :func:`~lagsym.verify.simulate_cut`,
:func:`~lagsym.simulate.simulate`, :func:`~lagsym.job.plan_job`, ...) take
``progress=None`` or a :class:`Progress`: a callable ``progress(done, total, stage)``.
``stage`` names the work (``"dropping the tool"``), ``done`` counts it and
never decreases within a stage, ``total`` is what the stage will count or None
while that is not known.  Each stage ends with a call whose ``done`` is its
``total`` (for an unknown total, the last call gives ``done`` as the total).
Calls come at coarse points, a few hundred a stage at most, never one a point;
a stage that spreads its work over threads makes its calls one at a time.

>>> seen = []
>>> t = Tally(lambda done, total, stage: seen.append((done, total, stage)), "rows", 3)
>>> for _ in range(3):
...     t.add(1)
>>> t.finish()
>>> seen[-1]
(3, 3, 'rows')
"""

from __future__ import annotations

import threading
from typing import Callable, Protocol

__all__ = ["Progress", "Tally", "Counting", "no_progress", "prefixed", "MOST_CALLS", "PIECE", "COMPILING", "ANNOUNCED"]

MOST_CALLS = 200  # reports a stage with a known total makes at most, besides its last
# A stage that is a wait, not work: a listener that draws no bars still says it began (a first run after an
# install compiles the cutter kernel, which keeps the command silent for a while).
COMPILING = "compiling the cutter kernel, once after an install or upgrade"
ANNOUNCED = frozenset({COMPILING})
PIECE = 1 << 14  # items of a batch done between two reports: positions of a drop-cutter (a multiple of its chunk)


class Progress(Protocol):
    """What a long-running function calls as its work advances."""

    def __call__(self, done: int, total: int | None, stage: str) -> None: ...


def no_progress(done: int, total: int | None, stage: str) -> None:
    """The :class:`Progress` that listens to nothing."""


class Tally:
    """The count of one stage's work, reported to ``progress`` (or to nothing if it is None).

    With a known ``total`` a report goes out only when the count has moved on
    by a :data:`MOST_CALLS`-th of it since the last, so a caller may add
    often; :meth:`finish` always reports.  Adding is safe from several threads.
    """

    def __init__(self, progress: Progress | None, stage: str, total: int | None = None):
        self.progress, self.stage, self.total = progress, stage, None if total is None else int(total)
        self.done, self._told = 0, -1
        self._step = 1 if total is None else max(int(total) // MOST_CALLS, 1)
        self._lock = threading.Lock()

    @property
    def live(self) -> bool:
        """Whether anyone listens."""
        return self.progress is not None

    def start(self) -> None:
        """Report the stage with nothing done yet, so it shows before its first piece of work ends."""
        if self.progress is not None:
            self.progress(0, self.total, self.stage)
            self._told = 0

    def add(self, n: int) -> None:
        """Count ``n`` more done, and report if the count has moved far enough."""
        if self.progress is None:
            return
        with self._lock:
            self.done += int(n)
            if self.done - self._told >= self._step and (self.total is None or self.done < self.total):
                self._told = self.done
                self.progress(self.done, self.total, self.stage)

    def finish(self) -> None:
        """The stage's last report: all of a known total done, or the count reached as the total."""
        if self.progress is None:
            return
        with self._lock:
            end = self.done if self.total is None else self.total
            self.done = self._told = end
            self.progress(end, end, self.stage)

    def __enter__(self) -> Tally:
        self.start()
        return self

    def __exit__(self, kind, value, tb) -> None:
        if kind is None:
            self.finish()

    def pieces(self, f: Callable, arrays, piece: int = PIECE):
        """``f`` over the arrays ``piece`` items at a time, counted; the results joined as one array.

        Without a listener ``f`` gets the whole arrays in one call.  ``f``
        must treat each item on its own, so the pieces give what one call
        would.
        """
        import numpy as np

        n = len(arrays[0])
        if self.progress is None or n <= piece:
            out = f(*arrays)
            self.add(n)
            return out
        outs = []
        for lo in range(0, n, piece):
            outs.append(f(*(a[lo:lo + piece] for a in arrays)))
            self.add(len(outs[-1]))
        return np.concatenate(outs)

    def whole(self, f: Callable, arrays, piece: int = PIECE):
        """The stage from start to finish: :meth:`pieces` of ``f`` over ``arrays``."""
        with self:
            return self.pieces(f, arrays, piece)

    def counting(self, f: Callable, piece: int = PIECE) -> Counting:
        """``f`` (called with arrays and keywords) with every call counted :meth:`pieces` at a time."""
        return Counting(f, self, piece) if self.live else f


class Counting:
    """A function of arrays whose calls are counted in a :class:`Tally`; its other attributes are ``f``'s."""

    def __init__(self, f: Callable, tally: Tally, piece: int = PIECE):
        self.f, self.tally, self.piece = f, tally, piece

    def __call__(self, *arrays, **kw):
        return self.tally.pieces(lambda *a: self.f(*a, **kw), arrays, self.piece)

    def __getattr__(self, name: str):
        return getattr(self.f, name)


def prefixed(progress: Progress | None, prefix: str) -> Progress | None:
    """``progress`` with ``prefix: `` before every stage (None stays None)."""
    if progress is None:
        return None
    return lambda done, total, stage: progress(done, total, f"{prefix}: {stage}")
