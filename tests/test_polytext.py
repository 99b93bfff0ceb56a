"""The equation printed without SymPy is the text SymPy's own printers give for the same polynomial."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from fractions import Fraction

import pytest
import sympy
from hypothesis import given
from hypothesis import strategies as st

from lagsym import lagrange_curve, lagrange_surface, read_curve_points, read_points
from lagsym.equation import FORMATS, nested_form, render
from lagsym.lagrange import LagrangeCurve, LagrangeSurface
from lagsym.polytext import latex_text, nested_text, plain_text, supported

from conftest import EXAMPLES, ROOT

SURFACES = sorted(p for p in EXAMPLES.glob("*.json") if "curve" not in p.name and "printed" not in p.name)
CURVES = sorted(EXAMPLES.glob("paper-curve-*.json"))
DIGITS = (None, 1, 2, 3, 4, 6, 12, 20)


def _sympy_route(obj):
    """The same value with SymPy symbols as its variables: render then prints through SymPy's printers."""
    if isinstance(obj, LagrangeSurface):
        return dataclasses.replace(obj, variables=tuple(sympy.Symbol(str(v)) for v in obj.variables))
    return dataclasses.replace(obj, variable=sympy.Symbol(str(obj.variable)))


def _examples():
    return ([lagrange_surface(read_points(p)) for p in SURFACES]
            + [lagrange_curve(read_curve_points(p)) for p in CURVES])


def test_the_sympy_route_is_taken_for_symbols():
    s = _sympy_route(lagrange_surface(read_points(EXAMPLES / "paper-example-1.json")))
    assert not supported(s.variables) and supported(("x", "y")) and not supported(("x", "x"))


@pytest.mark.parametrize("fmt", FORMATS)
def test_every_example_prints_as_sympy_prints_it(fmt):
    for obj in _examples():
        slow = _sympy_route(obj)
        for digits in DIGITS if fmt in ("sympy", "latex") else (None,):
            assert render(obj, fmt, digits) == render(slow, fmt, digits), (obj, fmt, digits)


coefficient = st.one_of(st.just(Fraction(0)), st.just(Fraction(1)), st.just(Fraction(-1)),
                        st.fractions(max_denominator=10**6).filter(lambda f: abs(f) < 10**9))


@given(st.lists(st.lists(coefficient, min_size=1, max_size=4), min_size=1, max_size=4),
       st.sampled_from([("x", "y"), ("y", "x"), ("b", "a"), ("u", "v")]))
def test_random_surfaces_print_as_sympy_prints_them(rows, names):
    m = max(len(r) for r in rows)
    coeffs = tuple(tuple(r) + (Fraction(0),) * (m - len(r)) for r in rows)
    s = LagrangeSurface(grid=None, coefficients=coeffs, variables=names)
    terms = {(a, b): c for a, row in enumerate(coeffs) for b, c in enumerate(row) if c}
    expr = s.expr
    assert plain_text(terms, names) == str(expr)
    assert latex_text(terms, names) == sympy.latex(expr)
    assert nested_text(coeffs, names) == str(nested_form(s))
    for digits in (1, 3, 5):
        assert render(s, "latex", digits) == render(_sympy_route(s), "latex", digits)


@given(st.lists(coefficient, min_size=1, max_size=7), st.sampled_from(["x", "t"]))
def test_random_curves_print_as_sympy_prints_them(coeffs, name):
    c = LagrangeCurve(points=None, coefficients=tuple(coeffs), variable=name)
    terms = {(a,): v for a, v in enumerate(coeffs) if v}
    assert plain_text(terms, (name,)) == str(c.expr)
    assert latex_text(terms, (name,)) == sympy.latex(c.expr)
    assert nested_text(coeffs, (name,)) == str(nested_form(c))
    for digits in (1, 2, 4, 17):
        assert render(c, "latex", digits) == render(_sympy_route(c), "latex", digits)


@pytest.mark.parametrize("text", ["1e+20", "1e-05", "8.333e-10", "123456789012345678.5", "0.0001234", "6.5",
                                  "1234567890123456789", "9.999999999999999999e+30"])
def test_decimal_coefficients_in_latex_as_sympy_reads_and_prints_them(text):
    c = LagrangeCurve(points=None, coefficients=(Fraction(text), Fraction(-text.count("5") - 1)), variable="x")
    assert render(c, "latex", 20) == render(_sympy_route(c), "latex", 20)


@pytest.mark.parametrize("argv", [
    ["equation", "examples/paper-example-4.json"],
    ["equation", "examples/paper-example-4.json", "--format", "latex", "--digits", "4"],
    ["equation", "examples/paper-example-3.json", "--format", "json"],
    ["equation", "examples/paper-example-2.json", "--format", "horner"],
    ["equation", "examples/paper-example-4.json", "--format", "python"],
    ["curve", "examples/paper-curve-3rd.json", "--digits", "3"],
])
def test_the_equation_is_printed_without_importing_sympy(argv):
    code = ("import io, sys, lagsym.cli; out = io.StringIO(); "
            f"status = lagsym.cli.main({argv!r}, out, io.StringIO()); "
            "print(status, len(out.getvalue()) > 10, 'sympy' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["0", "True", "False"]
