"""A first run after an install compiles the cutter kernel: the command says so on standard error, piped or not."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from conftest import EXAMPLES

ARGS = ["toolpath", str(EXAMPLES / "paper-example-1.json"), "--scale", "10", "--step", "1", "--stepover", "2",
        "--safe-z", "400"]
LINE = "lagsym: compiling the cutter kernel, once after an install or upgrade ...\n"


def _run(tmp_path, cache):
    # An empty Numba cache directory is what a fresh install has: nothing compiled yet.
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    return subprocess.run([sys.executable, "-m", "lagsym", *ARGS, "-o", str(tmp_path / "a.nc")], env=env,
                          capture_output=True, text=True, timeout=600)


@pytest.mark.slow
def test_the_first_run_says_it_compiles_and_the_second_does_not(tmp_path):
    cache = tmp_path / "numba-cache"
    first = _run(tmp_path, cache)
    assert first.returncode == 0, first.stderr
    assert first.stderr.startswith(LINE), first.stderr
    assert first.stderr.count(LINE) == 1
    assert any(cache.rglob("*.nbi")), "the compiled kernel was not cached"
    second = _run(tmp_path, cache)
    assert second.returncode == 0, second.stderr
    assert "compiling" not in second.stderr, second.stderr
    assert (tmp_path / "a.nc").read_text().count("\n") > 10


@pytest.mark.slow
def test_roughing_says_so_too(tmp_path):
    cache = tmp_path / "numba-cache"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    r = subprocess.run([sys.executable, "-m", "lagsym", "rough", str(EXAMPLES / "paper-example-4.json"), "--scale", "20",
                        "--tool-diameter", "10", "--safe-z", "150", "--stock-above", "5", "-o", str(tmp_path / "r.nc")], env=env,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    # A job's stages carry the operation's name.
    assert r.stderr.startswith("lagsym: rough T1: " + LINE[len("lagsym: "):]), r.stderr


@pytest.mark.slow
def test_the_first_command_compiles_in_the_background_for_the_plans_that_follow(tmp_path):
    """The README's first command (lagsym equation) starts the compile in the background, from the installed
    lagsym even in a clone; the README's toolpath seconds later waits for that kernel and loads it (it used to
    compile it a second time beside the background process: 40 s against 4.5 s warm); and a plan after the
    background compile has ended says nothing of compiling.  One fresh cache serves the three checks."""
    import time

    from lagsym.toolpath.kernelcache import compiling_in_background

    cache = tmp_path / "numba-cache"
    env = {k: v for k, v in os.environ.items() if k != "LAGSYM_NO_BACKGROUND_COMPILE"}
    env["NUMBA_CACHE_DIR"] = str(cache)
    # Run where the README runs it: in a clone, whose sources are another lagsym than the one installed (here a
    # decoy).  The background process used to import the clone's (``-m`` looks in the working folder first) and
    # fill its cache, so the installed kernel compiled again in the first plan.
    clone = tmp_path / "clone"
    (clone / "lagsym").mkdir(parents=True)
    (clone / "lagsym" / "__init__.py").write_text("open(__file__ + '.imported', 'w').close()\n")
    eq = subprocess.run([sys.executable, "-P", "-m", "lagsym", "equation", str(EXAMPLES / "paper-example-1.json")],
                        env=env, cwd=clone, capture_output=True, text=True, timeout=120)
    assert eq.returncode == 0 and eq.stderr == "", eq.stderr
    r = subprocess.run([sys.executable, "-m", "lagsym", *ARGS, "-o", str(tmp_path / "a.nc")],
                       env={**env, "NUMBA_DEBUG_CACHE": "1"}, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    saved = [line for line in r.stdout.splitlines() if "drop_chunk" in line and "saved" in line]
    assert not saved, "the plan compiled the kernel itself: " + "; ".join(saved)
    assert any("drop_chunk" in line and "loaded" in line for line in r.stdout.splitlines()), r.stdout[-2000:]
    assert r.stderr.count(LINE) <= 1, r.stderr  # said once if the wait was long
    folder = next(cache.iterdir())
    deadline = time.monotonic() + 600
    while compiling_in_background(folder):  # the rest of the kernels, then the lock is let go
        assert not (clone / "lagsym" / "__init__.py.imported").exists(), "the background compile took the clone's"
        assert time.monotonic() < deadline, "the background compile did not end"
        time.sleep(0.2)
    assert not (clone / "lagsym" / "__init__.py.imported").exists(), "the background compile took the clone's"
    assert any(cache.rglob("kernel.drop_chunk-*.nbi")) and any(cache.rglob("compiled.points_kernel-*.nbi"))
    r = _run(tmp_path, cache)
    assert r.returncode == 0, r.stderr
    assert "compiling" not in r.stderr, r.stderr


def test_the_background_compile_is_off_when_asked_or_already_done(tmp_path, monkeypatch):
    from lagsym.toolpath import warmup

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "empty"))
    monkeypatch.setenv(warmup.OFF, "1")
    assert warmup.start_in_background() is False
    monkeypatch.delenv(warmup.OFF)
    folder = warmup.cache_folder()
    assert folder is not None and not warmup.kernel_cached(folder)
    folder.mkdir(parents=True)
    (folder / "kernel.drop_chunk-407.py311.nbi").write_bytes(b"")
    assert warmup.kernel_cached() and warmup.start_in_background() is False


_AHEAD = """
import json
import numpy as np
from numba.core import event
from lagsym.grid import grid_from_table
from lagsym.lagrange import lagrange_surface
from lagsym.toolpath.dropcutter import drop_cutter
from lagsym.toolpath.kernelahead import compile_ahead

class Names(event.Listener):
    def __init__(self):
        self.names = []
    def on_start(self, e):
        self.names.append(e.data["dispatcher"].py_func.__name__)
    def on_end(self, e):
        pass

ahead, kernel = Names(), Names()
with event.install_listener("numba:compile", ahead):
    compile_ahead()
surface = lagrange_surface(grid_from_table([0, 1, 2], [0, 1, 2], [[0, 1, 0], [1, 2, 1], [0, 1, 0]]))
xs = np.linspace(0.0, 2.0, 5)
with event.install_listener("numba:compile", kernel):
    for shape, corner in (("ball", None), ("flat", None), ("bull", 0.1)):
        drop_cutter(surface, xs, xs, 0.5, shape, corner=corner)
print(json.dumps([ahead.names, kernel.names]))
"""


@pytest.mark.slow
def test_the_kernels_heaviest_callees_compile_ahead_in_a_second_process_for_the_types_the_kernel_passes(tmp_path):
    """compile_ahead's second process compiles one group of callees while this one compiles the other; the kernel
    then loads both from the cache.  Types that differ from the kernel's would show here as a second compile."""
    from lagsym.toolpath.kernelahead import PARTS

    cache = tmp_path / "numba-cache"
    r = subprocess.run([sys.executable, "-c", _AHEAD], env={**os.environ, "NUMBA_CACHE_DIR": str(cache)},
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    ahead, kernel = json.loads(r.stdout)
    assert set(PARTS["lattice"]) <= set(ahead), ahead  # compiled here
    assert not set(PARTS["newton"]) & set(ahead), ahead  # compiled by the second process, loaded here
    assert {path.name.split("-")[0] for path in cache.rglob("*.nbi")} >= {f"kernel.{n}" for n in PARTS["newton"]}
    assert "drop_chunk" in kernel and not set(PARTS["newton"] + PARTS["lattice"]) & set(kernel), kernel


def test_the_background_compile_leaves_the_evaluation_kernels_while_a_plan_runs(tmp_path):
    """A plan holds the planning lock until its process ends; the background compile's evaluation kernels wait
    for it (at most their limit), so they do not share the first plan's cores."""
    import time

    from lagsym.toolpath.kernelcache import hold_planning_lock, wait_for_no_plan

    folder = tmp_path / "cache"
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys, time; from pathlib import Path\n"
         "from lagsym.toolpath.kernelcache import hold_planning_lock\n"
         "print(hold_planning_lock(Path(sys.argv[1])), flush=True); time.sleep(1.0)", str(folder)],
        stdout=subprocess.PIPE, text=True)
    assert holder.stdout.readline() == "True\n"  # the plan holds it now, and lets it go when it ends
    start = time.monotonic()
    with wait_for_no_plan(folder, limit=60.0):
        waited = time.monotonic() - start
        assert holder.poll() is not None, "entered while the plan still ran"
        assert hold_planning_lock(folder) is False  # a plan that starts meanwhile does not wait for the lock
    assert waited < 60.0
    assert holder.wait() == 0
    assert hold_planning_lock(folder) is True and hold_planning_lock(folder) is True  # held once per folder
    start = time.monotonic()
    with wait_for_no_plan(folder, limit=0.3):  # this process plans: the wait ends at its limit
        assert time.monotonic() - start >= 0.3


def test_a_plan_takes_the_planning_lock_before_it_waits_for_or_compiles_the_kernel(tmp_path, monkeypatch):
    import time

    from lagsym.toolpath import kernelahead, kernelcache
    from lagsym.toolpath.dropcutter import telling_compiles

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    ahead = []
    monkeypatch.setattr(kernelahead, "compile_ahead", lambda: ahead.append(kernelcache.cache_folder()))
    with telling_compiles(None):
        pass
    folder = kernelcache.cache_folder()
    assert ahead == [folder]  # no kernel in this cache: the plan compiles it, the heaviest parts side by side
    start = time.monotonic()
    with kernelcache.wait_for_no_plan(folder, limit=0.3):
        assert time.monotonic() - start >= 0.3
