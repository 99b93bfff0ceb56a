"""The fit as a value: :class:`SurfaceFit`, made by :func:`fit_surface`, with its surface and its report."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from fractions import Fraction
from functools import cached_property

import flint
import numpy as np

from .._arrays import readonly
from ..errors import GridError, InputError
from ..grid import ControlGrid, grid_from_table
from ..io.decimals import DecimalPoints
from ..lagrange import LagrangeSurface, horner2
from ..values import as_exact, choice
from .exact import _residuals, _Scaled, _solve, float_residuals
from .hull import convex_hull_integers, inside_hull, polygon_area
from .select import AMPLIFICATION_SAMPLES, CRITERIA, amplification, leave_one_out, parse_degree, samples_for
from .select import scores as score_all

__all__ = ["SurfaceFit", "fit_surface", "representation_nodes", "NODE_DIGITS"]

NODE_DIGITS = 6  # representation nodes: the Chebyshev extrema rounded to 1e-6 of the box


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
    points : sequence of (Fraction, Fraction, Fraction)
        The data, in the order given: a tuple, or the
        :class:`~lagsym.io.decimals.DecimalPoints` a table of plain decimals was read into.
    weights : tuple of Fraction or None
        The weights, when given.
    criterion : str or None
        ``"gcv"`` or ``"loo"`` when the degrees were chosen, else None.
    score : float or None
        The chosen degrees' score under ``criterion`` (from :attr:`float_residuals`).
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
    points: Sequence[tuple[Fraction, Fraction, Fraction]]
    weights: tuple[Fraction, ...] | None
    criterion: str | None = None
    score: float | None = None
    scores: tuple[tuple[tuple[int, int], float], ...] = ()
    hull: tuple[tuple[Fraction, Fraction], ...] = ()
    amplification: float = 1.0
    samples: int = AMPLIFICATION_SAMPLES
    scaled: object = field(default=None, repr=False, compare=False)  # the points in integers (.exact._Scaled)

    @property
    def terms(self) -> int:
        """The number of coefficients, ``(P + 1) (Q + 1)``."""
        return (self.degree[0] + 1) * (self.degree[1] + 1)

    @cached_property
    def _exact_residuals(self) -> tuple[tuple[int, ...], int]:
        # Made when asked only: with many points each is an integer of thousands of digits.
        return _residuals(self.scaled if self.scaled is not None else _Scaled.of(self.points, self.weights),
                          self.coefficients)

    @property
    def residual_numerators(self) -> tuple[int, ...]:
        """``z_k - p(x_k, y_k)`` times :attr:`residual_denominator`, exactly, in the order of the points."""
        return self._exact_residuals[0]

    @property
    def residual_denominator(self) -> int:
        """The one denominator of every exact residual."""
        return self._exact_residuals[1]

    @cached_property
    def _floats(self) -> tuple[np.ndarray, float]:
        found, bound = float_residuals(self.points, self.coefficients, self.box)
        return readonly(found), bound

    @property
    def float_residuals(self) -> np.ndarray:
        """``z_k - p(x_k, y_k)`` in floating point (:func:`.exact.float_residuals`): the statistics' residuals."""
        return self._floats[0]

    @cached_property
    def residuals(self) -> tuple[Fraction, ...]:
        """``z_k - p(x_k, y_k)``, exact, in the order of the points."""
        return tuple(Fraction(r, self.residual_denominator) for r in self.residual_numerators)

    def residual(self, k: int) -> Fraction:
        """The residual of point ``k`` (0-based), exact."""
        if "_exact_residuals" in self.__dict__:
            return Fraction(self.residual_numerators[k], self.residual_denominator)
        return self._exact_residual(k)

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
        return float(np.abs(self.float_residuals).max())

    @cached_property
    def rms(self) -> float:
        """The root mean square residual (unweighted)."""
        return math.sqrt(math.fsum(self.float_residuals ** 2) / len(self.points))

    @cached_property
    def float_rss(self) -> float:
        """The (weighted) residual sum of squares from :attr:`float_residuals`."""
        w = 1.0 if self.weights is None else np.array([float(v) for v in self.weights])
        return math.fsum(w * self.float_residuals ** 2)

    @property
    def sigma(self) -> float:
        """The noise estimate ``sqrt(RSS / (N - k))`` (weighted residuals; 0 when the fit interpolates)."""
        dof = len(self.points) - self.terms
        return math.sqrt(self.float_rss / dof) if dof > 0 else 0.0

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
        size = np.abs(self.float_residuals)
        # The float residuals decide but within their error bound of the threshold, where the exact one does.
        near = self._floats[1] + abs(float(t)) * 1e-15
        out = [int(k) for k in np.flatnonzero(size > float(t) + near)]
        out += [int(k) for k in np.flatnonzero(np.abs(size - float(t)) <= near) if abs(self._exact_residual(k)) > t]
        return tuple(sorted(out, key=lambda k: -size[k]))

    def _exact_residual(self, k: int) -> Fraction:
        x, y, z = self.points[k]
        return z - horner2(self.coefficients, x, y)

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


def _check_points(points, source: str):
    """The points as exact ``(x, y, z)``: a tuple of tuples of Fractions, or points read in whole columns as they
    are (:class:`~lagsym.io.decimals.DecimalPoints`, exact already)."""
    if isinstance(points, ControlGrid):
        return tuple(points.points())
    if isinstance(points, DecimalPoints) and len(points.columns) == 3 and len(points):
        return points
    out = []
    for idx, pt in enumerate(points):
        if len(pt) != 3:
            raise InputError(f"{source}: point {idx + 1} should be (x, y, z), got {len(pt)} values")
        out.append(tuple(as_exact(v, f"{source}: point {idx + 1}") for v in pt))
    if not out:
        raise InputError(f"{source}: no points to fit")
    return tuple(out)


def _distinct(points, j: int) -> int:
    """How many distinct values coordinate ``j`` takes."""
    if isinstance(points, DecimalPoints):
        return int(np.unique(points.columns[j]).size)
    return len({p[j] for p in points})


def _score(fit: SurfaceFit, criterion: str) -> float:
    """The chosen degrees' score from the residuals in floating point (as the candidates' scores are)."""
    n, k = len(fit.points), fit.terms
    if criterion == "gcv":
        return n * fit.float_rss / (n - k) ** 2
    return leave_one_out(fit.points, fit.weights, fit.float_residuals, fit.degree)


def _weights(weights, n: int, source: str) -> tuple[Fraction, ...] | None:
    if weights is None:
        return None
    w = tuple(as_exact(v, f"{source}: weight {i + 1}") for i, v in enumerate(weights))
    if len(w) != n:
        raise InputError(f"{source}: {len(w)} weights for {n} points; give one weight per point")
    bad = next((i for i, v in enumerate(w) if v <= 0), None)
    if bad is not None:
        raise InputError(f"{source}: weight {bad + 1} = {w[bad]} is not positive")
    return w


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
    chosen = parse_degree(degree)
    if chosen is not None and (criterion is not None or max_degree is not None):
        given = "criterion" if criterion is not None else "max_degree"
        raise InputError(f"{given} chooses degrees; the degrees are given ({chosen[0]}x{chosen[1]}): "
                         f"leave out one or the other")
    criterion = choice(criterion or "gcv", CRITERIA, "criterion")
    w = _weights(weights, len(pts), source)
    nx, ny = _distinct(pts, 0), _distinct(pts, 1)
    if nx < 2 or ny < 2:
        raise GridError(f"{source}: the points have {nx} distinct x and {ny} distinct y values; "
                        f"a surface needs at least 2 of each")
    scores: list = []
    if chosen is None:
        top = parse_degree(max_degree) if max_degree is not None else (min(nx - 1, 8), min(ny - 1, 8))
        top = (min(top[0], nx - 1), min(top[1], ny - 1))
        scores = score_all(pts, w, criterion, top)
        if not scores:
            raise GridError(f"{source}: {len(pts)} points are too few to choose a degree by {criterion}; "
                            f"give --degree")
        chosen = scores[0][0]
    scaled = _Scaled.of(pts, w)
    coeffs = _solve(scaled, chosen, source)
    # the box from the integers of the common denominators: no comparison of two Fractions a point
    x0, x1 = Fraction(min(scaled.X), scaled.dx), Fraction(max(scaled.X), scaled.dx)
    y0, y1 = Fraction(min(scaled.Y), scaled.dy), Fraction(max(scaled.Y), scaled.dy)
    samples = samples_for(len(pts))
    amp = amplification(pts, w, chosen, samples)
    fit = SurfaceFit(surface=_surface(coeffs, (x0, x1, y0, y1), source, units, amp), coefficients=coeffs,
                     degree=chosen, points=pts, weights=w, hull=_hull(scaled), amplification=amp,
                     samples=samples, scaled=scaled)
    if not scores:
        return fit
    scored = replace(fit, criterion=criterion, score=_score(fit, criterion), scores=tuple(scores))
    scored.__dict__["_floats"] = fit._floats  # computed for the score: not computed again
    return scored


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
    return tuple((Fraction(a, s.dx), Fraction(b, s.dy)) for a, b in convex_hull_integers(s.X, s.Y))
