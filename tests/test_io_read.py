"""Reading inputs: only regular files and standard input, never without a limit, never waiting forever."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from conftest import ROOT
from lagsym.errors import InputError
from lagsym.io import MAX_BYTES, read_points, read_program

GRID = '{"x": [0, 1], "y": [0, 1], "z": [[0, 1], [1, 2]]}'


def _lagsym(*argv, stdin=None, timeout=120):
    return subprocess.run([sys.executable, "-m", "lagsym", *map(str, argv)], cwd=ROOT, stdin=stdin,
                          capture_output=True, text=True, timeout=timeout)


@pytest.mark.parametrize("path, kind", [("/dev/zero", "a character device"), ("/dev/null", "a character device")])
def test_devices_are_refused_at_once(path, kind):
    with pytest.raises(InputError, match=f"{path}: is {kind}, not a points file; give a regular file, or '-'"):
        read_points(path)
    with pytest.raises(InputError, match=f"{path}: is {kind}, not a program"):
        read_program(path)


def test_a_named_pipe_is_refused_without_waiting(tmp_path):
    fifo = tmp_path / "points.fifo"
    os.mkfifo(fifo)
    done = _lagsym("equation", fifo, timeout=30)
    assert done.returncode == 2
    assert done.stderr == f"lagsym: error: {fifo}: is a pipe (FIFO), not a points file; " \
                          "give a regular file, or '-' for standard input\n"


def test_standard_input_is_read_with_a_dash():
    done = subprocess.run(
        [sys.executable, "-m", "lagsym", "equation", "-"], cwd=ROOT, input=GRID, capture_output=True, text=True,
        timeout=120)
    assert (done.returncode, done.stdout, done.stderr) == (0, "z = x + y\n", "")


def test_endless_standard_input_stops_at_the_limit():
    with open("/dev/zero", "rb") as zero:
        done = _lagsym("equation", "-", stdin=zero)
    assert done.returncode == 2
    assert done.stderr == f"lagsym: error: standard input: more than {MAX_BYTES} bytes is too large for a points file\n"


def test_silent_standard_input_times_out(monkeypatch):
    import lagsym.io as io_module

    r, w = os.pipe()
    try:
        monkeypatch.setattr(io_module.files, "STDIN_SILENCE_S", 0.2)
        with open(r, "rb", closefd=False) as fake, pytest.raises(InputError, match="nothing arrived for 0.2 s"):
            monkeypatch.setattr(sys, "stdin", type("S", (), {"buffer": fake})())
            read_points("-")
    finally:
        os.close(r)
        os.close(w)


def test_a_program_over_the_limit_is_refused_by_its_size(tmp_path):
    big = tmp_path / "big.nc"
    with open(big, "wb") as fh:
        fh.truncate(MAX_BYTES + 1)
    with pytest.raises(InputError, match=rf"big.nc: {MAX_BYTES + 1} bytes is too large for a program \(at most"):
        read_program(big)


@pytest.mark.parametrize("reader, maker", [("read_points", "grid_from_points"),
                                           ("read_curve_points", "curve_from_points")])
def test_points_in_memory_are_sent_to_the_function_for_them(reader, maker):
    import lagsym

    points = [[0, 0, 1], [0, 1, 2], [1, 0, 3], [1, 1, 4]]
    with pytest.raises(lagsym.InputError) as e:
        getattr(lagsym, reader)(points)
    assert "no such file" not in str(e.value)
    assert "not list [[0, 0, 1]" in str(e.value) and f"use lagsym.{maker}(points)" in str(e.value)
    # and the function it names takes them
    assert lagsym.grid_from_points(points).z_array.shape == (2, 2)
