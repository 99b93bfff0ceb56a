"""Both cores for a large evaluation: blocks of the points or grid rows, taken in turn by one thread a core.

NumPy lets go of the interpreter lock inside its array loops, and the
compiled kernels run without it, so threads working on separate parts of one
output run side by side.  Each part or block is computed exactly as it would
be alone (the same arithmetic), so the values are the same bit for bit
whatever the threads.  :func:`run_blocks` hands out blocks as threads come
free; :func:`run_parts` runs given parts, one a thread.  Below
:data:`THREAD_POINTS` values a thread the threads would cost more than
they save, and one thread does all.  The threads end with the call: none is
left running (a plan forks its worker processes only while no other thread
runs, :mod:`lagsym.toolpath.workers`).
"""

from __future__ import annotations

import os
import threading

__all__ = ["THREAD_POINTS", "MAX_THREADS", "TAKE_VALUES", "available_cores", "thread_count", "parts", "run_parts",
           "run_blocks", "block_items"]

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


def run_parts(work, cuts: list[tuple[int, int]]) -> None:
    """``work(start, stop)`` for every part, the first in the calling thread and each other in a thread of its own.

    Plain threads, started and joined here: a pool's set-up cost about a
    third of a millisecond on the benchmark machine, a sixth of a
    2000 x 2000 sample.  The first error raised in any part is raised again
    once all have ended.
    """
    if len(cuts) == 1:
        work(*cuts[0])
        return
    errors: list[BaseException] = []

    def run(lo, hi):
        try:
            work(lo, hi)
        except BaseException as e:  # raised again in the calling thread
            errors.append(e)

    threads = [threading.Thread(target=run, args=cut, daemon=True) for cut in cuts[1:]]
    for t in threads:
        t.start()
    try:
        work(*cuts[0])
    finally:
        for t in threads:
            t.join()
    if errors:
        raise errors[0]


def block_items(per_item: int, align: int = 1) -> int:
    """Items of ``per_item`` values in a block of about :data:`TAKE_VALUES` values: a multiple of ``align``."""
    return max(align, TAKE_VALUES // max(per_item, 1) // align * align)


def run_blocks(work, n: int, block: int, per_item: int = 1) -> None:
    """``work(start, stop)`` over ``n`` items in blocks of ``block``, each thread taking the next block when it is done.

    The threads :func:`thread_count` allows, as :func:`run_parts` runs them;
    where fixed parts would leave the calling thread waiting for one started
    late (starting a thread took 0.05-0.15 ms on the benchmark machine, a
    tenth of a 2000 x 2000 sample) or slowed by the machine, here it takes
    fewer blocks.  Each block is computed as it would be alone, so the values
    do not depend on which thread computed which.  After an error no thread
    takes another block.
    """
    count = thread_count(n, per_item)
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

    run_parts(take, [(0, n)] * count)
