"""The ``lagsym`` command itself: commands, help, the error contract, exit statuses, ``--traceback``."""

from __future__ import annotations

import subprocess
import sys

import pytest

from conftest import EXAMPLES, ROOT

EX1 = EXAMPLES / "paper-example-1.json"
CURVE3 = EXAMPLES / "paper-curve-3rd.json"


@pytest.mark.parametrize("argv,needle", [
    (["equation", "missing.json"], "missing.json: no such file"),
    (["equation", str(CURVE3)], "point 1 [1, 1] has 2 values"),
    (["curve", str(EX1)], "point 1 [1, 2, 7] has 3 values"),
    (["equation", str(EX1), "--format", "xml"], "invalid choice: 'xml'"),
    (["equation", str(EX1), "--digits", "0"], "argument --digits: '0' is out of range"),
])
def test_bad_input_is_one_line_and_exit_2(run_cli, argv, needle):
    status, out, err = run_cli(*argv)
    assert status == 2 and out == ""
    assert needle in err and err.count("\n") == 1 and "Traceback" not in err


def test_no_partial_output_on_error(run_cli, tmp_path):
    target = tmp_path / "eq.txt"
    target.write_text("keep me\n")
    assert run_cli("equation", tmp_path / "nope.json", "-o", target)[0] == 2
    assert target.read_text() == "keep me\n"


def test_traceback_on_request(run_cli):
    status, _, err = run_cli("equation", "missing.json", "--traceback")
    assert status == 2 and "Traceback" in err and "no such file" in err


def test_console_entry_point_runs_as_a_process(tmp_path):
    r = subprocess.run([sys.executable, "-m", "lagsym", "equation", str(tmp_path / "x.json")],
                       capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 2 and r.stdout == "" and r.stderr.strip().endswith("x.json: no such file")
    r = subprocess.run([sys.executable, "-m", "lagsym", "curve", str(CURVE3)], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0 and r.stdout == "y = 5*x**3/6 - 13*x**2/2 + 47*x/3 - 9\n"


def test_help_lists_the_commands(run_cli):
    status, out, _ = run_cli("--help")
    assert status == 0 and "equation" in out and "curve" in out and "check" in out


@pytest.mark.parametrize("where", ["before", "after"])
def test_traceback_before_or_after_the_command(run_cli, tmp_path, where):
    missing = tmp_path / "missing.json"
    argv = ["--traceback", "equation", missing] if where == "before" else ["equation", "--traceback", missing]
    status, _, err = run_cli(*argv)
    assert status == 2
    assert err.startswith("Traceback (most recent call last):") and err.endswith(f"{missing}: no such file\n")
    status, _, err = run_cli("equation", missing)
    assert err == f"lagsym: error: {missing}: no such file\n"
