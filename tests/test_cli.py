"""The ``lagsym equation``, ``curve`` and ``check`` commands, and the CLI's error contract."""

from __future__ import annotations

import json
import subprocess
import sys
from fractions import Fraction

import pytest
import sympy

from conftest import EXAMPLES, ROOT

EX1 = EXAMPLES / "paper-example-1.json"
EX4 = EXAMPLES / "paper-example-4.json"
CURVE3 = EXAMPLES / "paper-curve-3rd.json"


def test_equation_example_1(run_cli):
    assert run_cli("equation", EX1) == (0, "z = x**2 + 3*y\n", "")


def test_curve_3rd_degree(run_cli):
    assert run_cli("curve", CURVE3) == (0, "y = 5*x**3/6 - 13*x**2/2 + 47*x/3 - 9\n", "")


def test_curve_digits_as_the_paper_prints(run_cli):
    assert run_cli("curve", CURVE3, "--digits", "4")[1] == "y = 0.8333*x**3 - 6.5*x**2 + 15.67*x - 9\n"


def test_equation_output_parses_back_with_sympify(run_cli):
    status, out, _ = run_cli("equation", EX4)
    lhs, rhs = out.strip().split(" = ")
    assert status == 0 and lhs == "z"
    x, y = sympy.symbols("x y")
    expr = sympy.sympify(rhs)
    assert expr.subs({x: 2, y: 2}) == sympy.Rational(263, 100)


def test_equation_json(run_cli):
    status, out, _ = run_cli("equation", EX4, "--format", "json")
    doc = json.loads(out)
    assert status == 0
    assert doc["degree"] == {"x": 4, "y": 4}
    assert Fraction(doc["coefficients"]["4,4"]) == Fraction(-1, 2880)
    assert doc["nodes"]["x"] == ["1", "2", "3", "4", "5"]


def test_equation_latex_and_horner(run_cli):
    assert run_cli("equation", EX1, "--format", "latex")[1] == "z = x^{2} + 3 y\n"
    status, out, _ = run_cli("equation", EX4, "--format", "horner")
    x, y = sympy.symbols("x y")
    nested = sympy.sympify(out.split(" = ")[1])
    flat = sympy.sympify(run_cli("equation", EX4)[1].split(" = ")[1])
    assert status == 0 and sympy.expand(nested - flat) == 0


def test_equation_python_defines_a_function(run_cli):
    status, out, _ = run_cli("equation", EX4, "--format", "python")
    namespace: dict = {}
    exec(compile(out, "F.py", "exec"), namespace)
    assert status == 0 and abs(namespace["F"](3, 2) - 3.15) < 1e-12


def test_equation_to_file(run_cli, tmp_path):
    out = tmp_path / "eq.txt"
    assert run_cli("equation", EX1, "-o", out) == (0, "", "")
    assert out.read_text() == "z = x**2 + 3*y\n"


def test_check_reports_and_strict(run_cli, tmp_path):
    status, out, _ = run_cli("check", EX4)
    assert status == 0 and "degree in x: 4" in out and "Lebesgue constant" in out and "overshoot" in out
    high = tmp_path / "high.json"
    high.write_text(json.dumps({"x": list(range(9)), "y": [0, 1], "z": [[int(i == 4), 0] for i in range(9)]}))
    status, out, _ = run_cli("check", high)
    assert status == 0 and "WARNING degree in x: 8" in out
    assert run_cli("check", high, "--strict")[0] == 1
    doc = json.loads(run_cli("check", high, "--format", "json")[1])
    assert {f["name"] for f in doc["findings"] if f["warning"]} >= {"degree_x", "lebesgue_x", "overshoot"}


def test_check_curve(run_cli):
    status, out, _ = run_cli("check", CURVE3)
    assert status == 0 and "degree: 3" in out


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
