"""``lagsym equation``: the exact surface in every output format."""

from __future__ import annotations

import json
from fractions import Fraction

import sympy

from conftest import EXAMPLES

EX1 = EXAMPLES / "paper-example-1.json"
EX4 = EXAMPLES / "paper-example-4.json"


def test_equation_example_1(run_cli):
    assert run_cli("equation", EX1) == (0, "z = x**2 + 3*y\n", "")


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
