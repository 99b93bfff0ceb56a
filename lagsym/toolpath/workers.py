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

Each worker has a pipe of its own to the command, and the command hands a
chunk to a worker only when that worker is idle.  Nothing is shared between
workers: no queue, no lock, no handler thread.  A signal to the whole
process group (a closed terminal's SIGHUP, ``timeout``, a service
manager's SIGTERM) kills the workers at any moment, and the command, whose
only thread waits on the pipes, ends at once: ``multiprocessing.Pool``
could not promise that (a worker killed while it held its shared queue's
lock left the pool's clean-up waiting for that lock for ever).
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import pickle
import signal
import sys
import threading
from multiprocessing.connection import wait

from ..errors import LagsymError, Terminated
from ..evaluate.threads import available_cores

__all__ = ["Workers", "MIN_POINTS", "MAX_PROCESSES", "available_cores"]

MIN_POINTS = 5_000
"""Fine samples from which a plan starts worker processes (below it, one process does all)."""

MAX_PROCESSES = 8
"""Worker processes at most, whatever the cores: each holds its own interpreter and NumPy."""


def _serve(conn, evaluator, parent: int) -> None:
    """A worker: ``(fn, args)`` in, ``(True, fn(evaluator, *args))`` or ``(False, exception)`` out, until the pipe ends.

    The fork copies the command's handlers (SIGTERM and SIGHUP stop it with
    one line, :mod:`lagsym.cli`); a worker takes the system's instead, so
    that a signal ends it silently.  Ctrl-C reaches the whole process group:
    the command stops and ends its workers, so a worker ignores it.  On
    Linux the kernel kills a worker whose command has ended
    (:func:`_die_with`): none is left holding the command's standard error.
    """
    for sig in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _die_with(parent)
    while True:
        try:
            task = conn.recv()
        except EOFError:  # the command closed its end
            return
        fn, args = task
        try:
            reply = (True, fn(evaluator, *args))
        except Exception as exc:  # handed back to the command, which raises it
            reply = (False, exc)
        try:
            conn.send(reply)
        except (pickle.PicklingError, TypeError, AttributeError) as exc:
            conn.send((False, LagsymError(f"a worker's result could not be sent back: {exc}")))


def _die_with(parent: int) -> None:
    """Linux: be killed when the thread that forked this worker (the command's) ends;
    end now if the command ended before this was asked."""
    if sys.platform.startswith("linux"):
        try:
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            return
        if os.getppid() != parent:
            os._exit(0)


class Workers:
    """Worker processes for one evaluator, used as a context manager; ``map`` runs chunks and keeps their order.

    With fewer than two cores, ``processes`` below 2, other threads running
    or no ``fork`` on the platform, no process is started and :meth:`map`
    runs the chunks here.
    """

    def __init__(self, evaluator, processes: int | None = None):
        self.evaluator = evaluator
        self.processes = min(available_cores(), MAX_PROCESSES) if processes is None else processes
        self._started: list = []  # (process, the command's end of its pipe)

    def __enter__(self) -> Workers:
        if (self.processes > 1 and threading.active_count() == 1
                and "fork" in multiprocessing.get_all_start_methods()):
            ctx = multiprocessing.get_context("fork")
            try:
                for _ in range(self.processes):
                    here, there = ctx.Pipe()
                    # daemon: were the command to end before __exit__ (a signal between two lines here),
                    # multiprocessing's own clean-up at exit kills the worker rather than waiting for it
                    process = ctx.Process(target=_serve, args=(there, self.evaluator, os.getpid()), daemon=True)
                    self._started.append((process, here))
                    process.start()
                    there.close()
            except BaseException:
                self._end()
                raise
        return self

    def __exit__(self, *exc) -> None:
        self._end()

    def _end(self) -> None:
        """Every worker killed and reaped: they hold nothing the command needs, so none is asked to stop."""
        started, self._started = self._started, []
        for process, conn in started:
            conn.close()
            if process.pid is not None:
                process.kill()
        for process, _ in started:
            if process.pid is not None:
                process.join()

    def _lost(self, conn) -> None:
        """A worker ended without its result: the signal that killed it stops the command too (a signal to the
        process group reaches the workers and the command at once), or the system killed it."""
        process = next(p for p, c in self._started if c is conn)
        process.join(2.0)
        code = process.exitcode
        if code is not None and -code in (signal.SIGTERM, signal.SIGHUP):
            raise Terminated(-code)
        how = "still running" if code is None else f"exit status {code}" if code >= 0 else f"signal {-code}"
        raise LagsymError(f"a worker process of the plan ended without its result ({how}; the system kills "
                          "a process so when memory runs out): free memory and run the command again")

    @property
    def parallel(self) -> bool:
        """Whether chunks run in worker processes."""
        return bool(self._started)

    def map(self, fn, chunks) -> list:
        """``[fn(evaluator, *args) for args in chunks]``, in the worker processes where there are any."""
        chunks = list(chunks)
        if not self._started or len(chunks) < 2:
            return [fn(self.evaluator, *args) for args in chunks]
        results = [None] * len(chunks)
        idle = [conn for _, conn in reversed(self._started)]
        busy = {}
        todo = 0
        while todo < len(chunks) or busy:
            while idle and todo < len(chunks):
                conn = idle.pop()
                conn.send((fn, chunks[todo]))
                busy[conn] = todo
                todo += 1
            for conn in wait(list(busy)):
                try:
                    ok, value = conn.recv()
                except EOFError:
                    self._lost(conn)
                if not ok:
                    raise value
                results[busy.pop(conn)] = value
                idle.append(conn)
        return results
