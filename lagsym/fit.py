"""Exact least-squares tensor-product polynomials through measured points (``lagsym fit``).

The paper (section 2) separates reliable data, which an interpolant may pass
through, from data with measurement errors, which calls for an approximating
function that "passes close to all the points but not necessarily through any
of them".  :func:`fit_surface` finds the polynomial

    ``p(x, y) = sum_{a <= P, b <= Q} c[a][b] x**a y**b``

that minimises ``sum_k w_k (z_k - p(x_k, y_k))**2`` over points given on a
grid or scattered, exactly: decimal text in the file is the decimal it spells
and the coefficients are the exact rational solution of the normal equations.

How it stays fast in exact arithmetic: every coordinate is scaled to an
integer (``x * Dx`` with ``Dx`` the common denominator of the x values, for
decimals a power of ten) and shifted by an integer near the middle of its
range, so the moments ``sum_k w_k u_k**s v_k**t`` and the right-hand side are
integer matrix products (python-flint's ``fmpz_mat``); the normal equations
``G c = r`` of size ``(P+1)(Q+1)`` are solved exactly (``fmpz_mat.solve``)
and the solution is carried back to powers of ``x`` and ``y`` by the exact
binomial change of variables.

The degrees may be chosen automatically.  Each candidate ``(P, Q)`` is scored
in floating point in the Chebyshev basis of the data box (well conditioned,
so the scores are accurate to many digits) by generalized cross-validation,
``GCV = N * RSS / (N - k)**2``, or by leave-one-out, ``PRESS = sum_k
w_k (r_k / (1 - h_kk))**2 / N`` (``h`` the leverages); the lowest score wins
and the chosen degrees are then fitted exactly, and their score recomputed
from the exact residuals.

The result is a :class:`SurfaceFit`; its :attr:`~SurfaceFit.surface` is a
:class:`~lagsym.lagrange.LagrangeSurface` through the fitted polynomial's
values at ``P+1`` by ``Q+1`` nodes near the Chebyshev extrema of the box, so
it *is* the fitted polynomial (a polynomial of degree ``P`` is its own
Lagrange interpolant on ``P+1`` nodes), well conditioned, and accepted by
every command and function that takes a surface.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, replace
from fractions import Fraction
from functools import cached_property

import flint

from .errors import GridError, InputError
from .grid import ControlGrid, grid_from_table
from .lagrange import LagrangeSurface
from .values import as_exact, choice

__all__ = ["SurfaceFit", "fit_surface", "fit_coefficients", "representation_nodes", "CRITERIA", "MAX_DEGREE",
           "convex_hull", "polygon_area"]

CRITERIA = ("gcv", "loo")
MAX_DEGREE = 12  # one polynomial beyond this is a piecewise surface's job
NODE_DIGITS = 6  # representation nodes: the Chebyshev extrema rounded to 1e-6 of the box
AMPLIFICATION_SAMPLES = 65  # per axis at most: the fit's Lebesgue function sampled on up to 65 x 65 points
AMPLIFICATION_WORK = 4_000_000  # sample points times data points: fewer samples for many points, at least 17 x 17


@dataclass(frozen=True)
class SurfaceFit:
    """An exact least-squares fit and its report.

    Attributes
    ----------
    surface : LagrangeSurface
        The fitted polynomial, as the Lagrange surface through its own values
        at :func:`representation_nodes` (exactly the same polynomial).
    coefficients : tuple of tuple of Fraction
        ``coefficients[a][b]`` multiplies ``x**a * y**b``, ``a <= P``, ``b <= Q``.
    degree : tuple of int
        ``(P, Q)``.
    points : tuple of (Fraction, Fraction, Fraction)
        The data, in the order given.
    weights : tuple of Fraction or None
        The weights, when given.
    residual_numerators : tuple of int
        ``z_k - p(x_k, y_k)`` times :attr:`residual_denominator`, in the order
        of the points (:attr:`residuals` gives them as fractions).
    residual_denominator : int
        The one denominator of every residual.
    criterion : str or None
        ``"gcv"`` or ``"loo"`` when the degrees were chosen, else None.
    score : float or None
        The chosen degrees' score under ``criterion`` (from the exact residuals).
    scores : tuple of ((int, int), float)
        Every candidate's score, lowest first (empty when the degrees were given).
    hull : tuple of (Fraction, Fraction)
        The convex hull of the points' ``(x, y)``, counter-clockwise.
    amplification : float
        How much the fit can amplify errors in the points: the largest value
        over the box of its Lebesgue function ``sum_k |h_k(x, y)|`` (``h_k``
        the weight of point ``k`` in the fitted value at ``(x, y)``), sampled
        on a grid of :attr:`samples` squared points of the box; also the
        surface grid's ``amplification``, which the guard rail reads.
    samples : int
        The points per axis of that grid: 65, fewer for many points (at
        least 17), so that sampling costs no more than the fit.
    """

    surface: LagrangeSurface
    coefficients: tuple[tuple[Fraction, ...], ...]
    degree: tuple[int, int]
    points: tuple[tuple[Fraction, Fraction, Fraction], ...]
    weights: tuple[Fraction, ...] | None
    residual_numerators: tuple[int, ...]
    residual_denominator: int
    criterion: str | None = None
    score: float | None = None
    scores: tuple[tuple[tuple[int, int], float], ...] = ()
    hull: tuple[tuple[Fraction, Fraction], ...] = ()
    amplification: float = 1.0
    samples: int = AMPLIFICATION_SAMPLES

    @property
    def terms(self) -> int:
        """The number of coefficients, ``(P + 1) (Q + 1)``."""
        return (self.degree[0] + 1) * (self.degree[1] + 1)

    @cached_property
    def residuals(self) -> tuple[Fraction, ...]:
        """``z_k - p(x_k, y_k)``, exact, in the order of the points."""
        return tuple(Fraction(r, self.residual_denominator) for r in self.residual_numerators)

    def residual(self, k: int) -> Fraction:
        """The residual of point ``k`` (0-based), exact."""
        return Fraction(self.residual_numerators[k], self.residual_denominator)

    @cached_property
    def rss(self) -> Fraction:
        """The (weighted) residual sum of squares, exact."""
        d = self.residual_denominator
        if self.weights is None:
            return Fraction(sum(r * r for r in self.residual_numerators), d * d)
        return sum((w * r * r for w, r in zip(self.weights, self.residual_numerators)), Fraction(0)) / (d * d)

    @property
    def max_residual(self) -> float:
        """The largest ``|z_k - p(x_k, y_k)|``."""
        return float(Fraction(max(abs(r) for r in self.residual_numerators), self.residual_denominator))

    @property
    def rms(self) -> float:
        """The root mean square residual (unweighted)."""
        d = self.residual_denominator
        return math.sqrt(float(Fraction(sum(r * r for r in self.residual_numerators), d * d))
                         / len(self.residual_numerators))

    @property
    def sigma(self) -> float:
        """The noise estimate ``sqrt(RSS / (N - k))`` (weighted residuals; 0 when the fit interpolates)."""
        dof = len(self.residual_numerators) - self.terms
        return math.sqrt(float(self.rss) / dof) if dof > 0 else 0.0

    @property
    def box(self) -> tuple[Fraction, Fraction, Fraction, Fraction]:
        """``(x0, x1, y0, y1)``: the points' bounding box, the surface's domain."""
        return self.surface.grid.bounds

    @property
    def outside_hull(self) -> float:
        """The share of the box outside the points' convex hull, where the fit extrapolates."""
        x0, x1, y0, y1 = self.box
        return float(1 - polygon_area(self.hull) / ((x1 - x0) * (y1 - y0)))

    def corners_outside(self) -> tuple[tuple[Fraction, Fraction], ...]:
        """The box corners outside the points' convex hull."""
        x0, x1, y0, y1 = self.box
        return tuple(c for c in ((x0, y0), (x1, y0), (x1, y1), (x0, y1)) if not inside_hull(self.hull, c))

    def beyond(self, threshold) -> tuple[int, ...]:
        """The 0-based indices of the points whose ``|residual|`` exceeds ``threshold``, largest first."""
        t = as_exact(threshold, "threshold")
        limit = t * self.residual_denominator
        out = [k for k, r in enumerate(self.residual_numerators) if abs(r) > limit]
        return tuple(sorted(out, key=lambda k: -abs(self.residual_numerators[k])))

    def report(self, threshold=None, limit: int = 10) -> str:
        """The residual report as lines of text: degrees, score, max, RMS, points beyond ``threshold``, extrapolation.

        ``threshold`` defaults to three times :attr:`sigma`.
        """
        (p, q), n = self.degree, len(self.points)
        lines = []
        if self.criterion:
            ranked = ", ".join(f"{a}x{b} {s:.4g}" for (a, b), s in self.scores[1:4])
            lines.append(f"degree {p}x{q} chosen by {_NAMES[self.criterion]}: score {self.score:.6g} "
                         f"(lowest of {len(self.scores)} candidates; next {ranked})" if ranked else
                         f"degree {p}x{q} chosen by {_NAMES[self.criterion]}: score {self.score:.6g}")
        else:
            lines.append(f"degree {p}x{q} as given")
        weighted = "weighted " if self.weights else ""
        lines.append(f"{n} points, {self.terms} coefficients, {weighted}least squares in exact rationals")
        lines.append(f"residuals: max {self.max_residual:.6g}, RMS {self.rms:.6g}, "
                     f"noise estimate sqrt(RSS/(N-k)) {self.sigma:.6g}")
        lines.append(f"amplification of errors in the points: {self.amplification:.4g} (the fit's Lebesgue "
                     f"function, sampled on {self.samples} x {self.samples} points of the box)")
        if threshold is None:
            t, said = Fraction(3) * as_exact(self.sigma, "sigma"), "3 x the noise estimate"
        else:
            t, said = as_exact(threshold, "--threshold"), "the threshold"
        far = self.beyond(t) if t > 0 else ()
        lines.append(f"{len(far)} point(s) beyond {float(t):.6g} ({said})")
        for k in far[:limit]:
            x, y, z = self.points[k]
            lines.append(f"  point {k + 1} at (x, y) = ({float(x):.6g}, {float(y):.6g}): z {float(z):.6g}, "
                         f"residual {float(self.residual(k)):+.6g}")
        if len(far) > limit:
            lines.append(f"  ... and {len(far) - limit} more")
        share = self.outside_hull
        x0, x1, y0, y1 = (float(v) for v in self.box)
        if share <= 0:
            lines.append(f"no extrapolation: the points' convex hull is the whole box x {x0:g}..{x1:g}, "
                         f"y {y0:g}..{y1:g}")
        else:
            corners = "; ".join(f"({float(a):g}, {float(b):g})" for a, b in self.corners_outside())
            lines.append(f"extrapolates on {100 * share:.3g} % of the box x {x0:g}..{x1:g}, y {y0:g}..{y1:g}: "
                         f"outside the points' convex hull ({len(self.hull)} vertices)"
                         + (f", near the corners {corners}" if corners else ""))
        return "\n".join(lines)


_NAMES = {"gcv": "generalized cross-validation", "loo": "leave-one-out"}


def representation_nodes(lo: Fraction, hi: Fraction, degree: int) -> tuple[Fraction, ...]:
    """``max(degree, 1) + 1`` exact nodes near the Chebyshev extrema of ``[lo, hi]``, the ends exactly ``lo``, ``hi``.

    The Lebesgue constant of these nodes stays below 2.5 up to degree 12, so
    the values stored at them amplify nothing.

    Examples
    --------
    >>> representation_nodes(Fraction(0), Fraction(10), 2)
    (Fraction(0, 1), Fraction(5, 1), Fraction(10, 1))
    """
    n = max(degree, 1)
    scale = 10 ** NODE_DIGITS
    out = []
    for i in range(n + 1):
        t = Fraction(round((1 - math.cos(math.pi * i / n)) / 2 * scale), scale)
        out.append(lo + (hi - lo) * t)
    return tuple(out)


def _common_denominator(values: Sequence[Fraction]) -> int:
    d = 1
    for v in values:
        d = math.lcm(d, v.denominator)
    return d


def _powers(values: Sequence[int], top: int) -> list[list[int]]:
    rows = []
    for v in values:
        row, acc = [1], 1
        for _ in range(top):
            acc *= v
            row.append(acc)
        rows.append(row)
    return rows


def _shift_matrix(scale: int, shift: int, degree: int) -> list[list[int]]:
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
        xs, ys, zs = ([pt[i] for pt in points] for i in range(3))
        dx, dy, dz = (_common_denominator(v) for v in (xs, ys, zs))
        if weights is None:
            W, dw = [1] * len(points), 1
        else:
            dw = _common_denominator(weights)
            W = [int(w * dw) for w in weights]
        return cls([int(v * dx) for v in xs], [int(v * dy) for v in ys], [int(v * dz) for v in zs], W,
                   dx, dy, dz, dw)


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
    pu = _powers([v - cx for v in s.X], 2 * p)
    pv = _powers([v - cy for v in s.Y], 2 * q)
    n = len(s.X)
    wu = flint.fmpz_mat(2 * p + 1, n, [w * r[e] for e in range(2 * p + 1) for w, r in zip(s.W, pu)])
    wzu = flint.fmpz_mat(p + 1, n, [w * z * r[e] for e in range(p + 1) for w, z, r in zip(s.W, s.Z, pu)])
    moments = wu * flint.fmpz_mat(n, 2 * q + 1, [c for r in pv for c in r])  # sum w u**s v**t
    rhs = wzu * flint.fmpz_mat(n, q + 1, [c for r in pv for c in r[:q + 1]])
    k = (p + 1) * (q + 1)
    idx = [(a, b) for a in range(p + 1) for b in range(q + 1)]
    gram = flint.fmpz_mat(k, k, [moments[a + c, b + d] for a, b in idx for c, d in idx])
    r = flint.fmpz_mat(k, 1, [rhs[a, b] for a, b in idx])
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
    col = flint.fmpz_mat((P + 1) * (Q + 1), 1, [int(c * den) for row in coefficients for c in row])
    xs = [[x ** a * s.dx ** (P - a) for a in range(P + 1)] for x in s.X]
    ys = [[y ** b * s.dy ** (Q - b) for b in range(Q + 1)] for y in s.Y]
    basis = flint.fmpz_mat(n, (P + 1) * (Q + 1), [u * v for rx, ry in zip(xs, ys) for u in rx for v in ry])
    values = basis * col
    scale = den * s.dx ** P * s.dy ** Q
    return tuple(z * scale - int(values[k, 0]) * s.dz for k, z in enumerate(s.Z)), scale * s.dz


def _check_points(points, source: str) -> tuple[tuple[Fraction, Fraction, Fraction], ...]:
    if isinstance(points, ControlGrid):
        return tuple(points.points())
    out = []
    for idx, pt in enumerate(points):
        if len(pt) != 3:
            raise InputError(f"{source}: point {idx + 1} should be (x, y, z), got {len(pt)} values")
        out.append(tuple(as_exact(v, f"{source}: point {idx + 1}") for v in pt))
    if not out:
        raise InputError(f"{source}: no points to fit")
    return tuple(out)


def _degree(degree) -> tuple[int, int] | None:
    if degree is None or degree == "auto":
        return None
    if isinstance(degree, str):
        if not re.fullmatch(r"[0-9]{1,6}(x[0-9]{1,6})?", degree.strip().lower()):
            raise InputError(f"degree {degree!r} should be a whole number (4), two (4x3) or 'auto'")
        vals = [int(v) for v in degree.strip().lower().split("x")]
    elif isinstance(degree, int) and not isinstance(degree, bool):
        vals = [degree]
    else:
        try:
            vals = [int(v) for v in degree]
        except (TypeError, ValueError):
            raise InputError(f"degree {degree!r} should be a whole number, a pair or 'auto'") from None
    if len(vals) == 1:
        vals = vals * 2
    if len(vals) != 2 or not all(0 <= v <= MAX_DEGREE for v in vals):
        raise InputError(f"degree {degree!r}: give degrees from 0 to {MAX_DEGREE} in x and y")
    return vals[0], vals[1]


def _chebyshev(values, lo: float, hi: float, top: int):
    import numpy as np

    t = (2 * np.asarray(values, dtype=float) - (lo + hi)) / (hi - lo) if hi > lo else np.zeros(len(values))
    return np.polynomial.chebyshev.chebvander(t, top)


def _scores(points, weights, criterion: str, max_degree: tuple[int, int]) -> list[tuple[tuple[int, int], float]]:
    """Every candidate's score in floating point, in the Chebyshev basis of the box, lowest first."""
    import numpy as np

    xs = np.array([float(p[0]) for p in points])
    ys = np.array([float(p[1]) for p in points])
    zs = np.array([float(p[2]) for p in points])
    w = np.ones(len(xs)) if weights is None else np.array([float(v) for v in weights])
    sw = np.sqrt(w)
    vx = _chebyshev(xs, xs.min(), xs.max(), max_degree[0])
    vy = _chebyshev(ys, ys.min(), ys.max(), max_degree[1])
    n = len(xs)
    out = []
    for p in range(max_degree[0] + 1):
        for q in range(max_degree[1] + 1):
            k = (p + 1) * (q + 1)
            if k >= n:
                continue
            a = (vx[:, :p + 1, None] * vy[:, None, :q + 1]).reshape(n, k) * sw[:, None]
            qm, rm = np.linalg.qr(a)
            diag = np.abs(np.diag(rm))
            if diag.min() <= 1e-10 * diag.max():
                continue  # these points do not determine the degree
            res = sw * zs - qm @ (qm.T @ (sw * zs))
            if criterion == "gcv":
                s = n * float(res @ res) / (n - k) ** 2
            else:
                h = np.einsum("ij,ij->i", qm, qm)
                s = float(np.mean((res / (1 - h)) ** 2))
            out.append(((p, q), s))
    out.sort(key=lambda t: (t[1], sum(t[0])))
    return out


def _exact_score(fit: SurfaceFit, criterion: str) -> float:
    """The chosen degrees' score from the exact residuals (leverages, for leave-one-out, in floating point)."""
    import numpy as np

    n, k = len(fit.points), fit.terms
    if criterion == "gcv":
        return float(n * fit.rss / (n - k) ** 2)
    xs = np.array([float(p[0]) for p in fit.points])
    ys = np.array([float(p[1]) for p in fit.points])
    sw = np.sqrt(np.array([float(v) for v in (fit.weights or (1,) * n)]))
    vx = _chebyshev(xs, xs.min(), xs.max(), fit.degree[0])
    vy = _chebyshev(ys, ys.min(), ys.max(), fit.degree[1])
    qm, _ = np.linalg.qr((vx[:, :, None] * vy[:, None, :]).reshape(n, k) * sw[:, None])
    h = np.einsum("ij,ij->i", qm, qm)
    r = np.array([float(v) for v in fit.residuals]) * sw
    return float(np.mean((r / (1 - h)) ** 2))


def fit_surface(points, degree=None, *, criterion: str | None = None, weights=None, max_degree=None,
                source: str | None = None, units: str | None = None) -> SurfaceFit:
    """The exact least-squares tensor-product polynomial through measured points.

    Parameters
    ----------
    points : ControlGrid or sequence of (x, y, z)
        A grid, or scattered points in any order; numbers are read exactly
        (:func:`lagsym.values.as_exact`: a float is the decimal it prints).
    degree : int, (int, int), str or None
        ``4`` (4 in x and y), ``(4, 3)`` or ``"4x3"``; None or ``"auto"``
        chooses them by ``criterion``.
    criterion : {"gcv", "loo"}, optional
        How ``degree=None`` chooses: generalized cross-validation (the
        default) or leave-one-out; refused with given degrees, which it
        would not change.
    weights : sequence of numbers, optional
        One positive weight per point (for example ``1 / sigma_k**2``).
    max_degree : int or (int, int), optional
        The highest degrees tried automatically (default: one less than the
        distinct x and y values, at most 8); each candidate must leave at
        least one point more than it has coefficients.
    source, units : str, optional
        The file name for messages and the units of the coordinates (a grid's own by default).

    Returns
    -------
    SurfaceFit
        The exact fit, its surface and its report.

    Examples
    --------
    A fit with as many coefficients as points is the Lagrange interpolant:

    >>> from lagsym.grid import grid_from_points
    >>> from lagsym.lagrange import lagrange_surface
    >>> g = grid_from_points([(0, 0, 1), (0, 1, 2), (1, 0, 3), (1, 1, 5), (2, 0, 4), (2, 1, 1)])
    >>> fit_surface(g, (2, 1)).surface.expr == lagrange_surface(g).expr
    True
    """
    if isinstance(points, ControlGrid):
        source = source or points.source
        units = units if units is not None else points.units
    source = source or "<points>"
    pts = _check_points(points, source)
    chosen = _degree(degree)
    if chosen is not None and (criterion is not None or max_degree is not None):
        given = "criterion" if criterion is not None else "max_degree"
        raise InputError(f"{given} chooses degrees; the degrees are given ({chosen[0]}x{chosen[1]}): "
                         f"leave out one or the other")
    criterion = choice(criterion or "gcv", CRITERIA, "criterion")
    w = None
    if weights is not None:
        w = tuple(as_exact(v, f"{source}: weight {i + 1}") for i, v in enumerate(weights))
        if len(w) != len(pts):
            raise InputError(f"{source}: {len(w)} weights for {len(pts)} points; give one weight per point")
        bad = next((i for i, v in enumerate(w) if v <= 0), None)
        if bad is not None:
            raise InputError(f"{source}: weight {bad + 1} = {w[bad]} is not positive")
    nx, ny = len({p[0] for p in pts}), len({p[1] for p in pts})
    if nx < 2 or ny < 2:
        raise GridError(f"{source}: the points have {nx} distinct x and {ny} distinct y values; "
                        f"a surface needs at least 2 of each")
    scores: list = []
    if chosen is None:
        top = _degree(max_degree) if max_degree is not None else (min(nx - 1, 8), min(ny - 1, 8))
        top = (min(top[0], nx - 1), min(top[1], ny - 1))
        scores = _scores(pts, w, criterion, top)
        if not scores:
            raise GridError(f"{source}: {len(pts)} points are too few to choose a degree by {criterion}; "
                            f"give --degree")
        chosen = scores[0][0]
    scaled = _Scaled.of(pts, w)
    coeffs = _solve(scaled, chosen, source)
    numerators, denominator = _residuals(scaled, coeffs)
    x0, x1 = min(p[0] for p in pts), max(p[0] for p in pts)
    y0, y1 = min(p[1] for p in pts), max(p[1] for p in pts)
    samples = _samples(len(pts))
    amp = _amplification(pts, w, chosen, samples)
    fit = SurfaceFit(surface=_surface(coeffs, (x0, x1, y0, y1), source, units, amp), coefficients=coeffs,
                     degree=chosen, points=pts, weights=w, residual_numerators=numerators,
                     residual_denominator=denominator, hull=_hull(scaled), amplification=amp,
                     samples=samples)
    if not scores:
        return fit
    return replace(fit, criterion=criterion, score=_exact_score(fit, criterion), scores=tuple(scores))


def _samples(n: int) -> int:
    return max(17, min(AMPLIFICATION_SAMPLES, math.isqrt(AMPLIFICATION_WORK // n)))


def _amplification(points, weights, degree: tuple[int, int], samples: int) -> float:
    """The largest value of the fit's Lebesgue function over a grid of the box, in floating point.

    With ``sqrt(W) A = Q R`` (``A`` the Chebyshev basis at the points), the
    fitted value at ``(x, y)`` is ``b(x, y) R^-1 Q^T sqrt(W) z``; the sum of
    the absolute values of that row's entries is the Lebesgue function.
    """
    import numpy as np

    xs = np.array([float(p[0]) for p in points])
    ys = np.array([float(p[1]) for p in points])
    sw = np.sqrt(np.array([float(v) for v in weights])) if weights is not None else np.ones(len(xs))
    (p, q), n = degree, len(xs)
    lo_x, hi_x, lo_y, hi_y = xs.min(), xs.max(), ys.min(), ys.max()
    a = (_chebyshev(xs, lo_x, hi_x, p)[:, :, None] * _chebyshev(ys, lo_y, hi_y, q)[:, None, :]).reshape(n, -1)
    qm, rm = np.linalg.qr(a * sw[:, None])
    k = samples
    gx = _chebyshev(np.linspace(lo_x, hi_x, k), lo_x, hi_x, p)
    gy = _chebyshev(np.linspace(lo_y, hi_y, k), lo_y, hi_y, q)
    b = (gx[:, None, :, None] * gy[None, :, None, :]).reshape(k * k, -1)
    coef = np.linalg.solve(rm.T, b.T).T  # b R^-1, one row an evaluation point
    best, rows = 0.0, max(1, 4_000_000 // n)
    for start in range(0, len(coef), rows):
        h = (coef[start:start + rows] @ qm.T) * sw
        best = max(best, float(np.abs(h).sum(axis=1).max()))
    return best


def _surface(coeffs, box, source: str, units: str | None, amp: float | None = None) -> LagrangeSurface:
    """The fitted polynomial as the Lagrange surface through its values at the representation nodes.

    The values are found with one exact matrix product; the surface's
    coefficients are the fit's own (padded to degree 1 where a degree is 0),
    which is what :func:`~lagsym.lagrange.lagrange_surface` of those values
    gives, since a polynomial of degree ``P`` is its own interpolant on
    ``P + 1`` nodes.
    """
    x0, x1, y0, y1 = box
    P, Q = len(coeffs) - 1, len(coeffs[0]) - 1
    nodes_x = representation_nodes(x0, x1, P)
    nodes_y = representation_nodes(y0, y1, Q)
    n, m = len(nodes_x), len(nodes_y)
    padded = [[coeffs[a][b] if a <= P and b <= Q else Fraction(0) for b in range(m)] for a in range(n)]
    vx = flint.fmpq_mat(n, n, [_fmpq(v ** a) for v in nodes_x for a in range(n)])
    vy = flint.fmpq_mat(m, m, [_fmpq(v ** b) for v in nodes_y for b in range(m)])
    cm = flint.fmpq_mat(n, m, [_fmpq(c) for row in padded for c in row])
    zm = vx * cm * vy.transpose()
    z = [[Fraction(int(zm[i, k].p), int(zm[i, k].q)) for k in range(m)] for i in range(n)]
    grid = replace(grid_from_table(nodes_x, nodes_y, z, source=source, units=units), amplification=amp)
    return LagrangeSurface(grid=grid, coefficients=tuple(tuple(r) for r in padded))


def _fmpq(v: Fraction) -> flint.fmpq:
    return flint.fmpq(v.numerator, v.denominator)


def _hull(s: _Scaled) -> tuple[tuple[Fraction, Fraction], ...]:
    return tuple((Fraction(a, s.dx), Fraction(b, s.dy)) for a, b in convex_hull(list(zip(s.X, s.Y))))


def _cross(o, a, b) -> Fraction:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def convex_hull(points) -> tuple[tuple[Fraction, Fraction], ...]:
    """The convex hull of ``(x, y)`` points, counter-clockwise, exact (Andrew's monotone chain).

    Examples
    --------
    >>> convex_hull([(0, 0), (2, 0), (1, 1), (2, 2), (0, 2)])
    ((0, 0), (2, 0), (2, 2), (0, 2))
    """
    pts = sorted(set(points))
    if len(pts) <= 2:
        return tuple(pts)
    lower: list = []
    for p in pts:
        while len(lower) >= 2 and _cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list = []
    for p in reversed(pts):
        while len(upper) >= 2 and _cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return tuple(lower[:-1] + upper[:-1])


def polygon_area(vertices) -> Fraction:
    """The exact area of a simple polygon (shoelace), 0 for fewer than 3 vertices."""
    if len(vertices) < 3:
        return Fraction(0)
    s = sum((Fraction(a[0]) * b[1] - Fraction(b[0]) * a[1]
             for a, b in zip(vertices, vertices[1:] + vertices[:1])), Fraction(0))
    return abs(s) / 2


def inside_hull(hull, point) -> bool:
    """Whether ``point`` lies in the counter-clockwise convex polygon ``hull`` (its border included)."""
    if len(hull) < 3:
        return False
    return all(_cross(a, b, point) >= 0 for a, b in zip(hull, hull[1:] + hull[:1]))
