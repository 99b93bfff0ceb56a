"""A first run after an install compiles the cutter kernel: the command says so on standard error, piped or not."""

from __future__ import annotations

import os
import subprocess
import sys

from conftest import EXAMPLES

ARGS = ["toolpath", str(EXAMPLES / "paper-example-1.json"), "--scale", "10", "--step", "1", "--stepover", "2",
        "--safe-z", "400"]
LINE = "lagsym: compiling the cutter kernel, once after an install or upgrade ...\n"


def _run(tmp_path, cache):
    # An empty Numba cache directory is what a fresh install has: nothing compiled yet.
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    return subprocess.run([sys.executable, "-m", "lagsym", *ARGS, "-o", str(tmp_path / "a.nc")], env=env,
                          capture_output=True, text=True, timeout=600)


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


def test_roughing_says_so_too(tmp_path):
    cache = tmp_path / "numba-cache"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    r = subprocess.run([sys.executable, "-m", "lagsym", "rough", str(EXAMPLES / "paper-example-4.json"), "--scale", "20",
                        "--tool-diameter", "10", "--safe-z", "150", "--stock-above", "5", "-o", str(tmp_path / "r.nc")], env=env,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    # A job's stages carry the operation's name.
    assert r.stderr.startswith("lagsym: rough T1: " + LINE[len("lagsym: "):]), r.stderr
