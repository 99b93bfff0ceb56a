"""Both cores for a large evaluation: blocks of the points or grid rows, taken in turn by one thread a core.

NumPy lets go of the interpreter lock inside its array loops, and the
compiled kernels run without it, so threads working on separate parts of one
output run side by side.  Each part or block is computed exactly as it would
be alone (the same arithmetic), so the values are the same bit for bit
whatever the threads.  :func:`run_blocks` hands out blocks as threads come
free; :func:`run_parts` runs given parts, one a thread.  Below
:data:`THREAD_POINTS` values a thread the threads would cost more than
they save, and one thread does all.

The other threads are the helpers of a :class:`HelperPool`, kept from one
call to the next: starting a thread blocks the caller until the new thread
runs, as long as a good part of a large sample, while posting a part to a
parked helper returns at once and the caller goes to work
(``benchmarks/bench_threads.py`` measures both).  A pool belongs to whoever
made it: an :class:`~.engine.Engine` holds one, and :meth:`HelperPool.close`
ends its helpers.  Where no pool is given, :data:`PROCESS_POOL` serves: its
helpers live as long as the process.  A pool made with ``keep=False`` ends
its helpers as each call returns, and one made with ``max_threads=1`` never
starts any: the values are the same bit for bit in every case.

Between calls a helper waits on a lock of its own, holding no other, runs
no work and keeps no reference to the call's work or output: when a call
returns nothing of it is left running or kept alive.  The helpers are
low-level threads (:mod:`_thread`), not counted by
:func:`threading.active_count`, so a plan still forks its worker processes
(:mod:`lagsym.toolpath.workers`, which forks only while no other thread
runs); in a forked process every pool is empty and starts helpers of its own
when it needs them.  One caller at a time uses a pool's helpers; a call made
while another thread's call has them runs all its parts itself.
"""

from __future__ import annotations

import _thread
import os
import threading
import weakref

__all__ = ["THREAD_POINTS", "MAX_THREADS", "TAKE_VALUES", "HelperPool", "PROCESS_POOL", "available_cores",
           "thread_count", "parts", "run_parts", "run_blocks", "block_items"]

THREAD_POINTS = 1 << 18
"""Values a thread computes at least: below twice this, one thread does all."""

MAX_THREADS = 4
"""Threads at most, whatever the cores: beyond a few, memory speed is the limit."""

TAKE_VALUES = 1 << 17
"""Values a thread of :func:`run_blocks` takes at a time (8 blocks of a 2000 x 2000 grid a thread)."""


def available_cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on every platform
        return os.cpu_count() or 1


def thread_count(n: int, per_item: int = 1) -> int:
    """Threads for ``n`` items of ``per_item`` values: one a core, each with :data:`THREAD_POINTS` values or more."""
    return min(available_cores(), MAX_THREADS, max(1, n * per_item // THREAD_POINTS))


def parts(n: int, per_item: int = 1, align: int = 1) -> list[tuple[int, int]]:
    """``n`` items (of ``per_item`` values each) cut into contiguous ``(start, stop)`` parts, one per thread.

    A part starts at a multiple of ``align`` (the block size of the work), so
    every part's blocks are those of the whole.
    """
    threads = thread_count(n, per_item)
    if threads < 2:
        return [(0, n)]
    size = -(-n // threads)
    size = -(-size // align) * align
    return [(lo, min(lo + size, n)) for lo in range(0, n, size)]


class _Helper:
    """A thread kept for later calls: it runs one posted part at a time and waits on its own lock in between."""

    def __init__(self):
        self._go, self._done = _thread.allocate_lock(), _thread.allocate_lock()
        self._go.acquire()
        self._done.acquire()
        self._part = None
        self.alive = True
        _thread.start_new_thread(self._loop, ())

    def _loop(self) -> None:
        try:
            while True:
                self._go.acquire()
                part, self._part = self._part, None
                if part is None:  # ended by its pool
                    return
                try:
                    part()  # records its own errors (run_parts)
                finally:
                    part = None  # nothing of the call (its output above all) is kept until the next
                    self._done.release()
        finally:
            self.alive = False

    def post(self, part) -> None:
        """Run ``part()`` in this thread."""
        self._part = part
        self._go.release()

    def wait(self) -> None:
        """Wait until the part posted last has ended."""
        self._done.acquire()

    def end(self) -> None:
        """Let the thread return once it is parked (at once if it is parked now)."""
        self.post(None)


_POOLS: weakref.WeakSet = weakref.WeakSet()  # every pool, emptied in a forked child


class HelperPool:
    """Helper threads kept between the calls that share work among threads, owned by whoever made the pool.

    Parameters
    ----------
    max_threads : int
        Threads a call uses at most, the calling thread included (and never
        more than :func:`thread_count` allows); 1 runs every call in the
        calling thread alone, starting no helper.
    keep : bool
        Keep the helpers parked for the next call (the default); False ends
        them as each call returns.

    The values a call computes are the same whatever the pool.  Use the
    pool as a context manager, or call :meth:`close`, to end its helpers.

    Examples
    --------
    >>> with HelperPool() as pool:
    ...     seen = []
    ...     pool.run_parts(lambda lo, hi: seen.append(lo), [(0, 1), (1, 2)])
    >>> sorted(seen), pool.helpers
    ([0, 1], 0)
    """

    def __init__(self, max_threads: int = MAX_THREADS, keep: bool = True):
        if isinstance(max_threads, bool) or not isinstance(max_threads, int) or max_threads < 1:
            raise ValueError(f"max_threads = {max_threads!r} should be a whole number of threads, 1 or more")
        self.max_threads = max_threads
        self.keep = bool(keep)
        self._lock = _thread.allocate_lock()  # held by the one caller using the helpers
        self._helpers: list[_Helper] = []
        _POOLS.add(self)

    def __repr__(self) -> str:
        return f"HelperPool(max_threads={self.max_threads}, keep={self.keep})"

    def __enter__(self) -> HelperPool:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @property
    def helpers(self) -> int:
        """Helper threads parked now."""
        return sum(h.alive for h in self._helpers)

    def close(self) -> None:
        """End the parked helpers; a later call starts new ones.  A call running now keeps its helpers."""
        if not self._lock.acquire(blocking=False):
            return
        try:
            self._end_helpers()
        finally:
            self._lock.release()

    def _end_helpers(self) -> None:
        for h in self._helpers:
            h.end()
        self._helpers = []

    def _forget(self) -> None:
        """In a forked child: the helper threads did not come along."""
        self._lock, self._helpers = _thread.allocate_lock(), []

    def threads(self, n: int, per_item: int = 1) -> int:
        """Threads a call of ``n`` items of ``per_item`` values uses: :func:`thread_count`, at most ``max_threads``."""
        return min(self.max_threads, thread_count(n, per_item))

    def run_parts(self, work, cuts: list[tuple[int, int]], stop: list | None = None) -> None:
        """``work(start, stop)`` for every part, the first in the calling thread and each other in a helper of its own.

        The first error raised in any part is raised again once all have
        ended.  Where another thread's call has the helpers, or the pool
        allows one thread, this thread runs the parts one after another.
        Interrupted while it waits for the helpers, the call appends to
        ``stop`` (so a part that checks it ends early), leaves the helpers to
        end their parts, starts fresh helpers next time, and raises.
        """
        if len(cuts) == 1:
            work(*cuts[0])
            return
        if self.max_threads < 2 or not self._lock.acquire(blocking=False):
            for cut in cuts:
                work(*cut)
            return
        errors: list[BaseException] = []

        def part(lo, hi):
            try:
                work(lo, hi)
            except BaseException as e:  # raised again in the calling thread
                errors.append(e)

        try:
            helpers = [h for h in self._helpers if h.alive]
            while len(helpers) < len(cuts) - 1:
                helpers.append(_Helper())
            self._helpers = helpers
            busy = helpers[:len(cuts) - 1]
            for helper, (lo, hi) in zip(busy, cuts[1:]):
                helper.post(lambda lo=lo, hi=hi: part(lo, hi))
            part(*cuts[0])
            for helper in busy:
                helper.wait()
            if not self.keep:
                self._end_helpers()
        except BaseException:  # interrupted while the helpers run: they end their parts and are not used again
            if stop is not None:
                stop.append(True)
            self._helpers = []
            raise
        finally:
            self._lock.release()
        if errors:
            raise errors[0]

    def run_blocks(self, work, n: int, block: int, per_item: int = 1) -> None:
        """``work(start, stop)`` over ``n`` items in blocks of ``block``, each thread taking the next when it is done.

        The threads :meth:`threads` allows, as :meth:`run_parts` runs them;
        where fixed parts would leave the calling thread waiting for a helper
        woken late or slowed by the machine, here it takes fewer blocks.
        Each block is computed as it would be alone, so the values do not
        depend on which thread computed which.  After an error no thread
        takes another block.
        """
        count = self.threads(n, per_item)
        if count < 2:
            work(0, n)
            return
        lock = threading.Lock()
        starts = iter(range(0, n, block))
        failed = []

        def take(_lo, _hi):
            while not failed:
                with lock:
                    lo = next(starts, None)
                if lo is None:
                    return
                try:
                    work(lo, min(lo + block, n))
                except BaseException:
                    failed.append(True)
                    raise

        self.run_parts(take, [(0, n)] * count, failed)


PROCESS_POOL = HelperPool()
"""The pool of calls given none: its helpers are started on the first large call and live as long as the process."""


def _forget_helpers() -> None:
    for pool in list(_POOLS):
        pool._forget()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_helpers)


def run_parts(work, cuts: list[tuple[int, int]], stop: list | None = None, pool: HelperPool | None = None) -> None:
    """:meth:`HelperPool.run_parts` of ``pool`` (:data:`PROCESS_POOL` by default)."""
    (PROCESS_POOL if pool is None else pool).run_parts(work, cuts, stop)


def block_items(per_item: int, align: int = 1) -> int:
    """Items of ``per_item`` values in a block of about :data:`TAKE_VALUES` values: a multiple of ``align``."""
    return max(align, TAKE_VALUES // max(per_item, 1) // align * align)


def run_blocks(work, n: int, block: int, per_item: int = 1, pool: HelperPool | None = None) -> None:
    """:meth:`HelperPool.run_blocks` of ``pool`` (:data:`PROCESS_POOL` by default)."""
    (PROCESS_POOL if pool is None else pool).run_blocks(work, n, block, per_item)
