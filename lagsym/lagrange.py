"""Exact Lagrange curves and tensor-product surfaces (the paper's eqs. 1-3 and 6-7).

The polynomial is derived in exact rational arithmetic.  Each 1-D basis
polynomial ``L_i(x) = prod_{j != i} (x - x_j) / (x_i - x_j)`` is found by one
exact division of the node polynomial ``w(x) = prod_j (x - x_j)``; their
power-basis coefficients form a matrix ``Bx`` with ``Bx[i, a]`` the coefficient
of ``x**a`` in ``L_i``.  The surface ``F(x, y) = sum_ik L_i(x) L_k(y) z_ik`` then
has the coefficient matrix ``C = Bx.T @ Z @ By`` (``C[a, b]`` multiplies
``x**a * y**b``), computed with python-flint's exact rational matrices.  This
avoids expanding ``n * m`` symbolic products, the textbook route: each
would be a SymPy expression built and expanded term by term, where the
matrix product is one exact computation on the coefficients.

The polynomials are built on plain SymPy symbols, ``x`` and ``y`` by default,
the ones ``sympy.symbols('x y')`` gives, so that ``subs``, ``diff``,
``integrate``, ``solve`` and ``==`` work with the symbols a user types; pass
``x=`` and ``y=`` to use others.  SymPy is imported only when a SymPy value
(:attr:`~LagrangeSurface.expr`, ``poly``, ``symbols``, a basis) is first asked
for: the exact coefficients and the printed equation (:mod:`lagsym.polytext`)
need none of it, and the import alone takes most of a second.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property

from typing import TYPE_CHECKING

import flint

from .errors import InputError
from .exactsize import MAX_EXACT_MB, ExactClock, check_exact_size, stepped_product
from .exactsize import to_fraction as _frac
from .values import MAX_NAME, as_exact, check_name, of_type  # noqa: F401 - MAX_NAME: where the name check was

from .grid import ControlGrid, CurvePoints

__all__ = [
    "X",
    "Y",
    "LagrangeCurve",
    "LagrangeSurface",
    "lagrange_curve",
    "lagrange_surface",
    "lagrange_basis",
    "basis_coefficients",
    "horner2",
]

if TYPE_CHECKING:
    import sympy

LATEX_TERMS = 120  # a rich display longer than this shows a summary, not a page of LaTeX


def __getattr__(name: str):
    # X and Y, the plain symbols x and y, made when first asked for, so that importing this module
    # does not import SymPy.  Plain symbols: a symbol with assumptions (real=True) is a different
    # symbol from the x a user types, and every subs, diff or == with it silently fails.
    if name in ("X", "Y"):
        import sympy

        return sympy.Symbol(name.lower())
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _variable(value, what: str):
    """A variable as the value keeps it: a plain symbol by its name (no SymPy needed), any other symbol itself."""
    if isinstance(value, str):
        return check_name(value, what)
    import sympy

    if not isinstance(value, sympy.Symbol):
        raise InputError(f"{what} = {value!r} is not a SymPy symbol or a name")
    check_name(value.name, what)
    return value.name if type(value) is sympy.Symbol and value == sympy.Symbol(value.name) else value


def _symbols_of(variables) -> tuple:
    import sympy

    return tuple(sympy.Symbol(v) if isinstance(v, str) else v for v in variables)


def _fmpq(v: Fraction) -> flint.fmpq:
    return flint.fmpq(v.numerator, v.denominator)


def _basis_polys(nodes: tuple[Fraction, ...], clock: ExactClock) -> list[flint.fmpq_poly]:
    w = flint.fmpq_poly([1])
    for xj in nodes:
        w *= flint.fmpq_poly([-_fmpq(xj), 1])
    out, started = [], time.perf_counter()
    for k, xi in enumerate(nodes):
        q = w // flint.fmpq_poly([-_fmpq(xi), 1])
        out.append(q / q(_fmpq(xi)))
        clock.foresee(k + 1, len(nodes), time.perf_counter() - started, 1)  # the rows' numbers follow
    return out


def _basis_matrix(nodes: tuple[Fraction, ...], source=None) -> flint.fmpq_mat:
    # A division and a normalisation a node, then a row's coefficients made into numbers (most of the time),
    # each about as long as the others: one clock foresees the basis from its first rows and refuses it past the
    # time limit, as it does the products that follow.
    n = len(nodes)
    clock = ExactClock(f"Lagrange basis on {n} nodes", source)
    rows, polys = [], _basis_polys(nodes, clock)
    started = time.perf_counter()
    for k, p in enumerate(polys):
        c = p.coeffs()
        rows.extend(c + [flint.fmpq(0)] * (n - len(c)))
        clock.foresee(k + 1, n, time.perf_counter() - started, 0)
    return flint.fmpq_mat(n, n, rows)


def _node(v, i: int) -> Fraction:
    # Text by the one exact-number policy (which bounds its exponent); a number as its exact value.
    if isinstance(v, str) or isinstance(v, bool):
        return as_exact(v, f"node {i}")
    try:
        return Fraction(v)
    except (TypeError, ValueError, OverflowError, ZeroDivisionError):
        raise InputError(f"node {i} = {v!r:.80} is not a finite number") from None


def _distinct_nodes(nodes) -> tuple[Fraction, ...]:
    """``nodes`` as exact rationals, checked: a basis needs at least one node and no two alike."""
    try:
        values = tuple(_node(v, i) for i, v in enumerate(nodes))
    except TypeError:
        raise InputError(f"nodes = {nodes!r:.80} is not a sequence of numbers") from None
    if not values:
        raise InputError("nodes = () is empty: a basis needs at least one node")
    seen: dict[Fraction, int] = {}
    for i, v in enumerate(values):
        if v in seen:
            raise InputError(f"nodes {seen[v]} and {i} are both {v}: a Lagrange basis needs distinct nodes")
        seen[v] = i
    return values


def basis_coefficients(nodes, *, max_mb: float | None = MAX_EXACT_MB) -> tuple[tuple[Fraction, ...], ...]:
    """Power-basis coefficients of the Lagrange basis on ``nodes``.

    Row ``i`` holds the coefficients of ``L_i`` from the constant term up.
    ``max_mb``: refuse, before any work, a basis estimated at more megabytes
    (as :func:`lagrange_curve`; :mod:`lagsym.exactsize`).

    Examples
    --------
    >>> basis_coefficients([1, 2, 3])[0]
    (Fraction(3, 1), Fraction(-5, 2), Fraction(1, 2))
    """
    nodes = _distinct_nodes(nodes)
    check_exact_size(f"basis on {len(nodes)} nodes", None, nodes, None, (), max_mb)
    m = _basis_matrix(nodes)
    n = len(nodes)
    return tuple(tuple(_frac(m[i, a]) for a in range(n)) for i in range(n))


def lagrange_basis(nodes, symbol: sympy.Symbol | str = "x", *,
                   max_mb: float | None = MAX_EXACT_MB) -> tuple[sympy.Poly, ...]:
    """The Lagrange basis polynomials ``L_i`` on ``nodes`` as exact ``sympy.Poly`` over QQ.

    ``max_mb``: refuse, before any work, a basis estimated at more megabytes
    (``--max-exact-mb``; :func:`basis_coefficients`).

    Examples
    --------
    >>> [p.as_expr() for p in lagrange_basis([1, 2, 3])][1]
    -x**2 + 4*x - 3
    """
    (symbol,) = _symbols_of((_variable(symbol, "symbol"),))
    return tuple(_poly1(row, symbol) for row in basis_coefficients(nodes, max_mb=max_mb))


def _poly1(coeffs, symbol) -> sympy.Poly:
    import sympy

    # The domain's own rationals, not sympy.Rational: no expression is made for each coefficient (2.5x sooner).
    qq = sympy.QQ
    return sympy.Poly.from_list([qq(c.numerator, c.denominator) for c in reversed(coeffs)], symbol, domain=qq)


@dataclass(frozen=True)
class LagrangeCurve:
    """The Lagrange interpolating polynomial ``y = F(x)`` through a set of points.

    Attributes
    ----------
    points : CurvePoints
        The nodes and values.
    coefficients : tuple of Fraction
        ``coefficients[a]`` multiplies ``x**a``.
    variable : str or sympy.Symbol
        The variable: the name of a plain symbol (``"x"`` by default), or the
        symbol itself if it carries assumptions.
    symbol : sympy.Symbol
        The variable of :attr:`poly`, :attr:`expr` and :attr:`basis` (made on
        first use).

    In Jupyter the curve shows as its equation in LaTeX and, once ``import lagsym`` has
    registered the display, a small line plot (:mod:`lagsym.plot.inline`).
    """

    points: CurvePoints
    coefficients: tuple[Fraction, ...]
    variable: str | sympy.Symbol = "x"

    def __post_init__(self):
        _variable(self.variable, "x")  # checked; kept as given (a plain symbol stays a symbol)

    @cached_property
    def symbol(self) -> sympy.Symbol:
        """The variable as a SymPy symbol."""
        return _symbols_of((self.variable,))[0]

    @property
    def degree(self) -> int:
        """Degree of the interpolant (one less than the number of points)."""
        return len(self.points.x) - 1

    @cached_property
    def poly(self) -> sympy.Poly:
        """The curve as a ``sympy.Poly`` in :attr:`symbol` over QQ."""
        return _poly1(self.coefficients, self.symbol)

    @cached_property
    def expr(self) -> sympy.Expr:
        """The curve as an exact SymPy expression in :attr:`symbol`."""
        return self.poly.as_expr()

    @cached_property
    def basis(self) -> tuple[sympy.Poly, ...]:
        """The basis polynomials ``L_i(x)`` (paper eq. 2)."""
        return lagrange_basis(self.points.x, self.symbol, max_mb=None)  # its size checked with the curve

    def __repr__(self) -> str:
        sym = "" if self.variable == "x" else f", x={self.variable}"
        return f"LagrangeCurve({len(self.points.x)} points, degree {self.degree}{sym}, source={self.points.source!r})"

    def _repr_latex_(self) -> str:
        return _latex("y", self.expr, len([c for c in self.coefficients if c]), f"degree {self.degree}")

    def exact_value(self, x) -> Fraction:
        """``F(x)`` in exact arithmetic."""
        x = Fraction(x)
        acc = Fraction(0)
        for c in reversed(self.coefficients):
            acc = acc * x + c
        return acc


@dataclass(frozen=True)
class LagrangeSurface:
    """The tensor-product Lagrange surface ``z = F(x, y)`` through a control grid.

    Attributes
    ----------
    grid : ControlGrid
        The control points.
    coefficients : tuple of tuple of Fraction
        ``coefficients[a][b]`` multiplies ``x**a * y**b`` (numpy's ``polyval2d``
        order).
    variables : tuple of str or sympy.Symbol
        The variables ``(x, y)``: names of plain symbols (``("x", "y")`` by
        default), or symbols that carry assumptions.
    symbols : tuple of sympy.Symbol
        The variables of :attr:`poly`, :attr:`expr` and the bases (made on
        first use).

    In Jupyter the surface shows as its equation in LaTeX and, once ``import lagsym`` has
    registered the display, a small figure (:mod:`lagsym.plot.inline`).
    """

    grid: ControlGrid
    coefficients: tuple[tuple[Fraction, ...], ...]
    variables: tuple[str | sympy.Symbol, str | sympy.Symbol] = ("x", "y")

    def __post_init__(self):
        if not isinstance(self.variables, (tuple, list)) or len(self.variables) != 2:
            raise InputError(f"variables = {self.variables!r} is not a pair of names or symbols")
        _variable(self.variables[0], "x"), _variable(self.variables[1], "y")  # checked; kept as given
        object.__setattr__(self, "variables", tuple(self.variables))

    @cached_property
    def symbols(self) -> tuple[sympy.Symbol, sympy.Symbol]:
        """The variables as SymPy symbols."""
        return _symbols_of(self.variables)

    @property
    def degree(self) -> tuple[int, int]:
        """Degree in x and in y."""
        return self.grid.degree

    @cached_property
    def poly(self) -> sympy.Poly:
        """The surface as a ``sympy.Poly`` in :attr:`symbols` over QQ."""
        import sympy

        qq = sympy.QQ  # the domain's own rationals, as for a curve
        terms = {(a, b): qq(c.numerator, c.denominator) for a, row in enumerate(self.coefficients)
                 for b, c in enumerate(row) if c}
        return sympy.Poly.from_dict(terms, *self.symbols, domain=qq)

    @cached_property
    def expr(self) -> sympy.Expr:
        """The surface as an exact SymPy expression in :attr:`symbols`."""
        return self.poly.as_expr()

    @cached_property
    def basis_x(self) -> tuple[sympy.Poly, ...]:
        """The basis polynomials ``L_i(x)`` (paper eq. 6)."""
        return lagrange_basis(self.grid.x, self.symbols[0], max_mb=None)  # checked with the surface

    @cached_property
    def basis_y(self) -> tuple[sympy.Poly, ...]:
        """The basis polynomials ``L_k(y)`` (paper eq. 7)."""
        return lagrange_basis(self.grid.y, self.symbols[1], max_mb=None)

    def __repr__(self) -> str:
        (n, m), (sx, sy) = self.grid.shape, self.variables
        sym = "" if self.variables == ("x", "y") else f", x={sx}, y={sy}"
        return f"LagrangeSurface({n}x{m} nodes, degree {self.degree}{sym}, source={self.grid.source!r})"

    def _repr_latex_(self) -> str:
        terms = sum(1 for row in self.coefficients for c in row if c)
        return _latex("z", self.expr, terms, f"degree {self.degree[0]} x {self.degree[1]}")

    def exact_value(self, x, y) -> Fraction:
        """``F(x, y)`` in exact arithmetic (nested Horner on the rational coefficients)."""
        return horner2(self.coefficients, Fraction(x), Fraction(y))

    def derivative(self, dx: int = 1, dy: int = 0) -> sympy.Poly:
        """The exact partial derivative ``d^(dx+dy) F / dx^dx dy^dy`` as a Poly."""
        sx, sy = self.symbols
        return self.poly.diff(*([(sx, dx)] if dx else []), *([(sy, dy)] if dy else [])) if (dx or dy) else self.poly


def _latex(lhs: str, expr: sympy.Expr, terms: int, degree: str) -> str:
    if terms > LATEX_TERMS:
        # MathJax takes seconds over a page of terms; the summary says how to get them all.
        return rf"${lhs} = F$ ({degree}, {terms} terms: ``.expr`` holds them all)"
    import sympy

    return f"${lhs} = {sympy.latex(expr)}$"


def horner2(coefficients, x: Fraction, y: Fraction) -> Fraction:
    """``sum c[a][b] x**a y**b`` in nested Horner form, exact for exact arguments.

    Examples
    --------
    >>> horner2(((1, 2), (3, 4)), Fraction(1, 2), Fraction(3))
    Fraction(29, 2)
    """
    acc = Fraction(0)
    for row in reversed(coefficients):
        inner = Fraction(0)
        for c in reversed(row):
            inner = inner * y + c
        acc = acc * x + inner
    return acc


def lagrange_curve(points: CurvePoints, x: sympy.Symbol | str = "x", *,
                   max_mb: float | None = MAX_EXACT_MB) -> LagrangeCurve:
    """The exact Lagrange curve through ``points`` (paper eq. 1-3).

    Parameters
    ----------
    points : CurvePoints
        The nodes and values.
    x : sympy.Symbol or str, optional
        The variable of the polynomial: plain ``x`` by default.
    max_mb : float or None, optional
        Refuse, before any work, a curve estimated at more megabytes (``--max-exact-mb``; :mod:`lagsym.exactsize`).

    Examples
    --------
    >>> from lagsym.grid import curve_from_points
    >>> pts = curve_from_points([(1, 1), (2, 3), (3, 1)])
    >>> lagrange_curve(pts).expr
    -2*x**2 + 8*x - 5
    >>> import sympy
    >>> t = sympy.Symbol("t")
    >>> lagrange_curve(pts, x=t).expr.subs(t, 2)
    3
    """
    points = of_type(points, CurvePoints, "points", "curve_from_points([(x, y), ...]) or read_points(file)")
    check_exact_size(f"curve through {len(points.x)} points", points.source, points.x, None, points.y, max_mb)
    b = _basis_matrix(points.x, points.source)
    yv = flint.fmpq_mat(len(points.y), 1, [_fmpq(v) for v in points.y])
    c = stepped_product(b.transpose(), yv, clock=ExactClock(f"curve through {len(points.x)} points", points.source))
    return LagrangeCurve(points=points, coefficients=tuple(_frac(c[a, 0]) for a in range(c.nrows())),
                         variable=_variable(x, "x"))


def lagrange_surface(grid: ControlGrid, x: sympy.Symbol | str = "x", y: sympy.Symbol | str = "y", *,
                     max_mb: float | None = MAX_EXACT_MB) -> LagrangeSurface:
    """The exact tensor-product Lagrange surface through ``grid`` (paper eqs. 6-7).

    Parameters
    ----------
    grid : ControlGrid
        The control points.
    x, y : sympy.Symbol or str, optional
        The variables of the polynomial: plain ``x`` and ``y`` by default, the
        symbols ``sympy.symbols('x y')`` gives.
    max_mb : float or None, optional
        Refuse, before any work, a surface estimated at more megabytes (``--max-exact-mb``; :mod:`lagsym.exactsize`).

    Examples
    --------
    >>> from lagsym.grid import grid_from_points
    >>> pts = [(1, 2, 7), (1, 3, 10), (1, 4, 13), (3, 2, 15), (3, 3, 18), (3, 4, 21),
    ...        (5, 2, 31), (5, 3, 34), (5, 4, 37)]
    >>> s = lagrange_surface(grid_from_points(pts))
    >>> import sympy
    >>> x, y = sympy.symbols("x y")
    >>> s.expr == x**2 + 3*y, s.expr.subs({x: 1, y: 2}), sympy.diff(s.expr, x)
    (True, 7, 2*x)
    >>> u, v = sympy.symbols("u v")
    >>> lagrange_surface(grid_from_points(pts), x=u, y=v).expr
    u**2 + 3*v
    """
    grid = of_type(grid, ControlGrid, "grid", "grid_from_points([(x, y, z), ...]) or read_points(file)")
    sx, sy = _variable(x, "x"), _variable(y, "y")
    if sx == sy:
        raise InputError(f"x and y are both the symbol {sx}: a surface needs two different variables")
    n, m = grid.shape
    check_exact_size(f"surface through {n} x {m} nodes", grid.source, grid.x, grid.y,
                [v for row in grid.z for v in row], max_mb)
    bx = _basis_matrix(grid.x, grid.source)
    by = _basis_matrix(grid.y, grid.source)
    z = flint.fmpq_mat(n, m, [_fmpq(v) for row in grid.z for v in row])
    clock = ExactClock(f"surface through {n} x {m} nodes", grid.source)
    c = stepped_product(stepped_product(bx.transpose(), z, clock=clock, products_after=1), by, clock=clock)
    coeffs = tuple(tuple(_frac(c[a, b]) for b in range(m)) for a in range(n))
    return LagrangeSurface(grid=grid, coefficients=coeffs, variables=(sx, sy))
