"""Which engine runs a large batch, NumPy or the compiled kernels of :mod:`.compiled`: an :class:`Engine` policy.

Both engines give the same bits, so the choice changes how long a batch
takes, never its values.  Loading Numba and the cached kernels takes about
:data:`LOAD_SECONDS`, once per process, and pays only where many large
batches follow: a process that samples one large grid (a command writing a
file) never gains by loading them; one that evaluates many (a notebook, a
benchmark, a search) gains a lot.  Hence the ``"auto"`` policy: a batch of
:data:`COMPILED_POINTS` values or more runs in NumPy until such batches
have taken, together, :data:`LOAD_SECONDS` under that :class:`Engine`, and
compiled from then on.  Whatever the number of batches, the total then stays
within about twice the best one could have chosen knowing it beforehand
(the rule of renting skis until the rent has cost the price of buying).
Where the kernels are loaded already (:func:`.surface.load_compiled`, or an
earlier batch), large batches run compiled at once.  Smaller batches always
run in NumPy.  ``"numpy"`` never loads the kernels (the policy turned off);
``"compiled"`` runs every large batch compiled from the first.

An :class:`Engine` counts its own time, and holds the
:class:`~.threads.HelperPool` its batches share among threads.  The
evaluator's functions take one as ``engine=``; without it they use the
engine of the current context (:func:`current_engine`), which is
:data:`PROCESS_ENGINE` unless a caller chose another with :func:`use_engine`:

>>> with use_engine(Engine("numpy")) as engine:
...     current_engine() is engine, engine.use_compiled(10**7)
(True, False)
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from ..values import choice
from .threads import PROCESS_POOL, HelperPool

__all__ = ["COMPILED_POINTS", "LOAD_SECONDS", "POLICIES", "Engine", "PROCESS_ENGINE", "current_engine",
           "use_engine", "compiled_loaded", "use_compiled", "choose_engine"]

COMPILED_POINTS = 1 << 18
"""Values (scattered points or grid nodes) from which a batch may run compiled."""

LOAD_SECONDS = 0.5
"""About what loading Numba and the cached kernels takes (``benchmarks/bench_sampling.py`` reports it)."""

POLICIES = ("auto", "numpy", "compiled")
"""The choices of :class:`Engine`: rent then buy, NumPy always, compiled always (for large batches)."""

_COMPILED = __name__.rsplit(".", 1)[0] + ".compiled"


def compiled_loaded() -> bool:
    """Whether this process has loaded the compiled kernels."""
    return _COMPILED in sys.modules


class Engine:
    """How large batches run: which engine (``policy``, one of :data:`POLICIES`) and which helper threads.

    Parameters
    ----------
    policy : str
        ``"auto"`` (the default): large batches in NumPy until they have
        taken ``load_seconds`` under this engine, or the kernels are loaded,
        then compiled; ``"numpy"``: never compiled; ``"compiled"``: every
        large batch compiled.
    load_seconds : float
        The time ``"auto"`` spends in NumPy before it loads the kernels.
    pool : HelperPool, optional
        The threads large batches are shared among; :data:`.threads.PROCESS_POOL` by default.

    The values are the same bit for bit whatever the engine.
    """

    def __init__(self, policy: str = "auto", *, load_seconds: float = LOAD_SECONDS, pool: HelperPool | None = None):
        self.policy = choice(policy, POLICIES, "engine policy")
        self.load_seconds = float(load_seconds)
        self.pool = PROCESS_POOL if pool is None else pool
        self._lock = threading.Lock()
        self._spent = 0.0

    def __repr__(self) -> str:
        return f"Engine({self.policy!r}, load_seconds={self.load_seconds}, spent={self._spent:.3f})"

    @property
    def spent(self) -> float:
        """Seconds this engine's large batches have taken in NumPy."""
        return self._spent

    def use_compiled(self, values: int) -> bool:
        """Whether a batch of ``values`` runs compiled: large, and the policy says so."""
        if values < COMPILED_POINTS or self.policy == "numpy":
            return False
        return self.policy == "compiled" or compiled_loaded() or self._spent >= self.load_seconds

    def record(self, values: int, seconds: float) -> None:
        """Count ``seconds`` a batch of ``values`` took in NumPy towards :attr:`load_seconds` (large batches only)."""
        if values >= COMPILED_POINTS:
            with self._lock:
                self._spent += seconds

    @contextmanager
    def choose(self, values: int) -> Iterator[bool]:
        """Whether a batch of ``values`` runs compiled (:meth:`use_compiled`); the time it takes in NumPy is counted."""
        compiled = self.use_compiled(values)
        start = time.perf_counter()
        yield compiled
        if not compiled:
            self.record(values, time.perf_counter() - start)


PROCESS_ENGINE = Engine()
"""The engine of every context in which no other was chosen: ``"auto"``, its time counted for the whole process."""

_CURRENT: ContextVar[Engine] = ContextVar("lagsym_engine", default=PROCESS_ENGINE)


def current_engine() -> Engine:
    """The engine of this context: the innermost :func:`use_engine`'s, else :data:`PROCESS_ENGINE`."""
    return _CURRENT.get()


@contextmanager
def use_engine(engine: Engine) -> Iterator[Engine]:
    """Run the evaluations inside the ``with`` block (in this thread or task) under ``engine``.

    ``with use_engine(Engine("numpy")):`` turns the compiled kernels off for
    a block of code that takes no ``engine=`` of its own (a command, a figure).
    """
    if not isinstance(engine, Engine):
        raise TypeError(f"engine = {engine!r} is not an Engine")
    token = _CURRENT.set(engine)
    try:
        yield engine
    finally:
        _CURRENT.reset(token)


def use_compiled(values: int) -> bool:
    """:meth:`Engine.use_compiled` of the :func:`current_engine`."""
    return _CURRENT.get().use_compiled(values)


def choose_engine(values: int):
    """:meth:`Engine.choose` of the :func:`current_engine`."""
    return _CURRENT.get().choose(values)
