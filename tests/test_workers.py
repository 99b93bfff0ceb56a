"""Drop-cutter in worker processes gives the values one process gives."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from lagsym.evaluate import surface_evaluator
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.toolpath.workers import Workers

from conftest import EXAMPLES, ROOT
from cutters import brute


def _fresh(code: str, tmp_path, stderr: bool = False):
    """Run ``code`` as a script in a fresh interpreter (the suite's other tests may leave threads running
    here, and workers fork only where no other thread runs); its standard output, or both streams."""
    script = tmp_path / "run.py"
    script.write_text(code)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, str(script)], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return (done.stdout, done.stderr) if stderr else done.stdout


@pytest.mark.slow
def test_worker_processes_give_the_same_values_as_one_process(tmp_path):
    out = _fresh(
        "import numpy as np\n"
        "from lagsym.evaluate import surface_evaluator\n"
        "from lagsym.io import read_points\n"
        "from lagsym.lagrange import lagrange_surface\n"
        "from lagsym.toolpath import drop_cutter\n"
        "from lagsym.toolpath.workers import Workers\n"
        f"surface = lagrange_surface(read_points({str(EXAMPLES / 'paper-example-4.json')!r}))\n"
        "ev = surface_evaluator(surface)\n"
        "rng = np.random.default_rng(11)\n"
        "x, y = rng.uniform(1, 5, 3000), rng.uniform(1, 5, 3000)\n"
        "alone = drop_cutter(surface, x, y, 0.15, evaluator=ev)\n"
        "with Workers(ev, 2) as workers:\n"
        "    parallel = workers.parallel\n"
        "    shared = drop_cutter(surface, x, y, 0.15, evaluator=ev, workers=workers)\n"
        f"np.save({str(tmp_path / 'shared.npy')!r}, shared)\n"
        "print(parallel, np.array_equal(shared, alone))\n", tmp_path)
    assert out.split() == ["True", "True"]
    surface = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
    rng = np.random.default_rng(11)
    x, y = rng.uniform(1, 5, 3000), rng.uniform(1, 5, 3000)
    shared = np.load(tmp_path / "shared.npy")
    for k in range(3):  # and the values are drop-cutter's: never below a brute-force search
        assert shared[k] >= brute(surface, x[k], y[k], 0.15)


def test_one_process_runs_the_chunks_here():
    ev = surface_evaluator(lagrange_surface(read_points(EXAMPLES / "paper-example-4.json")))
    with Workers(ev, 1) as workers:
        assert not workers.parallel
        assert workers.map(lambda e, a: (e is ev, a), [(1,), (2,)]) == [(True, 1), (True, 2)]


@pytest.mark.slow
def test_a_script_without_a_main_guard_runs_with_workers(tmp_path):
    # A worker that imported the caller's main module again would run this script once more, without end.
    out = _fresh(
        "from lagsym.evaluate import surface_evaluator\n"
        "from lagsym.io import read_points\n"
        "from lagsym.lagrange import lagrange_surface\n"
        "from lagsym.toolpath import drop_cutter\n"
        "from lagsym.toolpath.workers import Workers\n"
        f"s = lagrange_surface(read_points({str(EXAMPLES / 'paper-example-4.json')!r}))\n"
        "ev = surface_evaluator(s)\n"
        "with Workers(ev, 2) as w:\n"
        "    z = drop_cutter(s, [2.0] * 600, [3.0] * 600, 0.15, evaluator=ev, workers=w)\n"
        "print(w.processes, float(z[0]) == float(drop_cutter(s, 2.0, 3.0, 0.15)))\n", tmp_path)
    assert out.split() == ["2", "True"]


def test_with_another_thread_running_the_chunks_run_here(tmp_path):
    out = _fresh(
        "import threading\n"
        "from lagsym.evaluate import surface_evaluator\n"
        "from lagsym.io import read_points\n"
        "from lagsym.lagrange import lagrange_surface\n"
        "from lagsym.toolpath.workers import Workers\n"
        f"ev = surface_evaluator(lagrange_surface(read_points({str(EXAMPLES / 'paper-example-4.json')!r})))\n"
        "stop = threading.Event()\n"
        "other = threading.Thread(target=stop.wait)\n"
        "other.start()\n"
        "with Workers(ev, 2) as workers:\n"
        "    during = workers.parallel\n"
        "stop.set()\n"
        "other.join()\n"
        "with Workers(ev, 2) as workers:\n"
        "    after = workers.parallel\n"
        "print(during, after)\n", tmp_path)
    assert out.split() == ["False", "True"]


@pytest.mark.slow
def test_the_workers_end_silently_under_the_commands_signal_handlers(tmp_path):
    # The command's SIGTERM handler raised in each worker when the pool ended it: a traceback per worker.
    out, err = _fresh(
        "from lagsym.cli import _signals_as_interrupts\n"
        "from lagsym.evaluate import surface_evaluator\n"
        "from lagsym.io import read_points\n"
        "from lagsym.lagrange import lagrange_surface\n"
        "from lagsym.toolpath import drop_cutter\n"
        "from lagsym.toolpath.workers import Workers\n"
        f"s = lagrange_surface(read_points({str(EXAMPLES / 'paper-example-4.json')!r}))\n"
        "ev = surface_evaluator(s)\n"
        "with _signals_as_interrupts():\n"
        "    for _ in range(3):\n"
        "        with Workers(ev, 2) as w:\n"
        "            z = drop_cutter(s, [2.0] * 600, [3.0] * 600, 0.15, evaluator=ev, workers=w)\n"
        "print(w.processes)\n", tmp_path, stderr=True)
    assert out.split() == ["2"] and err == "", err[-2000:]


def test_a_worker_that_dies_or_fails_is_told_not_waited_for(tmp_path):
    # A worker killed by the system (SIGKILL: out of memory) is named in one error; one killed by SIGTERM stops
    # the command as that signal does; an error in a chunk reaches the command as itself; none waits.
    out = _fresh(
        "import os, signal\n"
        "from lagsym.errors import LagsymError, Terminated\n"
        "from lagsym.toolpath.workers import Workers\n"
        "def chunk(ev, k):\n"
        "    if k == 3:\n"
        "        os.kill(os.getpid(), signal.SIGKILL)\n"
        "    if k == 4:\n"
        "        os.kill(os.getpid(), signal.SIGTERM)\n"
        "    if k == 5:\n"
        "        raise ZeroDivisionError('chunk 5')\n"
        "    return k * k\n"
        "for bad in (3, 4, 5):\n"
        "    with Workers(None, 2) as w:\n"
        "        assert w.map(chunk, [(k,) for k in (0, 1, 2, 6, 7)]) == [0, 1, 4, 36, 49]\n"
        "        try:\n"
        "            w.map(chunk, [(k,) for k in (0, 1, bad, 6)])\n"
        "        except LagsymError as e:\n"
        "            print('error', e)\n"
        "        except Terminated as e:\n"
        "            print('terminated', e.signum)\n"
        "        except ZeroDivisionError as e:\n"
        "            print('raised', e)\n", tmp_path)
    lines = out.splitlines()
    assert lines[0].startswith("error a worker process of the plan ended without its result (signal 9;"), out
    assert lines[1:] == ["terminated 15", "raised chunk 5"], out


def test_a_chunk_reaches_the_kernel_as_a_worker_receives_it(monkeypatch):
    # Numba compiles one version of the kernel per kind of argument (a read-only array is another kind):
    # the arguments of a chunk computed here must be of the kinds a worker unpickles, or the workers compile
    # a version of their own in every plan after an install.
    import pickle

    import numba

    from lagsym.toolpath import drop_cutter, kernel

    seen = []
    monkeypatch.setattr(kernel, "drop_chunk", lambda *args: seen.append(args) or np.zeros(len(args[3])))
    surface = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
    for shape, corner in (("ball", None), ("flat", None), ("bull", 0.05)):
        drop_cutter(surface, np.linspace(1, 5, 9), 3.0, 0.15, shape, corner=corner)
    assert len(seen) == 3
    for args in seen:
        here = [numba.typeof(a) for a in args]
        # What a worker receives is a pickled task; the evaluator's coefficients it inherits by the fork.
        there = here[:1] + [numba.typeof(pickle.loads(pickle.dumps(a))) for a in args[1:]]
        assert here == there


@pytest.mark.slow
@pytest.mark.parametrize("sig", ["SIGTERM", "SIGHUP"])
def test_a_signal_to_the_whole_process_group_stops_a_parallel_plan_at_once(tmp_path, sig):
    # A closed terminal (SIGHUP), `timeout` or a service manager (SIGTERM) signal the whole group: the workers die
    # with the command, one of them perhaps while it holds the result queue's lock, on which Pool.terminate
    # waited for ever (4 stops in 6 hung).  Four stops at random moments of the plan, each within seconds.
    import random
    import signal
    import time

    signum = getattr(signal, sig)
    rng = random.Random(sig)
    out = tmp_path / "tp.nc"
    cmd = [sys.executable, "-m", "lagsym", "toolpath", str(EXAMPLES / "paper-example-4.json"), "--scale", "20",
           "--tool-diameter", "6", "--stepover", "0.1", "--step", "0.05", "--safe-z", "80", "-o", str(out)]
    for _ in range(4):
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                start_new_session=True, env={**os.environ, "PYTHONPATH": str(ROOT)})
        children = f"/proc/{proc.pid}/task/{proc.pid}/children"
        deadline = time.monotonic() + 120
        while len(open(children).read().split()) < 2:  # the plan's workers run
            assert proc.poll() is None and time.monotonic() < deadline, "the plan started no workers"
            time.sleep(0.02)
        time.sleep(rng.uniform(0.1, 1.5))
        os.killpg(proc.pid, signum)
        try:
            _, err = proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
            pytest.fail(f"{sig} to the process group: the command still ran 30 s later")
        assert proc.returncode == 128 + signum and f"stopped by {sig}" in err and err.count("\n") == 1, err
        assert not out.exists()
        deadline = time.monotonic() + 10  # no worker outlives the command (an orphan is reaped by init at once)
        while _group_alive(proc.pid):
            left = subprocess.run(["ps", "-o", "pid,stat,args", "-g", str(proc.pid)], capture_output=True, text=True)
            assert time.monotonic() < deadline, f"left running in the group:\n{left.stdout}"
            time.sleep(0.1)


def _group_alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return False
    return True
