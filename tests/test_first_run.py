"""A first run after an install compiles the cutter kernel: the command says so on standard error, piped or not."""

from __future__ import annotations

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
def test_the_first_command_leaves_the_kernel_compiled_for_the_first_plan(tmp_path):
    """The README's first command (lagsym equation) starts the compile in the background; the toolpath that follows
    loads the kernel from the cache and says nothing of compiling."""
    import time

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
    # the background process compiles the cutter kernel, then the evaluation kernels: wait for the last index
    deadline = time.monotonic() + 600
    while not (any(cache.rglob("kernel.drop_chunk-*.nbi")) and any(cache.rglob("compiled.points_kernel-*.nbi"))):
        assert not (clone / "lagsym" / "__init__.py.imported").exists(), "the background compile took the clone's"
        assert time.monotonic() < deadline, "the background compile left no kernel in the cache"
        time.sleep(0.5)
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


@pytest.mark.slow
def test_a_plan_started_while_the_background_compile_runs_waits_for_its_kernel(tmp_path):
    """The README's toolpath comes seconds after its first command: it used to compile the kernel a second time beside
    the background process (40 s against 4.5 s warm); it waits for that process's kernel and loads it."""
    from lagsym.toolpath.kernelcache import compiling_in_background

    cache = tmp_path / "numba-cache"
    env = {k: v for k, v in os.environ.items() if k != "LAGSYM_NO_BACKGROUND_COMPILE"}
    env.update(NUMBA_CACHE_DIR=str(cache), NUMBA_DEBUG_CACHE="1")
    eq = subprocess.run([sys.executable, "-m", "lagsym", "equation", str(EXAMPLES / "paper-example-1.json")],
                        env={**env, "NUMBA_DEBUG_CACHE": "0"}, capture_output=True, text=True, timeout=120)
    assert eq.returncode == 0, eq.stderr
    r = subprocess.run([sys.executable, "-m", "lagsym", *ARGS, "-o", str(tmp_path / "a.nc")], env=env,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    saved = [line for line in r.stdout.splitlines() if "drop_chunk" in line and "saved" in line]
    assert not saved, "the plan compiled the kernel itself: " + "; ".join(saved)
    assert any("drop_chunk" in line and "loaded" in line for line in r.stdout.splitlines()), r.stdout[-2000:]
    assert r.stderr.count(LINE) <= 1, r.stderr  # said once if the wait was long
    import time

    folder = next(cache.iterdir())
    deadline = time.monotonic() + 600
    while compiling_in_background(folder):  # the rest of the kernels, then the lock is let go
        assert time.monotonic() < deadline
        time.sleep(0.2)
