"""The helper threads kept between large evaluations: reused, parked between calls, safe to fork, never deadlocked,
held by a pool its owner can close or make keep nothing."""

import gc
import os
import signal
import subprocess
import sys
import threading
import time
import weakref

import numpy as np
import pytest

from lagsym.evaluate import threads
from lagsym.grid import grid_from_table
from lagsym.lagrange import lagrange_surface
from lagsym.sampling import sample


def _idents(count: int) -> set[int]:
    """The threads that ran ``count`` parts of one call."""
    seen = set()
    threads.run_parts(lambda lo, hi: (seen.add(threading.get_ident()), time.sleep(0.01)), [(k, k + 1) for k in range(count)])
    return seen


def test_the_helpers_are_reused_and_not_counted_as_running_threads():
    before = threading.active_count()
    first = _idents(3)
    assert len(first) == 3 and threading.get_ident() in first
    assert _idents(3) == first  # the same helpers woken again, not new threads
    assert threading.active_count() == before


def test_a_call_while_another_thread_has_the_helpers_runs_its_parts_itself():
    started, release = threading.Event(), threading.Event()
    done = []

    def hold(lo, hi):
        started.set()
        release.wait(5)

    holder = threading.Thread(target=lambda: threads.run_parts(hold, [(0, 1), (1, 2)]))
    holder.start()
    assert started.wait(5)
    seen = set()
    threads.run_parts(lambda lo, hi: (seen.add(threading.get_ident()), done.append(lo)), [(0, 1), (1, 2), (2, 3)])
    release.set()
    holder.join(5)
    assert seen == {threading.get_ident()} and sorted(done) == [0, 1, 2] and not holder.is_alive()


def test_a_part_may_itself_share_work_among_threads():
    inner = []
    threads.run_parts(lambda lo, hi: threads.run_parts(lambda a, b: inner.append((lo, a)), [(0, 1), (1, 2)]),
                      [(0, 1), (1, 2)])
    assert sorted(inner) == [(0, 0), (0, 1), (1, 0), (1, 1)]


@pytest.mark.slow
def test_interrupted_while_waiting_the_call_raises_at_once_stops_the_blocks_and_the_next_call_works():
    stop = []

    def work(lo, hi):
        if lo == 1:  # the helper, once the calling thread waits for it, interrupts it and runs on
            time.sleep(0.1)
            signal.pthread_kill(threading.main_thread().ident, signal.SIGINT)
            time.sleep(5.0)

    # Python's own Ctrl-C handler, whatever this process inherited (a shell starts a background job with
    # SIGINT ignored, and Python leaves it so).
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    t = time.perf_counter()
    try:
        with pytest.raises(KeyboardInterrupt):
            threads.run_parts(work, [(0, 1), (1, 2)], stop)
    finally:
        signal.signal(signal.SIGINT, old)
    # Raised before the helper's part ends (5 s after the interrupt), however late a loaded machine runs it.
    assert time.perf_counter() - t < 4.0 and stop == [True]
    assert len(_idents(2)) == 2  # fresh helpers


_CHILD = """
import os, threading, time
from lagsym.evaluate import threads
seen = set()
threads.run_parts(lambda lo, hi: (seen.add(threading.get_ident()), time.sleep(0.01)), [(0, 1), (1, 2)])
pid = os.fork()
if pid == 0:
    inner = set()
    threads.run_parts(lambda lo, hi: (inner.add(threading.get_ident()), time.sleep(0.01)), [(0, 1), (1, 2)])
    os._exit(0 if len(inner) == 2 else 1)
_, status = os.waitpid(pid, 0)
print(len(seen), os.waitstatus_to_exitcode(status))
"""


@pytest.mark.skipif(not hasattr(os, "fork"), reason="fork is POSIX")
def test_a_forked_process_starts_helpers_of_its_own():
    out = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True, timeout=60, check=False,
                         cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["2", "0"]


def test_the_hand_over_benchmark_runs_and_prints_its_table(tmp_path):
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    results = tmp_path / "results.json"  # never the tracked results file
    done = subprocess.run([sys.executable, os.path.join(root, "benchmarks", "bench_threads.py"), "--runs", "3",
                           "--results", str(results)],
                          cwd=root, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    rows = [ln for ln in done.stdout.splitlines() if ln.startswith("| ") and "us)" not in ln]
    assert len(rows) == 4 and all(len(r.split("|")) == 6 for r in rows)
    assert "the caller held: the peer" in done.stdout
    assert "threads" in results.read_text()


def test_nothing_of_a_call_is_kept_by_the_helpers_once_it_returns():
    class Output:
        pass

    out, seen = Output(), set()
    threads.run_parts(lambda lo, hi, out=out: seen.add(threading.get_ident()), [(0, 1), (1, 2)])
    assert len(seen) == 2  # a helper ran the second part
    gone = weakref.ref(out)
    del out
    assert gone() is None  # the helper's reference to its part died with the call
    gc.disable()  # freed by its count of references, as soon as the caller drops it: not by a later collection
    try:
        s = lagrange_surface(grid_from_table([0, 1, 2], [0, 1, 2], [[0, 1, 0], [1, 2, 1], [0, 1, 3]]))
        z = sample(s, 1000, 600).z  # shared among the threads (600,000 values)
        assert threads.thread_count(1000, 600) < 2 or threads.PROCESS_POOL.helpers
        assert np.isfinite(z).all()
        memory = z
        while memory.base is not None:
            memory = memory.base  # the allocation the grid's values live in
        gone = weakref.ref(memory)
        del z, memory
        assert gone() is None
    finally:
        gc.enable()


def test_a_pool_of_ones_own_keeps_its_helpers_apart_and_closing_it_ends_them():
    with threads.HelperPool() as pool:
        seen = set()
        pool.run_parts(lambda lo, hi: (seen.add(threading.get_ident()), time.sleep(0.01)), [(0, 1), (1, 2)])
        assert len(seen) == 2 and pool.helpers == 1
        assert not seen & _idents(2) - {threading.get_ident()}  # the process pool's helpers are others
    assert pool.helpers == 0
    again = set()
    pool.run_parts(lambda lo, hi: (again.add(threading.get_ident()), time.sleep(0.01)), [(0, 1), (1, 2)])
    assert len(again) == 2 and pool.helpers == 1  # a closed pool starts fresh helpers when used again
    pool.close()


def test_a_pool_that_keeps_nothing_or_allows_one_thread_gives_the_same_values():
    s = lagrange_surface(grid_from_table([0, 1, 2], [0, 1, 2], [[0, 1, 0], [1, 2, 1], [0, 1, 3]]))
    from lagsym.evaluate import Engine

    shared = sample(s, 1000, 600, engine=Engine("numpy")).z
    fleeting, alone = threads.HelperPool(keep=False), threads.HelperPool(max_threads=1)
    for pool in (fleeting, alone):
        for policy in ("numpy", "compiled"):
            assert np.array_equal(sample(s, 1000, 600, engine=Engine(policy, pool=pool)).z, shared), (pool, policy)
        assert pool.helpers == 0
    used = set()
    alone.run_parts(lambda lo, hi: used.add(threading.get_ident()), [(0, 1), (1, 2), (2, 3)])
    assert used == {threading.get_ident()}
    with pytest.raises(ValueError, match="max_threads = 0"):
        threads.HelperPool(max_threads=0)


_OWN_POOL_CHILD = """
import os, threading, time
from lagsym.evaluate import threads
pool = threads.HelperPool()
pool.run_parts(lambda lo, hi: time.sleep(0.01), [(0, 1), (1, 2)])
pid = os.fork()
if pid == 0:
    empty = pool.helpers == 0
    inner = set()
    pool.run_parts(lambda lo, hi: (inner.add(threading.get_ident()), time.sleep(0.01)), [(0, 1), (1, 2)])
    os._exit(0 if empty and len(inner) == 2 else 1)
_, status = os.waitpid(pid, 0)
print(pool.helpers, os.waitstatus_to_exitcode(status))
"""


@pytest.mark.skipif(not hasattr(os, "fork"), reason="fork is POSIX")
def test_a_forked_process_finds_its_own_pools_empty():
    out = subprocess.run([sys.executable, "-c", _OWN_POOL_CHILD], capture_output=True, text=True, timeout=60,
                         check=False, cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["1", "0"]
