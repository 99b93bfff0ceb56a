"""The exact surface in a SymPy session: the symbols a user types, the rich display, rounded equations."""

from __future__ import annotations

import dataclasses
from decimal import Decimal
from fractions import Fraction

import pytest
import sympy

from lagsym import lagrange_curve, lagrange_surface, read_curve_points, read_points
from lagsym.equation import FORMATS, decimal_text, render, rounded_coefficients, rounding_miss
from lagsym.errors import InputError
from lagsym.grid import curve_from_points, grid_from_table

from conftest import EXAMPLES

x, y = sympy.symbols("x y")
SURFACES = sorted(p for p in EXAMPLES.glob("*.json") if "curve" not in p.name and "printed" not in p.name)
CURVES = sorted(EXAMPLES.glob("paper-curve-*.json"))


def example1():
    return lagrange_surface(read_points(EXAMPLES / "paper-example-1.json"))


@pytest.mark.slow
def test_the_symbols_a_user_types_work_everywhere():
    expr = example1().expr
    assert expr == x**2 + 3 * y
    assert expr.subs({x: 1, y: 2}) == 7
    assert sympy.diff(expr, x) == 2 * x and sympy.diff(expr, y) == 3
    assert sympy.integrate(expr, (x, 1, 5), (y, 2, 4)) == sympy.Rational(248, 3) + 72
    assert sympy.solve(expr - 7, y) == [sympy.Rational(7, 3) - x**2 / 3]
    assert example1().expr.free_symbols == {x, y}


def test_a_curve_in_the_users_x():
    curve = lagrange_curve(read_curve_points(EXAMPLES / "paper-curve-2nd.json"))
    assert curve.expr == -2 * x**2 + 8 * x - 5
    assert sympy.solve(sympy.diff(curve.expr, x), x) == [2]
    assert sympy.integrate(curve.expr, (x, 1, 3)) == sympy.Rational(14, 3)


def test_the_callers_own_symbols():
    u, v, t = sympy.symbols("u v t")
    s = lagrange_surface(read_points(EXAMPLES / "paper-example-1.json"), x=u, y=v)
    assert s.symbols == (u, v) and s.expr == u**2 + 3 * v
    assert s.basis_x[0].gens == (u,) and s.basis_y[0].gens == (v,)
    assert s.derivative(1, 0).as_expr() == 2 * u
    assert render(s) == "z = u**2 + 3*v" and render(s, "latex") == "z = u^{2} + 3 v"
    assert render(s, digits=3) == "z = u**2 + 3*v"
    c = lagrange_curve(read_curve_points(EXAMPLES / "paper-curve-2nd.json"), x="t")
    assert c.expr == -2 * t**2 + 8 * t - 5 and c.basis[0].gens == (t,)
    assert render(c, "python").startswith("def F(t):")
    # Two values with other symbols are other values.
    assert s != example1() and s == lagrange_surface(s.grid, x=u, y=v)


def test_symbols_are_checked():
    g = read_points(EXAMPLES / "paper-example-1.json")
    with pytest.raises(InputError, match="both the symbol x"):
        lagrange_surface(g, x=x, y=x)
    with pytest.raises(InputError, match="not a SymPy symbol"):
        lagrange_surface(g, x=x + 1)


@pytest.mark.parametrize("path", SURFACES + CURVES, ids=lambda p: p.name)
def test_every_cli_sympy_output_reads_back_equal(run_cli, path):
    command = "curve" if "curve" in path.name else "equation"
    obj = (lagrange_curve(read_curve_points(path)) if command == "curve" else lagrange_surface(read_points(path)))
    status, out, _ = run_cli(command, path)
    assert status == 0 and sympy.sympify(out.split(" = ", 1)[1]) == obj.expr
    nested = sympy.sympify(run_cli(command, path, "--format", "horner")[1].split(" = ", 1)[1])
    assert sympy.expand(nested) == obj.expr
    assert run_cli(command, path, "--format", "latex")[1] == f"{out[0]} = {sympy.latex(obj.expr)}\n"
    rounded = sympy.sympify(run_cli(command, path, "--digits", "6")[1].split(" = ", 1)[1])
    assert rounded.free_symbols <= obj.expr.free_symbols


def test_repr_is_short_and_the_latex_display_is_the_equation():
    s = example1()
    assert repr(s) == f"LagrangeSurface(3x3 nodes, degree (2, 2), source={s.grid.source!r})"
    assert s._repr_latex_() == "$z = x^{2} + 3 y$"
    c = lagrange_curve(curve_from_points([(1, 1), (2, 3), (3, 1)]))
    assert repr(c) == "LagrangeCurve(3 points, degree 2, source='<points>')"
    assert c._repr_latex_() == "$y = - 2 x^{2} + 8 x - 5$"
    u = sympy.Symbol("u")
    assert "x=u" in repr(lagrange_curve(c.points, x=u))


def test_a_large_surface_displays_a_summary():
    n = 12
    g = grid_from_table(range(n), range(n), [[(i * 7 + k * 3) % 5 for k in range(n)] for i in range(n)])
    text = lagrange_surface(g)._repr_latex_()
    assert text.startswith("$z = F$ (degree 11 x 11") and len(text) < 200


def test_values_stay_frozen():
    s = example1()
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.symbols = (y, x)


def test_tiny_coefficients_print_in_scientific_notation():
    # Node spacing 1e-3 scales the cubic coefficient up; a spacing of 1e3 scales it down to about 1e-9.
    c = lagrange_curve(curve_from_points([(0, 0), (1000, 1), (2000, 0), (3000, 2)]))
    text = decimal_text(c, 4)
    assert "e-10*x**3" in text and "0.0000" not in text
    assert sympy.sympify(text, rational=True).coeff(x, 3) == sympy.Rational("8.333e-10")
    assert rounded_coefficients(c, 4)[(3,)] == Decimal("8.333E-10")


def test_rounding_miss_is_exact():
    """The miss is |z - F_rounded| at the control points in rationals, checked here against SymPy."""
    path = EXAMPLES / "paper-example-4.json"
    s = lagrange_surface(read_points(path))
    miss = rounding_miss(s, 4)
    rounded = sympy.sympify(decimal_text(s, 4), rational=True)
    exact = [abs(sympy.Rational(z.numerator, z.denominator) - rounded.subs({x: xi, y: yk}))
             for xi, yk, z in s.grid.points()]
    assert miss.largest == Fraction(str(max(exact)))
    assert miss.largest == Fraction(11, 8) and miss.at == (5, 5, Fraction(53, 50))
    assert 0 < rounding_miss(s, 30).largest < Fraction(1, 10**25)


def dome():
    """docs/equations.md's dome: 6x6 nodes at 12.5 mm, heights 9 exp(-r**2 / 900) mm to the hundredth."""
    import math

    nodes = [Fraction(25, 2) * i for i in range(6)]
    z = [[Fraction(round(900 * math.exp(-((float(a) - 31.25) ** 2 + (float(b) - 31.25) ** 2) / 900)), 100)
          for b in nodes] for a in nodes]
    return nodes, z


def test_a_measured_grid_rounded_to_4_digits_misses_by_tenths_of_a_millimetre(run_cli, tmp_path):
    import json

    nodes, z = dome()
    g = grid_from_table(nodes, nodes, z)
    assert g.z_range() == (Fraction("1.03"), Fraction("8.25"))
    misses = {d: float(rounding_miss(lagrange_surface(g), d).largest) for d in (4, 5, 6)}
    assert {d: f"{v:.3g}" for d, v in misses.items()} == {4: "0.392", 5: "0.0308", 6: "0.00557"}
    path = tmp_path / "dome.json"
    path.write_text(json.dumps({"units": "mm", "x": [str(v) for v in nodes], "y": [str(v) for v in nodes],
                                "z": [[str(v) for v in row] for row in z]}))
    status, out, err = run_cli("equation", path, "--digits", "4")
    assert status == 0 and out.count("\n") == 1 and sympy.sympify(out.split(" = ")[1]).free_symbols == {x, y}
    assert err == ("# rounded to 4 significant digits, the equation misses the control points by up to 0.392 mm "
                   "(at the point (62.5, 62.5, 1.03)); without --digits it passes through all of them exactly\n")


@pytest.mark.parametrize("fmt", [f for f in FORMATS if f not in ("sympy", "latex")])
def test_digits_goes_only_with_sympy_and_latex(fmt):
    with pytest.raises(InputError, match="--digits goes with"):
        render(example1(), fmt, 3)
