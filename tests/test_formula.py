"""The strict reference formula parser, fed good formulas and hostile strings."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from lagsym.errors import FormulaError, InputError
from lagsym.formula import FUNCTIONS, MAX_DEPTH, parse_formula


@pytest.mark.parametrize(
    "text, x, y, expected",
    [
        ("0.5*x**2 + y", 3, 1, Fraction(11, 2)),
        ("z = x**2 + 3*y", 1, 2, Fraction(7)),
        ("2**3**2", 0, 0, Fraction(512)),  # right-associative
        ("-x**2", 3, 0, Fraction(-9)),  # ** binds tighter than unary minus
        ("2**-1", 0, 0, Fraction(1, 2)),
        ("x/y/2", 8, 2, Fraction(2)),  # left-associative
        ("1 - 2 - 3", 0, 0, Fraction(-4)),
        ("(x + y) * (x - y)", 5, 3, Fraction(16)),
        ("1.06", 0, 0, Fraction(53, 50)),  # exact decimal, not the nearest double
        ("1e2 * x", Fraction(1, 100), 0, Fraction(1)),
        ("--x", 4, 0, Fraction(4)),
    ],
)
def test_exact_values(text, x, y, expected):
    assert parse_formula(text).exact_value(x, y) == expected


def test_numeric_values_and_functions():
    f = parse_formula("sqrt(abs(x)) + sin(pi*y) + exp(log(2)) + cos(0) + tan(0)")
    np.testing.assert_allclose(f(np.array([-4.0, 9.0]), np.array([0.5, 0.0])), [2 + 1 + 2 + 1, 3 + 0 + 2 + 1])
    assert f.evaluate_grid([1.0, 4.0], [0.0, 0.5, 1.0]).shape == (2, 3)
    assert set(FUNCTIONS) == {"sin", "cos", "tan", "exp", "log", "sqrt", "abs"}


def test_functions_have_no_exact_value():
    with pytest.raises(FormulaError, match="sin has no exact rational value"):
        parse_formula("sin(x)").exact_value(1, 1)
    with pytest.raises(FormulaError, match="exponent 1/2"):
        parse_formula("x**0.5").exact_value(4, 1)


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("__import__('os').system('true')", "unexpected \"'\""),
        ("__import__", "unknown name '__import__'"),
        ("x.__class__", "unexpected '.'"),
        ("().__class__.__bases__[0].__subclasses__()", "unexpected '.'"),
        ("open", "unknown name 'open'"),
        ("eval(x)", "unknown name 'eval'"),
        ("lambda: 1", "unexpected ':'"),
        ("lambda", "unknown name 'lambda'"),
        ("x if y else 1", "unexpected 'if'"),
        ("x; import os", "unexpected ';'"),
        ("[x]", "unexpected '['"),
        ("x, y", "unexpected ','"),
        ("x ^ 2", "write powers as **"),
        ("x == 1", "unexpected '='"),
        ("x = 1", "unexpected '='"),
        ("sin x", "expected '('"),
        ("sin(x, y)", "unexpected ','"),
        ("(x + 1", "expected ')', found the end"),
        ("x +", "found the end of the formula"),
        ("x y", "unexpected 'y'"),
        ("2x", "unexpected 'x'"),
        ("x\\", "unexpected '\\\\'"),
        ("١ + x", "unexpected '١'"),  # a non-ASCII digit
        ("'x'", "unexpected \"'\""),
        ("", "empty"),
        ("   ", "empty"),
        ("1e999999", "out of range"),
        ("x" * 3000, "longer than the limit"),
        ("(" * 500 + "x" + ")" * 500, f"nested more than {MAX_DEPTH}"),
        ("-" * 1000 + "x", f"nested more than {MAX_DEPTH}"),
        ("2" + "**2" * 400, f"nested more than {MAX_DEPTH}"),
        ("sqrt(" * 200 + "x" + ")" * 200, f"nested more than {MAX_DEPTH}"),
    ],
    ids=lambda v: v[:24] if isinstance(v, str) else None,
)
def test_hostile_strings_are_refused_with_a_clear_error(text, fragment):
    with pytest.raises(FormulaError) as info:
        parse_formula(text)
    assert fragment in str(info.value)
    assert isinstance(info.value, InputError)  # the CLI maps it to exit 2


def test_not_text_is_refused():
    with pytest.raises(FormulaError, match="not text"):
        parse_formula(b"x")  # type: ignore[arg-type]


def test_huge_powers_stay_cheap():
    f = parse_formula("9**9**9**9")
    assert math.isinf(float(f(0.0, 0.0)))
    with pytest.raises(FormulaError, match="not an integer within"):
        f.exact_value(0, 0)


def test_division_by_zero():
    assert math.isinf(float(parse_formula("1/x")(0.0, 0.0)))
    with pytest.raises(FormulaError, match="division by zero"):
        parse_formula("1/x").exact_value(0, 1)


def test_formula_is_frozen():
    f = parse_formula("x")
    with pytest.raises(AttributeError):
        f.text = "y"  # type: ignore[misc]


@given(st.text(max_size=60))
def test_any_text_parses_or_raises_formula_error(text):
    try:
        f = parse_formula(text)
    except FormulaError:
        return
    f(np.array([0.5, 2.0]), np.array([1.5, -1.0]))


# Random well-formed formulas, built with their exact value alongside.
_leaf = st.one_of(
    st.integers(0, 20).map(lambda n: (str(n), Fraction(n))),
    st.just(("x", Fraction(3, 2))),
    st.just(("y", Fraction(-2))),
)


def _combine(children):
    def build(parts):
        (a, va), op, (b, vb) = parts
        if op == "/" and vb == 0:
            return f"({a})-({b})", va - vb
        value = {"+": va + vb, "-": va - vb, "*": va * vb, "/": va / vb if vb else 0}[op]
        return f"({a}){op}({b})", value

    return st.tuples(children, st.sampled_from("+-*/"), children).map(build)


@given(st.recursive(_leaf, _combine, max_leaves=12))
def test_generated_formulas_evaluate_exactly_and_numerically(pair):
    text, value = pair
    f = parse_formula(text)
    assert f.exact_value(Fraction(3, 2), -2) == value
    np.testing.assert_allclose(f(1.5, -2.0), float(value), rtol=1e-9, atol=1e-9)


def test_never_reaches_eval_or_sympify(monkeypatch):
    import builtins

    import sympy

    def refuse(*args, **kwargs):
        raise AssertionError("eval-like call")

    monkeypatch.setattr(builtins, "eval", refuse)
    monkeypatch.setattr(builtins, "exec", refuse)
    monkeypatch.setattr(sympy, "sympify", refuse)
    f = parse_formula("z = sqrt(x**2 + y**2) / 2 - 0.5")
    assert float(f(3.0, 4.0)) == 2.0
    assert parse_formula("x*y - 1").exact_value(2, 3) == 5
