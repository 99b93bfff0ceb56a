"""Which engine runs a large batch: NumPy, or the compiled kernels of :mod:`.compiled` once they pay for their loading.

Both engines give the same bits, so the choice changes how long a batch
takes, never its values.  Loading Numba and the cached kernels takes about
half a second, once per process: as long as NumPy takes for about eight
batches of 10**6 scattered points or fifty grids of 2000 x 2000, each of
which then takes a few milliseconds compiled.  A process that samples one
large grid (a command writing a file) never gains by loading them; one that
evaluates many (a notebook, a benchmark, a search) gains a lot.  So a
batch of :data:`COMPILED_POINTS` values or more runs in NumPy until such
batches have taken, together, :data:`LOAD_SECONDS`, and compiled from then
on: whatever the number of batches, the total stays within about twice the
best one could have chosen knowing it beforehand (the rule of renting skis
until the rent has cost the price of buying).  Where the kernels are loaded
already (:func:`load_compiled`, or an earlier batch), large batches run
compiled at once.  Smaller batches always run in NumPy.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["COMPILED_POINTS", "LOAD_SECONDS", "compiled_loaded", "use_compiled", "spent_in_numpy", "choose_engine"]

COMPILED_POINTS = 1 << 18
"""Values (scattered points or grid nodes) from which a batch may run compiled."""

LOAD_SECONDS = 0.5
"""About what loading Numba and the cached kernels takes (0.5-0.6 s on the benchmark machine)."""

_COMPILED = __name__.rsplit(".", 1)[0] + ".compiled"
_lock = threading.Lock()
_spent = [0.0]  # seconds this process has spent on large batches in NumPy


def compiled_loaded() -> bool:
    """Whether this process has loaded the compiled kernels."""
    return _COMPILED in sys.modules


def use_compiled(values: int) -> bool:
    """Whether a batch of ``values`` runs compiled: large, and the kernels loaded or paid for."""
    return values >= COMPILED_POINTS and (compiled_loaded() or _spent[0] >= LOAD_SECONDS)


def spent_in_numpy(values: int, seconds: float) -> None:
    """Count ``seconds`` a batch of ``values`` took in NumPy towards :data:`LOAD_SECONDS` (large batches only)."""
    if values >= COMPILED_POINTS:
        with _lock:
            _spent[0] += seconds


@contextmanager
def choose_engine(values: int) -> Iterator[bool]:
    """Whether a batch of ``values`` runs compiled (:func:`use_compiled`); the time it takes in NumPy is counted."""
    compiled = use_compiled(values)
    start = time.perf_counter()
    yield compiled
    if not compiled:
        spent_in_numpy(values, time.perf_counter() - start)
