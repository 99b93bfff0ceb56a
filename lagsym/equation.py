"""The exact polynomial written out: SymPy text, LaTeX, JSON, nested (Horner) form, Python, decimals.

``render(obj, fmt)`` turns a :class:`~lagsym.lagrange.LagrangeSurface` or
:class:`~lagsym.lagrange.LagrangeCurve` into the text ``lagsym equation`` and
``lagsym curve`` print.  With variables named by single letters (``x`` and
``y``, always so on the command line) the text is written from the exact
coefficients by :mod:`lagsym.polytext`, the characters SymPy would print, and
SymPy is not imported; other variable names go through SymPy's printers.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from decimal import ROUND_HALF_EVEN, Decimal, localcontext
from fractions import Fraction

from typing import TYPE_CHECKING

import flint

from . import polytext
from .errors import InputError
from .lagrange import LagrangeCurve, LagrangeSurface

if TYPE_CHECKING:
    import sympy

__all__ = ["FORMATS", "render", "nested_form", "decimal_text", "round_significant", "rounded_coefficients",
           "RoundingMiss", "rounding_miss", "MAX_TERMS"]

FORMATS = ("sympy", "latex", "json", "horner", "python")
MAX_TERMS = 2_500  # terms SymPy prints by default: a 50 x 50 grid; SymPy prints term by term, so a larger one waits


def _lhs(obj) -> str:
    return "z" if isinstance(obj, LagrangeSurface) else "y"


def _symbols(obj) -> tuple[sympy.Symbol, ...]:
    return obj.symbols if isinstance(obj, LagrangeSurface) else (obj.symbol,)


def _names(obj) -> tuple:
    """The variables as the value keeps them: names (str) of plain symbols, else the symbols."""
    return obj.variables if isinstance(obj, LagrangeSurface) else (obj.variable,)


def _fast(obj) -> bool:
    return polytext.supported(_names(obj))


def _expr_text(obj) -> str:
    """``str(obj.expr)``, without SymPy where :mod:`lagsym.polytext` can write it."""
    return polytext.plain_text(_coeff_dict(obj), _names(obj)) if _fast(obj) else str(obj.expr)


def _nested_text(obj) -> str:
    """``str(nested_form(obj))``, without SymPy where :mod:`lagsym.polytext` can write it."""
    return polytext.nested_text(obj.coefficients, _names(obj)) if _fast(obj) else str(nested_form(obj))


def _coeff_dict(obj) -> dict[tuple[int, ...], Fraction]:
    if isinstance(obj, LagrangeSurface):
        return {(a, b): c for a, row in enumerate(obj.coefficients) for b, c in enumerate(row) if c}
    return {(a,): c for a, c in enumerate(obj.coefficients) if c}


def _latex_text(obj) -> str:
    if _fast(obj):
        return polytext.latex_text(_coeff_dict(obj), _names(obj))
    import sympy

    return sympy.latex(obj.expr)


def nested_form(obj) -> sympy.Expr:
    """The polynomial in nested (Horner) form: Horner in x whose coefficients are Horner in y.

    Examples
    --------
    >>> from lagsym import lagrange_curve, curve_from_points
    >>> nested_form(lagrange_curve(curve_from_points([(1, 1), (2, 3), (3, 1)])))
    x*(8 - 2*x) - 5
    """
    import sympy

    if isinstance(obj, LagrangeCurve):
        return sympy.horner(obj.expr, obj.symbol) if obj.expr.free_symbols else obj.expr
    sx, sy = obj.symbols
    expr = sympy.Integer(0)
    for row in reversed(obj.coefficients):
        py = sum((sympy.Rational(c.numerator, c.denominator) * sy**b for b, c in enumerate(row)), sympy.Integer(0))
        inner = sympy.horner(py, sy) if py.free_symbols else py
        expr = expr * sx + inner
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
    # Scientific notation where Python's repr of a float uses it: a tiny
    # coefficient as 2.983e-16, not 0.0000000000000002983.
    exponent = d.adjusted()
    if d and (exponent < -4 or exponent >= 16):
        mantissa = (d.scaleb(-exponent)).normalize()
        return f"{_decimal_str(mantissa)}e{exponent:+03d}"
    text = format(d, "f")
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def rounded_coefficients(obj, digits: int) -> dict[tuple[int, ...], Decimal]:
    """The nonzero coefficients rounded to ``digits`` significant digits, keyed by exponents.

    Examples
    --------
    >>> from lagsym import lagrange_curve, curve_from_points
    >>> rounded_coefficients(lagrange_curve(curve_from_points([(1, 1), (2, 3), (3, 2), (4, 3)])), 2)
    {(0,): Decimal('-9'), (1,): Decimal('16'), (2,): Decimal('-6.5'), (3,): Decimal('0.83')}
    """
    if digits < 1:
        raise InputError(f"--digits {digits}: give at least 1 significant digit")
    out = {}
    for key, c in sorted(_coeff_dict(obj).items()):
        d = round_significant(c, digits)
        if d:
            out[key] = d
    return out


def decimal_text(obj, digits: int) -> str:
    """The right-hand side with coefficients rounded to ``digits`` significant digits, as the paper prints them.

    Examples
    --------
    >>> from lagsym import lagrange_curve, curve_from_points
    >>> decimal_text(lagrange_curve(curve_from_points([(1, 1), (2, 3), (3, 2), (4, 3)])), 4)
    '0.8333*x**3 - 6.5*x**2 + 15.67*x - 9'
    """
    coeffs = rounded_coefficients(obj, digits)
    names = tuple(str(s) for s in _names(obj))
    # Graded order, highest total degree first, as SymPy prints.
    keys = sorted(coeffs, key=lambda k: (sum(k), k), reverse=True)
    parts: list[str] = []
    for key in keys:
        d = coeffs[key]
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
            "equation": f"z = {_expr_text(obj)}",
            "variables": [str(v) for v in obj.variables],
            "degree": {"x": obj.degree[0], "y": obj.degree[1]},
            "coefficients": {f"{a},{b}": polytext.fraction_text(c) for (a, b), c in sorted(coeffs.items())},
            "nodes": {"x": [str(v) for v in g.x], "y": [str(v) for v in g.y]},
        }
    else:
        doc = {
            "equation": f"y = {_expr_text(obj)}",
            "variables": [str(obj.variable)],
            "degree": {"x": obj.degree},
            "coefficients": {str(a): polytext.fraction_text(c) for (a,), c in sorted(coeffs.items())},
            "nodes": {"x": [str(v) for v in obj.points.x]},
        }
    return json.dumps(doc, indent=2)


def _python(obj) -> str:
    args = ", ".join(str(v) for v in _names(obj))
    what = (
        f"tensor-product Lagrange surface of degree {obj.degree[0]} x {obj.degree[1]}"
        if isinstance(obj, LagrangeSurface)
        else f"Lagrange curve of degree {obj.degree}"
    )
    src = getattr(obj.grid if isinstance(obj, LagrangeSurface) else obj.points, "source", "")
    # The file name is the user's text: written through repr, it is a string literal whatever it holds
    # (quotes, backslashes, newlines), never code.
    doc = f"{_lhs(obj)} = F({args}): {what} through the points of {src}."
    return (
        f"def F({args}):\n"
        f"    {doc!r}\n"
        f"    return {_nested_text(obj)}\n"
    )


def render(obj, fmt: str = "sympy", digits: int | None = None, max_terms: int | None = MAX_TERMS) -> str:
    """The equation of a surface or curve as text in format ``fmt`` (one of :data:`FORMATS`).

    ``digits`` rounds the coefficients to that many significant digits (``sympy``
    and ``latex`` formats only), the way the paper prints them.  An equation of
    more than ``max_terms`` terms (``--max-terms``) is refused before SymPy
    builds it, except the rounded ``sympy`` text, which is written straight
    from the exact coefficients; None for no limit.
    """
    if fmt not in FORMATS:
        raise InputError(f"unknown format {fmt!r}; choose one of {', '.join(FORMATS)}")
    lhs = _lhs(obj)
    if digits is not None and fmt == "sympy":
        return f"{lhs} = {decimal_text(obj, digits)}"
    terms = len(_coeff_dict(obj))
    if max_terms is not None and terms > max_terms:
        raise InputError(f"the equation has {terms} terms, more than the limit of {max_terms} (about "
                         f"{terms * 0.002:.0f} s to print); use --digits N with the sympy format, or raise the "
                         f"limit (--max-terms)")
    if digits is not None:
        rhs = decimal_text(obj, digits)
        if fmt == "latex" and _fast(obj):
            coeffs = {k: (d < 0, _decimal_str(abs(d))) for k, d in rounded_coefficients(obj, digits).items()}
            return f"{lhs} = {polytext.latex_decimal_text(coeffs, _names(obj))}"
        if fmt == "latex":
            import sympy

            names = {str(v): v for v in _symbols(obj)}
            return f"{lhs} = {sympy.latex(sympy.sympify(rhs, locals=names))}"
        raise InputError(f"--digits goes with --format sympy or latex, not {fmt}")
    if fmt == "sympy":
        return f"{lhs} = {_expr_text(obj)}"
    if fmt == "latex":
        return f"{lhs} = {_latex_text(obj)}"
    if fmt == "horner":
        return f"{lhs} = {_nested_text(obj)}"
    if fmt == "python":
        return _python(obj).rstrip("\n")
    return _json(obj)


@dataclass(frozen=True)
class RoundingMiss:
    """How far the equation with rounded coefficients misses the control points, exactly.

    Attributes
    ----------
    digits : int
        Significant digits the coefficients were rounded to.
    largest : Fraction
        The largest ``|z_ik - F_rounded(x_i, y_k)|`` over the control points (``|y_i - F(x_i)|``
        for a curve), exact.
    at : tuple of Fraction
        The control point where it is largest, ``(x, y, z)`` (``(x, y)`` for a curve).
    """

    digits: int
    largest: Fraction
    at: tuple[Fraction, ...]

    def text(self, units: str | None = None) -> str:
        """One line saying it, for standard error or a comment."""
        unit = f" {units}" if units else ""
        where = ", ".join(_decimal_str(round_significant(v, 12)) for v in self.at)
        if not self.largest:
            return f"rounded to {self.digits} significant digits, the equation still passes through every control point"
        return (f"rounded to {self.digits} significant digits, the equation misses the control points by up to "
                f"{_decimal_str(round_significant(self.largest, 3))}{unit} (at the point ({where})); "
                f"without --digits it passes through all of them exactly")


def _fmpq(v: Fraction) -> flint.fmpq:
    return flint.fmpq(v.numerator, v.denominator)


def _vandermonde(nodes, size: int) -> flint.fmpq_mat:
    return flint.fmpq_mat(len(nodes), size, [_fmpq(v) ** a for v in nodes for a in range(size)])


def rounding_miss(obj, digits: int) -> RoundingMiss:
    """Evaluate the rounded equation in exact rationals at every control point: the largest miss and where.

    Examples
    --------
    >>> from lagsym import lagrange_curve, curve_from_points
    >>> miss = rounding_miss(lagrange_curve(curve_from_points([(1, 1), (2, 3), (3, 2), (4, 3)])), 4)
    >>> miss.largest, miss.at
    (Fraction(7, 625), (Fraction(4, 1), Fraction(3, 1)))
    """
    rounded = {k: Fraction(d) for k, d in rounded_coefficients(obj, digits).items()}
    if isinstance(obj, LagrangeCurve):
        xs, values = obj.points.x, obj.points.y
        got = [sum((c * x ** a for (a,), c in rounded.items()), Fraction(0)) for x in xs]
        misses = [(abs(v - g), (x, v)) for x, v, g in zip(xs, values, got)]
    else:
        g = obj.grid
        n, m = g.shape
        c = flint.fmpq_mat(n, m, [_fmpq(rounded.get((a, b), Fraction(0))) for a in range(n) for b in range(m)])
        # All n * m values at once: F(x_i, y_k) = (Vx C Vy^T)[i, k], exact.
        f = _vandermonde(g.x, n) * c * _vandermonde(g.y, m).transpose()
        misses = []
        for i, xi in enumerate(g.x):
            for k, yk in enumerate(g.y):
                v = Fraction(int(f[i, k].p), int(f[i, k].q))
                misses.append((abs(g.z[i][k] - v), (xi, yk, g.z[i][k])))
    largest, at = max(misses, key=lambda t: t[0])
    return RoundingMiss(digits=digits, largest=largest, at=at)
