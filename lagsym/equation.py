"""The exact polynomial written out: SymPy text, LaTeX, JSON, nested (Horner) form, Python, decimals.

``render(obj, fmt)`` turns a :class:`~lagsym.lagrange.LagrangeSurface` or
:class:`~lagsym.lagrange.LagrangeCurve` into the text ``lagsym equation`` and
``lagsym curve`` print.
"""

from __future__ import annotations

import json
from decimal import ROUND_HALF_EVEN, Decimal, localcontext
from fractions import Fraction

import sympy

from .errors import InputError
from .lagrange import X, Y, LagrangeCurve, LagrangeSurface

__all__ = ["FORMATS", "render", "nested_form", "decimal_text", "round_significant"]

FORMATS = ("sympy", "latex", "json", "horner", "python")


def _lhs(obj) -> str:
    return "z" if isinstance(obj, LagrangeSurface) else "y"


def _coeff_dict(obj) -> dict[tuple[int, ...], Fraction]:
    if isinstance(obj, LagrangeSurface):
        return {(a, b): c for a, row in enumerate(obj.coefficients) for b, c in enumerate(row) if c}
    return {(a,): c for a, c in enumerate(obj.coefficients) if c}


def nested_form(obj) -> sympy.Expr:
    """The polynomial in nested (Horner) form: Horner in x whose coefficients are Horner in y.

    Examples
    --------
    >>> from lagsym import lagrange_curve, curve_from_points
    >>> nested_form(lagrange_curve(curve_from_points([(1, 1), (2, 3), (3, 1)])))
    x*(8 - 2*x) - 5
    """
    if isinstance(obj, LagrangeCurve):
        return sympy.horner(obj.expr, X) if obj.expr.free_symbols else obj.expr
    expr = sympy.Integer(0)
    for row in reversed(obj.coefficients):
        py = sum((sympy.Rational(c.numerator, c.denominator) * Y**b for b, c in enumerate(row)), sympy.Integer(0))
        inner = sympy.horner(py, Y) if py.free_symbols else py
        expr = expr * X + inner
    return expr


def round_significant(value: Fraction, digits: int) -> Decimal:
    """``value`` rounded to ``digits`` significant decimal digits (half to even)."""
    if value == 0:
        return Decimal(0)
    with localcontext() as ctx:
        ctx.prec = digits
        ctx.rounding = ROUND_HALF_EVEN
        return Decimal(value.numerator) / Decimal(value.denominator)


def _decimal_str(d: Decimal) -> str:
    text = format(d, "f")
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def decimal_text(obj, digits: int) -> str:
    """The right-hand side with coefficients rounded to ``digits`` significant digits, as the paper prints them.

    Examples
    --------
    >>> from lagsym import lagrange_curve, curve_from_points
    >>> decimal_text(lagrange_curve(curve_from_points([(1, 1), (2, 3), (3, 2), (4, 3)])), 4)
    '0.8333*x**3 - 6.5*x**2 + 15.67*x - 9'
    """
    if digits < 1:
        raise InputError(f"--digits {digits}: give at least 1 significant digit")
    coeffs = _coeff_dict(obj)
    names = ("x", "y")
    # Graded order, highest total degree first, as SymPy prints.
    keys = sorted(coeffs, key=lambda k: (sum(k), k), reverse=True)
    parts: list[str] = []
    for key in keys:
        d = round_significant(coeffs[key], digits)
        if d == 0:
            continue
        mono = "*".join(
            names[v] if p == 1 else f"{names[v]}**{p}" for v, p in enumerate(key) if p
        )
        mag = _decimal_str(abs(d))
        term = mono if mono and mag == "1" else (f"{mag}*{mono}" if mono else mag)
        sign = "-" if d < 0 else "+"
        parts.append(f"{'-' if sign == '-' else ''}{term}" if not parts else f" {sign} {term}")
    return "".join(parts) if parts else "0"


def _json(obj) -> str:
    coeffs = _coeff_dict(obj)
    if isinstance(obj, LagrangeSurface):
        g = obj.grid
        doc = {
            "equation": f"z = {obj.expr}",
            "variables": ["x", "y"],
            "degree": {"x": obj.degree[0], "y": obj.degree[1]},
            "coefficients": {f"{a},{b}": str(c) for (a, b), c in sorted(coeffs.items())},
            "nodes": {"x": [str(v) for v in g.x], "y": [str(v) for v in g.y]},
        }
    else:
        doc = {
            "equation": f"y = {obj.expr}",
            "variables": ["x"],
            "degree": {"x": obj.degree},
            "coefficients": {str(a): str(c) for (a,), c in sorted(coeffs.items())},
            "nodes": {"x": [str(v) for v in obj.points.x]},
        }
    return json.dumps(doc, indent=2)


def _python(obj) -> str:
    args = "x, y" if isinstance(obj, LagrangeSurface) else "x"
    what = (
        f"tensor-product Lagrange surface of degree {obj.degree[0]} x {obj.degree[1]}"
        if isinstance(obj, LagrangeSurface)
        else f"Lagrange curve of degree {obj.degree}"
    )
    src = getattr(obj.grid if isinstance(obj, LagrangeSurface) else obj.points, "source", "")
    return (
        f"def F({args}):\n"
        f'    """{_lhs(obj)} = F({args}): {what} through the points of {src}."""\n'
        f"    return {nested_form(obj)}\n"
    )


def render(obj, fmt: str = "sympy", digits: int | None = None) -> str:
    """The equation of a surface or curve as text in format ``fmt`` (one of :data:`FORMATS`).

    ``digits`` rounds the coefficients to that many significant digits (``sympy``
    and ``latex`` formats only), the way the paper prints them.
    """
    if fmt not in FORMATS:
        raise InputError(f"unknown format {fmt!r}; choose one of {', '.join(FORMATS)}")
    lhs = _lhs(obj)
    if digits is not None:
        rhs = decimal_text(obj, digits)
        if fmt == "sympy":
            return f"{lhs} = {rhs}"
        if fmt == "latex":
            return f"{lhs} = {sympy.latex(sympy.sympify(rhs, locals={'x': X, 'y': Y}))}"
        raise InputError(f"--digits goes with --format sympy or latex, not {fmt}")
    if fmt == "sympy":
        return f"{lhs} = {obj.expr}"
    if fmt == "latex":
        return f"{lhs} = {sympy.latex(obj.expr)}"
    if fmt == "horner":
        return f"{lhs} = {nested_form(obj)}"
    if fmt == "python":
        return _python(obj).rstrip("\n")
    return _json(obj)
