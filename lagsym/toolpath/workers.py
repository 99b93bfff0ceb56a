"""Drop-cutter on every core: chunks of tool positions shared among worker processes.

A plan drops the tool at tens of thousands of positions, each independent of
the others, so they are computed in chunks by worker processes, one per
core the process may run on, started once per plan (:class:`Workers`), and
only where a plan has enough positions to pay for it (:data:`MIN_POINTS`).
The workers are *forked*: a fresh interpreter would import the caller's main
module again, which a script without a ``__main__`` guard cannot bear.  A
fork is safe only while the process runs no other thread (one holding a lock
at the fork would leave it held in the child), so with other threads
running (a progress display's, say) the chunks are computed here, one after
the other.  Each worker has the surface's evaluator from the fork; a chunk's
result is the same whichever process computes it.
"""

from __future__ import annotations

import ctypes
import multiprocessing
import multiprocessing.pool as mp_pool
import os
import signal
import sys
import threading

from ..evaluate.threads import available_cores

__all__ = ["Workers", "MIN_POINTS", "MAX_PROCESSES", "available_cores"]

MIN_POINTS = 5_000
"""Fine samples from which a plan starts worker processes (below it, one process does all)."""

MAX_PROCESSES = 8
"""Worker processes at most, whatever the cores: each holds its own interpreter and NumPy."""

_EVALUATOR = None  # in a worker process only: the evaluator its initializer received


def _start(evaluator, parent: int) -> None:
    """A worker's start: the evaluator kept, and the signals a command catches given back to the system.

    The fork copies the command's handlers (SIGTERM and SIGHUP stop it with
    one line, :mod:`lagsym.cli`); in a worker they would turn the pool's own
    SIGTERM at the end of every plan into a traceback.  Ctrl-C reaches the
    whole process group: the command stops and ends the pool, so a worker
    ignores it.  On Linux the kernel kills a worker whose command has ended
    (:func:`_die_with`): none is left holding the command's standard error.
    """
    global _EVALUATOR
    _EVALUATOR = evaluator
    _die_with(parent)
    for sig in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _die_with(parent: int) -> None:
    """Linux: be killed when the thread that forked this worker ends (the command, or the pool's worker handler);
    end now if the command ended before this was asked."""
    if sys.platform.startswith("linux"):
        try:
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            return
        if os.getppid() != parent:
            os._exit(0)


def _abandon(pool) -> None:
    """End a pool that an error or a signal stops: its workers killed, its queues left alone.

    A signal sent to the whole process group (a closed terminal's SIGHUP,
    ``timeout``, a service manager's SIGTERM) also kills the workers, and one
    killed while it wrote a result still holds the result queue's lock:
    ``Pool.terminate`` then waits for that lock for ever (4 stops in 6 hung
    so).  So the handler threads are told to stop (the worker handler would
    fork replacements), every worker is killed and reaped, and the pool's
    own clean-up at exit, which takes the same lock, is cancelled.  Pool
    offers no public call for this; the attributes used are those of
    CPython's ``multiprocessing.pool`` since 3.8.
    """
    for handler in (pool._worker_handler, pool._task_handler, pool._result_handler):
        handler._state = mp_pool.TERMINATE
    pool._state = mp_pool.TERMINATE
    # The worker handler forks a replacement for each worker it finds dead until it sees the state: wait for it
    # to stop, so that no worker is forked after the kills below (one was, left holding the command's stderr).
    pool._worker_handler.join(2.0)
    for process in list(pool._pool):
        process.kill()
    for process in list(pool._pool):  # again: one the worker handler forked before it saw the state
        process.kill()
        process.join(5.0)
    pool._terminate.cancel()


def _call(task):
    fn, args = task
    return fn(_EVALUATOR, *args)


class Workers:
    """A pool of worker processes for one evaluator, used as a context manager; ``map`` runs chunks in order.

    With fewer than two cores, ``processes`` below 2, other threads running
    or no ``fork`` on the platform, no process is started and :meth:`map`
    runs the chunks here.
    """

    def __init__(self, evaluator, processes: int | None = None):
        self.evaluator = evaluator
        self.processes = min(available_cores(), MAX_PROCESSES) if processes is None else processes
        self._pool = None

    def __enter__(self) -> Workers:
        if (self.processes > 1 and threading.active_count() == 1
                and "fork" in multiprocessing.get_all_start_methods()):
            ctx = multiprocessing.get_context("fork")
            self._pool = ctx.Pool(self.processes, initializer=_start, initargs=(self.evaluator, os.getpid()))
        return self

    def __exit__(self, exc_type, *exc) -> None:
        pool, self._pool = self._pool, None
        if pool is None:
            return
        if exc_type is None:
            pool.terminate()
            pool.join()
        else:
            _abandon(pool)

    @property
    def parallel(self) -> bool:
        """Whether chunks run in worker processes."""
        return self._pool is not None

    def map(self, fn, chunks) -> list:
        """``[fn(evaluator, *args) for args in chunks]``, in the worker processes where there are any."""
        chunks = list(chunks)
        if self._pool is None or len(chunks) < 2:
            return [fn(self.evaluator, *args) for args in chunks]
        return self._pool.map(_call, [(fn, args) for args in chunks], chunksize=1)
