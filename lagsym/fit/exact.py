"""The exact least-squares solve: the data in integers, integer moments, one exact solve, exact residuals.

Every coordinate is scaled to an integer (``x * Dx``, ``Dx`` the common
denominator of the x values: for decimals a power of ten) and shifted by an
integer near the middle of its range, so the moments ``sum_k w_k u_k**s
v_k**t`` and the right-hand side are integer sums (modulo small primes in
float64 matrix products, :mod:`.moments`, or python-flint's ``fmpz_mat``
products where a value does not fit 64 bits); the normal equations are solved exactly
(``fmpz_mat.solve``) and the solution carried back to powers of ``x`` and
``y`` by the exact binomial change of variables.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction

import flint

from ..errors import GridError
from ..io.decimals import DecimalPoints, column_floats
from .moments import moments

__all__ = ["fit_coefficients"]


def _middle_and_half(lo: Fraction, hi: Fraction) -> tuple[Fraction, Fraction]:
    return Fraction(lo + hi, 2), Fraction(hi - lo, 2) or Fraction(1)


def _normalized(points, j: int, middle: Fraction, half: Fraction):
    """``(v - middle) / half`` for coordinate ``j`` of each point, each rounded once to the nearest float.

    In integers: ``(n/d - mn/md) / (hn/hd) = (n md hd - mn hd d) / (d md hn)``, and Python divides two
    integers correctly rounded, so each is ``float((v - middle) / half)`` without building a Fraction a point
    (nor, for points read in whole columns, a Fraction at all: ``n / d`` need not be in lowest terms).
    """
    import numpy as np

    a, b, c = middle.denominator * half.denominator, middle.numerator * half.denominator, \
        middle.denominator * half.numerator
    if isinstance(points, DecimalPoints):
        ns, d = points.integers(j)
        bd, dc = b * d, d * c
        return np.array([(n * a - bd) / dc for n in ns])
    return np.array([(v.numerator * a - b * v.denominator) / (v.denominator * c) for v in (p[j] for p in points)])


def _common_denominator(values: Sequence[Fraction]) -> int:
    d = 1
    for v in values:
        d = math.lcm(d, v.denominator)
    return d


def _times(values: Sequence[Fraction], d: int) -> list[int]:
    """``v * d`` for each value, ``d`` a multiple of every denominator: the integer without a Fraction product."""
    return [v.numerator * (d // v.denominator) for v in values]


def _powers(values: Sequence[int], top: int) -> list[list[int]]:
    rows = []
    for v in values:
        row, acc = [1], 1
        for _ in range(top):
            acc *= v
            row.append(acc)
        rows.append(row)
    return rows


def _shift_matrix(scale, shift, degree: int) -> list:
    """``T[a][e]``: the coefficient of ``x**e`` in ``(scale * x - shift)**a``."""
    return [[math.comb(a, e) * scale ** e * (-shift) ** (a - e) if e <= a else 0 for e in range(degree + 1)]
            for a in range(degree + 1)]


@dataclass(frozen=True)
class _Scaled:
    """The data in integers: ``x = X / dx``, ``y = Y / dy``, ``z = Z / dz``, ``w = W / dw``."""

    X: list[int]
    Y: list[int]
    Z: list[int]
    W: list[int]
    dx: int
    dy: int
    dz: int
    dw: int

    @classmethod
    def of(cls, points, weights) -> _Scaled:
        if weights is None:
            W, dw = [1] * len(points), 1
        else:
            dw = _common_denominator(weights)
            W = _times(weights, dw)
        if isinstance(points, DecimalPoints):  # the integers as read, over their least denominators
            (X, dx), (Y, dy), (Z, dz) = (points.integers(i) for i in range(3))
            return cls(X, Y, Z, W, dx, dy, dz, dw)
        xs, ys, zs = ([pt[i] for pt in points] for i in range(3))
        dx, dy, dz = (_common_denominator(v) for v in (xs, ys, zs))
        return cls(_times(xs, dx), _times(ys, dy), _times(zs, dz), W, dx, dy, dz, dw)


def fit_coefficients(points: Sequence[Sequence[Fraction]], degree: tuple[int, int],
                     weights: Sequence[Fraction] | None = None,
                     source: str = "<points>") -> tuple[tuple[Fraction, ...], ...]:
    """The exact least-squares coefficients ``c[a][b]`` (of ``x**a y**b``) of degree ``degree`` through ``points``.

    Raises
    ------
    GridError
        When the points do not determine a polynomial of that degree (too few
        distinct x or y values, or too few points).

    Examples
    --------
    >>> pts = [(0, 0, 1), (1, 0, 3), (0, 1, 2), (1, 1, 4), (2, 2, 7)]
    >>> fit_coefficients([(Fraction(x), Fraction(y), Fraction(z)) for x, y, z in pts], (1, 1))
    ((Fraction(1, 1), Fraction(1, 1)), (Fraction(2, 1), Fraction(0, 1)))
    """
    pts = [tuple(Fraction(v) for v in pt) for pt in points]
    ws = None if weights is None else [Fraction(w) for w in weights]
    return _solve(_Scaled.of(pts, ws), degree, source)


def _solve(s: _Scaled, degree: tuple[int, int], source: str) -> tuple[tuple[Fraction, ...], ...]:
    p, q = degree
    # Integer shifts near the middle keep the powers, and so the exact numbers, small.
    cx, cy = (min(s.X) + max(s.X)) // 2, (min(s.Y) + max(s.Y)) // 2
    n = len(s.X)
    mom, rhs = _moments([v - cx for v in s.X], [v - cy for v in s.Y], s.W, s.Z, (p, q))
    k = (p + 1) * (q + 1)
    idx = [(a, b) for a in range(p + 1) for b in range(q + 1)]
    gram = flint.fmpz_mat(k, k, [mom[a + c][b + d] for a, b in idx for c, d in idx])
    r = flint.fmpz_mat(k, 1, [rhs[a][b] for a, b in idx])
    try:
        sol = gram.solve(r)
    except ZeroDivisionError:
        nx, ny = len(set(s.X)), len(set(s.Y))
        raise GridError(
            f"{source}: the {n} points do not determine a degree {p}x{q} polynomial ({k} coefficients from "
            f"{nx} distinct x and {ny} distinct y values); give lower degrees"
        ) from None
    cu = flint.fmpq_mat(p + 1, q + 1, [sol[i, 0] for i in range(k)])
    tx = flint.fmpq_mat(p + 1, p + 1, [v for row in _shift_matrix(s.dx, cx, p) for v in row])
    ty = flint.fmpq_mat(q + 1, q + 1, [v for row in _shift_matrix(s.dy, cy, q) for v in row])
    c = tx.transpose() * cu * ty / s.dz
    return tuple(tuple(Fraction(int(c[a, b].p), int(c[a, b].q)) for b in range(q + 1)) for a in range(p + 1))


def _moments(U, V, W, Z, degree):
    """``sum w u**s v**t`` (``s <= 2p``, ``t <= 2q``) and ``sum w z u**a v**b`` (``a <= p``, ``b <= q``), exactly.

    Modulo small primes in float64 matrix products (:mod:`.moments`) where
    every value fits 64 bits; else as python-flint integer matrix products.
    """
    found = moments(U, V, W, Z, degree)
    if found is not None:
        return found
    p, q = degree
    pu, pv = _powers(U, 2 * p), _powers(V, 2 * q)
    n = len(U)
    wu = flint.fmpz_mat(2 * p + 1, n, [w * r[e] for e in range(2 * p + 1) for w, r in zip(W, pu)])
    wzu = flint.fmpz_mat(p + 1, n, [w * z * r[e] for e in range(p + 1) for w, z, r in zip(W, Z, pu)])
    mom = wu * flint.fmpz_mat(n, 2 * q + 1, [c for r in pv for c in r])
    rhs = wzu * flint.fmpz_mat(n, q + 1, [c for r in pv for c in r[:q + 1]])
    return ([[int(mom[i, j]) for j in range(2 * q + 1)] for i in range(2 * p + 1)],
            [[int(rhs[i, j]) for j in range(q + 1)] for i in range(p + 1)])


def _residuals(s: _Scaled, coefficients) -> tuple[tuple[int, ...], int]:
    """``z - p(x, y)`` for every point exactly, as integers over one denominator.

    With ``x = X / dx`` and ``C`` the coefficients times their common
    denominator ``den``: ``den dx**P dy**Q p(x, y) = sum_ab C[a][b] X**a
    dx**(P-a) Y**b dy**(Q-b)``, one integer matrix-vector product whose
    matrix holds only the data's small integers.
    """
    den = _common_denominator([c for row in coefficients for c in row])
    P, Q = len(coefficients) - 1, len(coefficients[0]) - 1
    n = len(s.X)
    # inner[k, a] = sum_b C[a][b] Y_k**b dy**(Q-b): one integer matrix product; then each point's sum over a.
    ys = flint.fmpz_mat(n, Q + 1, [y ** b * s.dy ** (Q - b) for y in s.Y for b in range(Q + 1)])
    cs = flint.fmpz_mat(Q + 1, P + 1, [int(coefficients[a][b] * den) for b in range(Q + 1) for a in range(P + 1)])
    inner = (ys * cs).entries()
    xs = [s.dx ** (P - a) for a in range(P + 1)]
    values = [sum(int(inner[k * (P + 1) + a]) * x ** a * xs[a] for a in range(P + 1)) for k, x in enumerate(s.X)]
    scale = den * s.dx ** P * s.dy ** Q
    return tuple(z * scale - v * s.dz for z, v in zip(s.Z, values)), scale * s.dz


def float_residuals(points, coefficients, box):
    """``z - p(x, y)`` for every point in floating point, for the fit's statistics (its RMS, largest residual and
    score), where the exact residuals of many points are integers of thousands of digits; and a bound on how far
    any of them may be from the exact one.

    ``p`` is taken to the monomials of coordinates normalized to ``[-1, 1]`` over the points' ``box``
    (``x0, x1, y0, y1``, exact) exactly, its
    coefficients rounded once; on that interval each term is at most its coefficient, so the rounding errors of
    the sums are within ``(2 (P + Q) + 8) u (sum |c| + |z|)`` (``u`` the unit roundoff), doubled here.
    """
    import numpy as np

    x0, x1, y0, y1 = box
    (xm, hx), (ym, hy) = _middle_and_half(x0, x1), _middle_and_half(y0, y1)

    def mat(rows):
        entries = [flint.fmpq(v.numerator, v.denominator) for r in rows for v in r]
        return flint.fmpq_mat(len(rows), len(rows[0]), entries)

    c = mat(coefficients)
    # x = xm + hx t: the coefficient of t**e in x**a is T[a][e] of the shift matrix of (hx t - (-xm))**a.
    tx, ty = mat(_shift_matrix(hx, -xm, c.nrows() - 1)), mat(_shift_matrix(hy, -ym, c.ncols() - 1))
    ct = tx.transpose() * c * ty
    cf = np.array([[int(ct[a, b].p) / int(ct[a, b].q) for b in range(ct.ncols())] for a in range(ct.nrows())])
    t, u = _normalized(points, 0, xm, hx), _normalized(points, 1, ym, hy)
    z = column_floats(points, 2)
    steps = 2 * (ct.nrows() + ct.ncols()) + 8
    bound = 2 * steps * np.finfo(float).eps / 2 * (float(np.abs(cf).sum()) + float(np.abs(z).max()))
    return z - np.polynomial.polynomial.polyval2d(t, u, cf), bound

