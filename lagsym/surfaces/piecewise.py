"""Smooth piecewise surfaces for grids too large for one polynomial: exact bicubic Hermite pieces.

One polynomial through an ``n x m`` grid has degree ``(n - 1, m - 1)``; past
a dozen nodes on even spacing it amplifies errors in the points thousands of
times (:mod:`lagsym.conditioning`).  A :class:`PiecewiseSurface` is instead one
bicubic polynomial per cell ``[x_i, x_{i+1}] x [y_k, y_{k+1}]`` of the grid,
built from the paper's Lagrange idea at a small scale:

* the slopes at each node are those of the local Lagrange parabola, the
  quadratic through the node and its two neighbours (at the first and last
  node, through the first or last three), :func:`lagrange_slopes`;
* the twist ``z_xy`` applies the same rule in both directions;
* each cell is the bicubic Hermite (Ferguson) patch of its four corners'
  heights, slopes and twists.

Every number is an exact rational.  **Continuity**: the surface passes
through every control point and is C1: across every border between pieces
the value, both first partial derivatives (and the twist ``F_xy``) of the two
pieces agree exactly, as polynomials along the whole border, because both
pieces take them from the same node data.  Second derivatives ``F_xx`` and
``F_yy`` jump in general (it is not C2).  It reproduces every polynomial of
degree at most 2 in x and 2 in y exactly, since the parabola's slopes are
exact for those.

The pieces are :class:`~lagsym.lagrange.LagrangeSurface` values (the
Lagrange surface through a 4 x 4 grid of a piece's own values in its cell is
the piece itself), so every exact and numeric tool for one polynomial works
on a piece; :class:`PiecewiseEvaluator` is the numeric evaluator of the whole
(floats), what drop-cutter and the toolpath planner use.
"""

from __future__ import annotations

from bisect import bisect_right
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property
from math import comb

import flint

from ..errors import GridError
from ..grid import ControlGrid, grid_from_table
from ..lagrange import LagrangeSurface, horner2
from .piecewise_numeric import PiecewiseEvaluator

__all__ = ["CONTINUITY", "PiecewiseSurface", "PiecewiseEvaluator", "lagrange_slopes", "piecewise_surface",
           "piecewise_evaluator", "MAX_PIECES"]

CONTINUITY = "C1"
"""What the pieces share across every border: value and both first partial derivatives (and the twist)."""

MAX_PIECES = 250_000
"""Pieces at most (a 501 x 501 grid): beyond it the exact pieces alone would take gigabytes."""

# Hermite data (p0, p1, m0, m1) of a cubic on [0, 1] -> its power coefficients a0..a3.
_HERMITE = ((1, 0, 0, 0), (0, 0, 1, 0), (-3, 3, -2, -1), (2, -2, 1, 1))


def _slope_weights(nodes, i: int) -> tuple[int, tuple[Fraction, Fraction, Fraction]]:
    """``(lo, w)``: the slope at ``nodes[i]`` of the parabola through ``nodes[lo:lo+3]`` is ``sum w_k f[lo+k]``."""
    lo = min(max(i - 1, 0), len(nodes) - 3)
    t = nodes[lo:lo + 3]
    xi = nodes[i]
    w = []
    for k in range(3):
        others = [t[j] for j in range(3) if j != k]
        denom = (t[k] - others[0]) * (t[k] - others[1])
        # d/dx of (x - a)(x - b) at xi
        w.append(((xi - others[0]) + (xi - others[1])) / denom)
    return lo, tuple(w)


def lagrange_slopes(nodes, values) -> tuple[Fraction, ...]:
    """The slope at every node of the local Lagrange parabola (3 points), exactly.

    At an inner node the parabola runs through the node and its two
    neighbours; at an end, through the three nearest nodes.  On even spacing
    the inner rule is the central difference.

    Examples
    --------
    >>> [str(s) for s in lagrange_slopes([0, 1, 3], [0, 1, 9])]  # x**2: exact
    ['0', '2', '6']
    """
    nodes = [Fraction(v) for v in nodes]
    values = [Fraction(v) for v in values]
    out = []
    for i in range(len(nodes)):
        lo, w = _slope_weights(nodes, i)
        out.append(sum((w[k] * values[lo + k] for k in range(3)), Fraction(0)))
    return tuple(out)


def _apply_rows(table, nodes) -> list[list[Fraction]]:
    """:func:`lagrange_slopes` down every column of ``table`` (the x direction: ``table[i][k]``)."""
    cols = [lagrange_slopes(nodes, [row[k] for row in table]) for k in range(len(table[0]))]
    return [[cols[k][i] for k in range(len(cols))] for i in range(len(nodes))]


def _apply_cols(table, nodes) -> list[list[Fraction]]:
    """:func:`lagrange_slopes` along every row of ``table`` (the y direction)."""
    return [list(lagrange_slopes(nodes, row)) for row in table]


def _fmpq(v) -> flint.fmpq:
    v = Fraction(v)
    return flint.fmpq(v.numerator, v.denominator)


def _frac(v: flint.fmpq) -> Fraction:
    return Fraction(int(v.p), int(v.q))


def _rows(mat: flint.fmpq_mat) -> tuple[tuple[Fraction, ...], ...]:
    return tuple(tuple(_frac(mat[i, j]) for j in range(mat.ncols())) for i in range(mat.nrows()))


def _to_power(origin: Fraction, width: Fraction) -> flint.fmpq_mat:
    """``P[a, k]``: ``((x - origin) / width)**a = sum_k P[a, k] x**k``."""
    return flint.fmpq_mat([[_fmpq(Fraction(comb(a, k)) * (-origin) ** (a - k) / width ** a) if k <= a else 0
                            for k in range(4)] for a in range(4)])


_M = flint.fmpq_mat([list(r) for r in _HERMITE])
_THIRDS = flint.fmpq_mat([[flint.fmpq(p ** a, 3 ** a) for a in range(4)] for p in range(4)])  # [p, a] = (p/3)**a


@dataclass(frozen=True)
class PiecewiseSurface:
    """Exact bicubic pieces over the cells of a control grid, joined C1 (see the module text).

    Attributes
    ----------
    grid : ControlGrid
        The control points; piece ``(i, k)`` covers ``[x[i], x[i+1]] x [y[k], y[k+1]]``.
    zx, zy, zxy : tuple of tuple of Fraction
        Slopes and twists at the nodes, ``[i][k]`` as ``grid.z``.
    """

    grid: ControlGrid
    zx: tuple[tuple[Fraction, ...], ...] = field(repr=False)
    zy: tuple[tuple[Fraction, ...], ...] = field(repr=False)
    zxy: tuple[tuple[Fraction, ...], ...] = field(repr=False)

    continuity = CONTINUITY

    @property
    def shape(self) -> tuple[int, int]:
        """Pieces along x and along y."""
        n, m = self.grid.shape
        return n - 1, m - 1

    @property
    def bounds(self) -> tuple[Fraction, Fraction, Fraction, Fraction]:
        """``(x0, x1, y0, y1)``: the control points' box."""
        return self.grid.bounds

    @property
    def source(self) -> str:
        return self.grid.source

    @property
    def units(self) -> str | None:
        return self.grid.units

    def __repr__(self) -> str:
        (n, m), (a, b) = self.grid.shape, self.shape
        return f"PiecewiseSurface({n}x{m} nodes, {a}x{b} bicubic pieces, {CONTINUITY}, source={self.grid.source!r})"

    def box(self, i: int, k: int) -> tuple[Fraction, Fraction, Fraction, Fraction]:
        """The cell of piece ``(i, k)``: ``(x[i], x[i+1], y[k], y[k+1])``."""
        g = self.grid
        return g.x[i], g.x[i + 1], g.y[k], g.y[k + 1]

    def local_coefficients(self, i: int, k: int) -> tuple[tuple[Fraction, ...], ...]:
        """``A[a][b]``: piece ``(i, k)`` is ``sum A[a][b] s**a t**b``, ``s, t`` the cell's coordinates on ``[0, 1]``."""
        return _rows(self._local(i, k))

    def local_entries(self, i: int, k: int) -> list:
        """The 16 exact local coefficients of piece ``(i, k)`` row by row (``A[0][0], A[0][1], ...``), as
        python-flint rationals."""
        return self._local(i, k).entries()

    def _local(self, i: int, k: int) -> flint.fmpq_mat:
        found = self._locals.get((i, k))
        if found is None:
            found = self._locals[i, k] = self._hermite(i, k)
        return found

    @cached_property
    def _locals(self) -> dict:
        return {}

    @cached_property
    def _node_data(self) -> tuple:
        """The heights, slopes, twists and cell widths as python-flint rationals, converted once."""
        g = self.grid
        tables = tuple([[_fmpq(v) for v in row] for row in t] for t in (g.z, self.zx, self.zy, self.zxy))
        widths = tuple([_fmpq(b - a) for a, b in zip(v, v[1:])] for v in (g.x, g.y))
        return tables, widths

    def _hermite(self, i: int, k: int) -> flint.fmpq_mat:
        (z, zx, zy, zxy), (wx, wy) = self._node_data
        hx, hy = wx[i], wy[k]
        rows = (i, i + 1)
        cols = (k, k + 1)
        g = [[z[r][c] for c in cols] + [hy * zy[r][c] for c in cols] for r in rows]
        g += [[hx * zx[r][c] for c in cols] + [hx * hy * zxy[r][c] for c in cols] for r in rows]
        return _M * flint.fmpq_mat(g) * _M.transpose()

    def coefficients(self, i: int, k: int) -> tuple[tuple[Fraction, ...], ...]:
        """``C[a][b]``: piece ``(i, k)`` is ``sum C[a][b] x**a y**b`` (the order of :class:`LagrangeSurface`)."""
        x0, x1, y0, y1 = self.box(i, k)
        return _rows(_to_power(x0, x1 - x0).transpose() * self._local(i, k) * _to_power(y0, y1 - y0))

    def piece(self, i: int, k: int) -> LagrangeSurface:
        """Piece ``(i, k)`` as the Lagrange surface through its values on a 4 x 4 grid over its cell (itself)."""
        return self._pieces[(i, k)] if (i, k) in self._pieces else self._make_piece(i, k)

    @cached_property
    def _pieces(self) -> dict:
        return {}

    @cached_property
    def evaluator(self) -> PiecewiseEvaluator:
        """The numeric evaluator of the whole surface (made on first use, kept with it)."""
        return PiecewiseEvaluator(self)

    def _make_piece(self, i: int, k: int) -> LagrangeSurface:
        c = self.coefficients(i, k)
        x0, x1, y0, y1 = self.box(i, k)
        xs = [x0 + (x1 - x0) * Fraction(a, 3) for a in range(4)]
        ys = [y0 + (y1 - y0) * Fraction(b, 3) for b in range(4)]
        values = _rows(_THIRDS * self._local(i, k) * _THIRDS.transpose())
        g = grid_from_table(xs, ys, values, source=f"{self.grid.source} piece ({i}, {k})", units=self.grid.units)
        s = LagrangeSurface(g, c)
        self._pieces[(i, k)] = s
        return s

    def piece_evaluator(self, i: int, k: int):
        """The :class:`~lagsym.evaluate.SurfaceEvaluator` of piece ``(i, k)``, made on first use and kept.

        The same evaluator as ``surface_evaluator(self.piece(i, k))``, bit for
        bit, made without the piece: its exact Chebyshev coefficients on its
        cell are ``Gx A Gy^T`` (``A`` its local coefficients, ``G`` each axis's
        change from cell coordinates to the Chebyshev basis, one per column or row
        of cells), each rounded once.
        """
        found = self._evaluators.get((i, k))
        if found is None:
            found = self._evaluators[i, k] = self._make_evaluator(i, k)
        return found

    @cached_property
    def _evaluators(self) -> dict:
        return {}

    @cached_property
    def _to_chebyshev(self) -> tuple[dict, dict]:
        return {}, {}

    def _axis_change(self, axis: int, j: int):
        """``(offset, scale, G, floats, exact)`` of cell ``j`` along ``axis``: ``G`` maps cell-coordinate powers
        to the Chebyshev basis of the cell's ``[-1, 1]`` map; ``floats`` are the cell's four thirds as floats
        (read-only) and ``exact`` which of them are exact."""
        import numpy as np

        from ..evaluate.chebyshev import chebyshev_transform

        found = self._to_chebyshev[axis].get(j)
        if found is None:
            nodes = self.grid.x if axis == 0 else self.grid.y
            a, b = nodes[j], nodes[j + 1]
            thirds = [a + (b - a) * Fraction(p, 3) for p in range(4)]
            offset, scale, d = chebyshev_transform(thirds)
            floats = np.array([float(t) for t in thirds])
            exact = np.array([Fraction(float(t)) == t for t in thirds])
            floats.setflags(write=False)
            exact.setflags(write=False)
            found = self._to_chebyshev[axis][j] = (offset, scale, d * _to_power(a, b - a).transpose(), floats, exact)
        return found

    def _make_evaluator(self, i: int, k: int):
        import numpy as np

        from ..evaluate.chebyshev import data_range
        from ..evaluate.surface import SurfaceEvaluator

        (xo, xh, gx, xn, xe), (yo, yh, gy, yn, ye) = self._axis_change(0, i), self._axis_change(1, k)
        a = self._local(i, k)
        cheb = gx * a * gy.transpose()
        values = _THIRDS * a * _THIRDS.transpose()  # the piece's heights on its 4 x 4 grid of thirds

        def floats(mat):
            # int / int is correctly rounded, as float(Fraction) is
            out = np.array([int(v.p) / int(v.q) for v in mat.entries()]).reshape(4, 4)
            out.setflags(write=False)
            return out

        z = floats(values)
        return SurfaceEvaluator(x_offset=xo, x_scale=xh, y_offset=yo, y_scale=yh, coefficients=floats(cheb),
                                data_range=data_range(z.ravel()), bounds=(float(xn[0]), float(xn[-1]),
                                                                          float(yn[0]), float(yn[-1])),
                                x_nodes=xn, y_nodes=yn, x_exact=xe, y_exact=ye, node_values=z)

    def locate(self, x, y) -> tuple[int, int]:
        """The piece whose cell holds ``(x, y)`` (a point on a border: the piece above and right of it)."""
        g = self.grid
        n, m = self.shape
        i = min(max(bisect_right(g.x, Fraction(x)) - 1, 0), n - 1)
        return i, min(max(bisect_right(g.y, Fraction(y)) - 1, 0), m - 1)

    def exact_value(self, x, y) -> Fraction:
        """``F(x, y)`` exactly, from the piece whose cell holds the point."""
        x, y = Fraction(x), Fraction(y)
        return horner2(self.coefficients(*self.locate(x, y)), x, y)

    def expr(self, i: int, k: int, x="x", y="y"):
        """Piece ``(i, k)`` as an exact SymPy expression in ``x, y``."""
        import sympy

        sx, sy = sympy.Symbol(x) if isinstance(x, str) else x, sympy.Symbol(y) if isinstance(y, str) else y
        c = self.coefficients(i, k)
        return sympy.Add(*[sympy.Rational(v.numerator, v.denominator) * sx ** a * sy ** b
                           for a, row in enumerate(c) for b, v in enumerate(row) if v])

    def piecewise(self, x="x", y="y"):
        """The whole surface as a SymPy ``Piecewise`` over the cells (a border point: its lower-left piece).

        Outside the box the ``Piecewise`` is ``nan``.
        """
        import sympy

        sx, sy = sympy.Symbol(x) if isinstance(x, str) else x, sympy.Symbol(y) if isinstance(y, str) else y
        branches = []
        n, m = self.shape
        for i in range(n):
            for k in range(m):
                x0, x1, y0, y1 = (sympy.Rational(v.numerator, v.denominator) for v in self.box(i, k))
                branches.append((self.expr(i, k, sx, sy), sympy.And(sx >= x0, sx <= x1, sy >= y0, sy <= y1)))
        branches.append((sympy.nan, True))
        return sympy.Piecewise(*branches, evaluate=False)


def piecewise_surface(grid: ControlGrid) -> PiecewiseSurface:
    """The C1 piecewise bicubic surface through ``grid`` (at least 3 nodes each way).

    Examples
    --------
    >>> g = grid_from_table([0, 1, 2], [0, 1, 2], [[x * x + y for y in range(3)] for x in range(3)])
    >>> s = piecewise_surface(g)
    >>> s.shape, s.expr(1, 0)  # x**2 + y is reproduced exactly
    ((2, 2), x**2 + y)
    """
    n, m = grid.shape
    if n < 3 or m < 3:
        raise GridError(f"{grid.source}: a piecewise surface needs at least 3 x 3 nodes (the slopes come from "
                        f"3-point Lagrange parabolas), the grid has {n} x {m}")
    if (n - 1) * (m - 1) > MAX_PIECES:
        raise GridError(f"{grid.source}: {n} x {m} nodes make {(n - 1) * (m - 1):,} pieces, more than the limit of "
                        f"{MAX_PIECES:,}; thin the grid")
    z = [list(r) for r in grid.z]
    zx = _apply_rows(z, grid.x)
    zy = _apply_cols(z, grid.y)
    zxy = _apply_cols(zx, grid.y)
    frozen = [tuple(tuple(r) for r in t) for t in (zx, zy, zxy)]
    return PiecewiseSurface(grid, *frozen)


def piecewise_evaluator(surface: PiecewiseSurface) -> PiecewiseEvaluator:
    """The evaluator of ``surface``, remembered on it."""
    return surface.evaluator
