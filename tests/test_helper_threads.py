"""The helper threads kept between large evaluations: reused, parked between calls, safe to fork, never deadlocked."""

import os
import signal
import subprocess
import sys
import threading
import time

import pytest

from lagsym.evaluate import threads


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


def test_interrupted_while_waiting_the_call_raises_at_once_stops_the_blocks_and_the_next_call_works():
    stop = []

    def work(lo, hi):
        if lo == 1:  # the helper, once the calling thread waits for it, interrupts it and runs on
            time.sleep(0.1)
            signal.pthread_kill(threading.main_thread().ident, signal.SIGINT)
            time.sleep(0.4)

    t = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        threads.run_parts(work, [(0, 1), (1, 2)], stop)
    assert time.perf_counter() - t < 0.4 and stop == [True]
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


def test_the_hand_over_benchmark_runs_and_prints_its_table():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    done = subprocess.run([sys.executable, os.path.join(root, "benchmarks", "bench_threads.py"), "--runs", "3"],
                          cwd=root, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    rows = [ln for ln in done.stdout.splitlines() if ln.startswith("| ") and "us)" not in ln]
    assert len(rows) == 4 and all(len(r.split("|")) == 6 for r in rows)
    assert "the caller held: the peer" in done.stdout
