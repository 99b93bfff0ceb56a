"""What the paper's section 4 warns about, measured for a given grid (``lagsym check``).

* degree in each direction: above 6 the paper sees the deviation grow greatly;
* the spacing ratio between the directions (limitation 2), as information
  only: rescaling one axis changes the ratio but leaves the interpolant's
  Lebesgue constants, overshoot and error bound exactly as they were, so the
  ratio says nothing about the surface, and the paper gives no threshold;
* the Lebesgue constant of each node set: how much the interpolant can amplify
  an error in the data (and floating-point rounding);
* the overshoot of the surface between the nodes compared with the data range
  (Runge's phenomenon);
* a bound on the rounding error of numeric samples, so that ill-conditioned
  grids are flagged instead of silently giving noise.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from .cad.extremes import Overshoot, overshoot
from .errors import ConditioningError
from .evaluate import surface_evaluator
from .grid import ControlGrid
from .lagrange import LagrangeSurface

__all__ = [
    "Finding", "CheckReport", "check_surface", "check_curve", "float_error_bound", "lebesgue_constant",
    "DEGREE_LIMIT", "SPACING_LIMIT", "LEBESGUE_LIMIT", "OVERSHOOT_LIMIT", "OVERSHOOT_REFUSED", "FLOAT_ERROR_LIMIT",
    "AMPLIFICATION_LIMIT", "Amplification", "amplification", "require_conditioning", "lebesgue_maximum",
]

DEGREE_LIMIT = 6  # the paper's danger line (section 4, item 4)
SPACING_LIMIT = 5.0  # lagsym's, not the paper's; outside 1/5..5 the ratio is pointed out, never a warning
LEBESGUE_LIMIT = 10.0  # data errors amplified more than tenfold
# A surface amplifies errors in its points by up to the product of its axes' Lebesgue constants.  Above
# 100, 0.01 mm of probe noise can become a millimetre.  The paper's examples stay below 5 (5x5 even
# nodes: 4.87); even nodes pass up to 8x8 (48), 9x9 is refused (120); Chebyshev-like nodes pass at any
# degree lagsym fits (12x12 of them: 6.2).
AMPLIFICATION_LIMIT = 100.0
OVERSHOOT_LIMIT = 0.10  # the surface leaves the data range by more than 10 % of it
OVERSHOOT_REFUSED = 1.0  # ... by more than the whole range: what the commands that machine or export refuse
FLOAT_ERROR_LIMIT = 1e-12  # numeric samples trusted to this fraction of the data range
EPS = float(np.finfo(float).eps)
# Neighbouring nodes closer than this fraction of their span (64 units of rounding at the span's end) are refused:
# floating point cannot place the samples between them that the Lebesgue constant is sought at.
NODE_RESOLUTION = Fraction(1, 2**47)


@dataclass(frozen=True)
class Finding:
    """One measured quantity, its limit and whether it crosses it."""

    name: str
    value: float
    limit: float
    warning: bool
    message: str


@dataclass(frozen=True)
class CheckReport:
    """All findings for one surface."""

    source: str
    findings: tuple[Finding, ...]

    @property
    def warnings(self) -> tuple[Finding, ...]:
        """The findings that cross their limit."""
        return tuple(f for f in self.findings if f.warning)

    def text(self) -> str:
        """The report as lines of text, one a finding."""
        lines = [f"{self.source}:"]
        for f in self.findings:
            lines.append(f"  {'WARNING' if f.warning else 'ok     '} {f.message}")
        lines.append(f"  {len(self.warnings)} warning(s)")
        return "\n".join(lines)


_CHUNK = 4_000_000
_LOG_MAX = math.log(sys.float_info.max)


def _spacing(nodes: np.ndarray) -> float:
    return float(np.mean(np.diff(nodes)))


def _log_lebesgue(s: np.ndarray, logw: np.ndarray, t: np.ndarray) -> np.ndarray:
    """log of sum_j |l(t) w_j / (t - t_j)| at points t strictly between nodes, l(t) = prod_k (t - t_k).

    The first (modified) Lagrange form with every factor in logarithms: all
    terms are positive, so nothing cancels and nothing overflows, however
    extreme the node spacing.
    """
    rows = max(_CHUNK // max(t[0].size * len(s), 1), 1)  # a few million terms at a time, however many nodes
    out = np.empty(t.shape)
    for i in range(0, len(t), rows):
        logd = np.log(np.abs(t[i:i + rows, ..., None] - s))
        terms = logd.sum(axis=-1, keepdims=True) + logw - logd
        top = terms.max(axis=-1)
        out[i:i + rows] = top + np.log(np.exp(terms - top[..., None]).sum(axis=-1))
    return out


def lebesgue_constant(nodes, samples: int = 17, rounds: int = 12) -> float:
    """The Lebesgue constant ``max_t sum_j |L_j(t)|`` of ``nodes`` over their span, to about 1e-12 relative.

    The Lebesgue function has one local maximum between each pair of
    neighbouring nodes; each is bracketed by sampling that interval and the
    bracket narrowed ``rounds`` times, so a narrow interval (clustered or
    geometric nodes) is searched as finely as a wide one.  The function is
    evaluated in logarithms (:func:`_log_lebesgue`).  This replaces the
    uniform sampling of :func:`lagsym.evaluate.lebesgue_constant`, which
    misses the maxima in narrow intervals and overflows at extreme
    conditioning (geometric nodes 1.1**k, k < 40: it returns inf where the
    constant is 1.571e32; 2.0**k, k < 30: 1.46e14 where it is 9.61e120).

    Examples
    --------
    >>> round(lebesgue_constant([0, 1]), 12), round(lebesgue_constant(range(20)))
    (1.0, 5890)
    """
    return lebesgue_maximum(nodes, samples, rounds)[0]


def lebesgue_maximum(nodes, samples: int = 17, rounds: int = 12, *, what: str = "nodes",
                     source: str | None = None) -> tuple[float, float]:
    """The Lebesgue constant of ``nodes`` and where the Lebesgue function reaches it (a coordinate in their span).

    The search of :func:`lebesgue_constant`, which this is.  Two nodes closer
    than :data:`NODE_RESOLUTION` of their span are refused (the search cannot
    tell them apart): with ``what`` (``"x nodes"``) and ``source`` (the file)
    in the message.

    Examples
    --------
    >>> value, at = lebesgue_maximum(range(12))
    >>> round(value, 1), 0 < at < 1 or 10 < at < 11
    (51.2, True)
    """
    exact = sorted(Fraction(v) for v in nodes)
    raw = np.asarray([float(v) for v in exact])
    if len(raw) < 2:
        return 1.0, float(raw[0]) if len(raw) else 0.0
    # The nodes scaled to [0, 1] exactly, then rounded: the constant does not change under scaling, and
    # nodes that differ far below a float's resolution at their size are still told apart.
    span = exact[-1] - exact[0]
    _check_gaps(exact, span, what, source)
    s = np.asarray([float((v - exact[0]) / span) for v in exact])
    diff = np.abs(s[:, None] - s[None, :])
    np.fill_diagonal(diff, 1.0)
    logw = -np.log(diff).sum(axis=1)
    lo, hi = s[:-1].copy(), s[1:].copy()
    u = np.linspace(0.0, 1.0, samples + 2)[1:-1]
    best = np.full(len(lo), -np.inf)
    where = np.zeros(len(lo))
    for _ in range(rounds):
        t = lo[:, None] + (hi - lo)[:, None] * u
        vals = _log_lebesgue(s, logw, t)
        vals[np.isnan(vals)] = -np.inf  # a sample that rounds onto a node: the function is 1 there, never the top
        k = vals.argmax(axis=1)
        top = vals[np.arange(len(lo)), k]
        centre = t[np.arange(len(lo)), k]
        where = np.where(top > best, centre, where)
        best = np.fmax(best, top)
        step = (hi - lo) / (samples + 1)
        lo, hi = np.maximum(centre - step, lo), np.minimum(centre + step, hi)
    i = int(best.argmax())
    value = math.exp(best[i]) if best[i] < _LOG_MAX else math.inf  # beyond a float: said as such, not overflowed
    return value, float(raw[0] + where[i] * (raw[-1] - raw[0]))


def _check_gaps(exact: list[Fraction], span: Fraction, what: str, source: str | None) -> None:
    """Refuse two neighbouring ``exact`` nodes closer than :data:`NODE_RESOLUTION` of their ``span``."""
    for a, b in zip(exact, exact[1:]):
        if b - a <= span * NODE_RESOLUTION:
            where = f"{source}: " if source else ""
            how = "are equal" if a == b else (f"are closer than floating point can tell apart over their span of "
                                              f"{_decimal(span)} (a gap of {float((b - a) / span):.3g} of it)")
            raise ConditioningError(f"{where}{what} {_decimal(a)} and {_decimal(b)} {how}: the Lebesgue constant is "
                                    f"beyond any limit; space the nodes further apart")


def _decimal(v: Fraction) -> str:
    """An exact node as the user wrote it: a decimal where it has one (1.0000000000000000000001), else p/q."""
    d = v.denominator
    while d % 2 == 0:
        d //= 2
    while d % 5 == 0:
        d //= 5
    if d != 1 or v.denominator > 10**60:
        return str(v)
    from decimal import Decimal, localcontext

    with localcontext() as ctx:
        ctx.prec = 80
        return format(Decimal(v.numerator) / Decimal(v.denominator), "f")


@dataclass(frozen=True)
class Amplification:
    """How much a grid's Lagrange surface can amplify errors in its heights.

    The surface is ``sum_ik L_i(x) L_k(y) z_ik``; an error ``e_ik`` in the
    heights moves it by ``sum_ik L_i(x) L_k(y) e_ik``, at most
    ``max|e| * (sum_i |L_i(x)|) (sum_k |L_k(y)|)``, whose largest value over
    the box is the product of the two axes' Lebesgue constants (the tensor
    Lebesgue function is the product of the 1-D ones, so the bound is
    reached).

    Attributes
    ----------
    value : float
        ``lebesgue_x * lebesgue_y``.
    lebesgue_x, lebesgue_y : float
        Each axis's Lebesgue constant.
    at : tuple of float
        ``(x, y)`` where the amplification is largest.
    limit : float
        The limit it was judged against.
    """

    value: float
    lebesgue_x: float
    lebesgue_y: float
    at: tuple[float, float]
    limit: float = AMPLIFICATION_LIMIT
    fitted: bool = False  # the value is a least-squares fit's, from the points it was fitted to

    @property
    def exceeds(self) -> bool:
        """Whether the amplification is above :attr:`limit`."""
        return self.value > self.limit

    def text(self) -> str:
        """The figure in words."""
        if self.fitted:
            return (f"errors in the measured points can be amplified up to {_times(self.value)} by this "
                    f"least-squares fit (its Lebesgue function sampled over the box)")
        return (f"errors in the points can be amplified up to {_times(self.value)} (Lebesgue constants "
                f"{_figure(self.lebesgue_x)} in x times {_figure(self.lebesgue_y)} in y), worst near (x, y) = "
                f"({self.at[0]:.4g}, {self.at[1]:.4g})")

    def header_note(self) -> str:
        """The program header's note when the surface was accepted above the limit."""
        return f"conditioning {_figure(self.value)}x above {self.limit:g} accepted (--accept-conditioning)"


def _figure(v: float, spec: str = ".4g") -> str:
    """A Lebesgue constant or an amplification: beyond a float's range said so, not as ``inf``."""
    return format(v, spec) if math.isfinite(v) else f"more than {sys.float_info.max:.4g}"


def _times(v: float) -> str:
    return f"{_figure(v)} times"


def amplification(surface, limit: float = AMPLIFICATION_LIMIT) -> Amplification:
    """The :class:`Amplification` of a grid or of a :class:`~lagsym.lagrange.LagrangeSurface`.

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> a = amplification(grid_from_table(range(12), range(12), [[0] * 12] * 12))
    >>> round(a.value), a.exceeds
    (2623, True)
    """
    g = surface if isinstance(surface, ControlGrid) else surface.grid
    lx, ax = lebesgue_maximum(g.x, what="x nodes", source=g.source)
    ly, ay = lebesgue_maximum(g.y, what="y nodes", source=g.source)
    if g.amplification is not None:  # the heights were computed from measured points: theirs is the figure
        return Amplification(g.amplification, lx, ly, (ax, ay), limit, fitted=True)
    return Amplification(lx * ly, lx, ly, (ax, ay), limit)


def require_conditioning(surface, *, accept: bool = False, limit: float = AMPLIFICATION_LIMIT) -> Amplification:
    """The surface's :class:`Amplification`, refused above ``limit`` unless ``accept``.

    Every command that turns a surface into something physical (a toolpath, a
    program, a macro, an exported or sampled file) asks this first: an
    interpolant of measured points whose nodes amplify their errors a hundred
    times machines the noise, not the part.

    Raises
    ------
    ConditioningError
        Naming the figure, where it is largest and the ways out: a
        least-squares fit (``lagsym fit``), fewer or Chebyshev-spaced nodes,
        smooth pieces (``lagsym piecewise``), or ``--accept-conditioning``.
    """
    a = amplification(surface, limit)
    if a.exceeds and not accept:
        g = surface if isinstance(surface, ControlGrid) else surface.grid
        way = ("fit them at lower degrees (lagsym fit POINTS --degree auto)" if a.fitted else
               f"fit the points instead (lagsym fit {g.source} -o surface.json), use fewer or Chebyshev-spaced nodes, "
               f"join exact points by smooth pieces (lagsym piecewise {g.source} -o pieces.json)")
        raise ConditioningError(
            f"{g.source}: {a.text()}, above lagsym's limit of {limit:g}: 0.01 of measurement noise could move "
            f"the surface by {_figure(0.01 * a.value, '.3g')}; {way}, or give --accept-conditioning to use it as it is")
    return a


def require_overshoot(surface: LagrangeSurface, *, accept: bool = False,
                      limit: float = OVERSHOOT_REFUSED) -> Overshoot:
    """The interpolant's :class:`~lagsym.cad.extremes.Overshoot`, refused above ``limit`` (a share of the data
    range, certified) unless ``accept``: a surface that leaves its points' heights by more than their whole
    range between them is not the part they describe.

    Raises
    ------
    ConditioningError
        Naming the figure, where it was seen, and the ways out.
    """
    o = overshoot(surface)
    if o.share > limit and not accept:
        g = surface.grid
        raise ConditioningError(
            f"{g.source}: the surface leaves its points' heights by up to {o.most:.4g} between them "
            f"({100 * o.share:.3g}% of their range {o.data_range:.4g}, certified; seen near (x, y) = "
            f"({o.at[0]:.4g}, {o.at[1]:.4g})), "
            f"above lagsym's limit of {100 * limit:g}%; fit the points instead (lagsym fit {g.source} -o "
            f"surface.json), join them by smooth pieces (lagsym piecewise {g.source} -o pieces.json), or give "
            f"--accept-conditioning to use it as it is")
    return o


def float_error_bound(surface: LagrangeSurface, box: tuple[float, float, float, float] | None = None) -> float:
    """A bound on the floating-point error of the numeric evaluator, as a fraction of the data range.

    The evaluator (:class:`~lagsym.evaluate.SurfaceEvaluator`) works in the
    Chebyshev basis of normalized coordinates, with coefficients found
    exactly; its rounding error is a few units of rounding times
    ``sum |C[a, b]|`` weighted by degree.  That sum is of the size of the
    surface itself, so the bound grows only where the surface does: with many
    equally spaced nodes and rough data the interpolant swings far beyond the
    data (Runge), and the bound says the samples cannot be trusted to the
    last digits.  ``box`` (``(x0, x1, y0, y1)``) defaults to the control box;
    beyond it (extrapolation) the bound grows.
    """
    return surface_evaluator(surface).relative_error_bound(box)


def check_surface(surface: LagrangeSurface, samples_per_interval: int = 24) -> CheckReport:
    """Measure what the paper's limitations warn about for ``surface``."""
    g = surface.grid
    dx, dy = g.degree
    findings = []
    amp = amplification(g)
    for axis, d, lam in (("x", dx, amp.lebesgue_x), ("y", dy, amp.lebesgue_y)):
        # The paper's line at 6 was drawn for even spacing; what makes a degree dangerous is the amplification
        # its nodes give (Chebyshev-like nodes at degree 11: 2.49), so the degree is judged by that.
        bad = d > DEGREE_LIMIT and lam > LEBESGUE_LIMIT
        if d <= DEGREE_LIMIT:
            note = f" (the paper's line: {DEGREE_LIMIT})"
        elif bad:
            note = f" (above {DEGREE_LIMIT}, the paper's danger line, on nodes with Lebesgue constant {lam:.3g})"
        else:
            note = (f" (above the paper's {DEGREE_LIMIT}, but on well-spaced nodes: Lebesgue constant {lam:.3g}, "
                    f"so not a danger)")
        findings.append(Finding(f"degree_{axis}", d, DEGREE_LIMIT, bad, f"degree in {axis}: {d}{note}"))
    ratio = _spacing(g.x_array) / _spacing(g.y_array)
    far = ratio > SPACING_LIMIT or ratio < 1 / SPACING_LIMIT
    # Not a warning: x -> a x maps the interpolant onto itself, so nothing measured above or below changes.
    findings.append(
        Finding("spacing_ratio", ratio, SPACING_LIMIT, False,
                f"spacing ratio mean dx / mean dy: {ratio:.4g} (information: the paper's limitation 2 names it, "
                f"but rescaling an axis changes no measure of the surface"
                + (f"; outside lagsym's 1/{SPACING_LIMIT:g}..{SPACING_LIMIT:g}" if far else "") + ")")
    )
    for axis, lam in (("x", amp.lebesgue_x), ("y", amp.lebesgue_y)):
        findings.append(
            Finding(f"lebesgue_{axis}", lam, LEBESGUE_LIMIT, lam > LEBESGUE_LIMIT,
                    f"Lebesgue constant of the {axis} nodes: {lam:.4g}"
                    + (f" (along {axis} alone, data errors can be amplified {lam:.3g} times)"
                       if lam > LEBESGUE_LIMIT else ""))
        )
    findings.append(
        Finding("amplification", amp.value, AMPLIFICATION_LIMIT, amp.exceeds,
                (f"surface amplification of errors in the measured points it was fitted to: {amp.value:.4g} "
                 f"(the fit's Lebesgue function, sampled)" if amp.fitted else
                 f"surface amplification of data errors: {amp.value:.4g} (the product of the two, worst near "
                 f"(x, y) = ({amp.at[0]:.4g}, {amp.at[1]:.4g}))")
                + (f": above {AMPLIFICATION_LIMIT:g}, so toolpath, rough, job, macro, export and sample refuse it "
                   f"without --accept-conditioning; for measured points use 'lagsym fit', for a large grid of exact "
                   f"points 'lagsym piecewise'"
                   if amp.exceeds else f" (limit {AMPLIFICATION_LIMIT:g})"))
    )
    o = overshoot(surface, samples_per_interval)
    findings.append(
        Finding("overshoot", o.share, OVERSHOOT_LIMIT, o.share > OVERSHOOT_LIMIT,
                f"overshoot between nodes: {o.sampled:.4g} sampled, worst near (x, y) = ({o.at[0]:.4g}, "
                f"{o.at[1]:.4g}); at most {o.most:.4g} ({100 * o.share:.3g}% of the data range "
                f"{o.data_range:.4g}), certified from the Bezier form")
    )
    err = float_error_bound(surface)
    bad = err > FLOAT_ERROR_LIMIT
    findings.append(
        Finding("float_error", err, FLOAT_ERROR_LIMIT, bad,
                f"floating-point evaluation error bound: {err:.2g} of the data range"
                + (f" (numeric samples cannot be trusted to {FLOAT_ERROR_LIMIT:g}; use fewer or Chebyshev-spaced "
                   f"nodes, or exact values from 'lagsym equation')" if bad else f" (limit {FLOAT_ERROR_LIMIT:g})"))
    )
    return CheckReport(source=g.source, findings=tuple(findings))


def check_curve(curve, samples_per_interval: int = 48) -> CheckReport:
    """The same measures for a 1-D Lagrange curve: degree, Lebesgue constant, overshoot."""
    from .evaluate import evaluate_curve

    p = curve.points
    d = curve.degree
    lam = lebesgue_maximum(p.x, what="x nodes", source=p.source)[0]
    xs = np.linspace(p.x_array[0], p.x_array[-1], d * samples_per_interval + 1)
    ys = evaluate_curve(curve, xs)
    lo, hi = float(p.y_array.min()), float(p.y_array.max())
    over = max(float(ys.max()) - hi, lo - float(ys.min()), 0.0)
    rel = over / (hi - lo) if hi > lo else (0.0 if over <= 1e-12 * max(abs(hi), 1.0) else float("inf"))
    findings = (
        Finding("degree_x", d, DEGREE_LIMIT, d > DEGREE_LIMIT,
                f"degree: {d}" + (f" (above {DEGREE_LIMIT}, the paper's danger line)" if d > DEGREE_LIMIT
                                  else f" (limit {DEGREE_LIMIT})")),
        Finding("lebesgue_x", lam, LEBESGUE_LIMIT, lam > LEBESGUE_LIMIT,
                f"Lebesgue constant of the nodes: {lam:.4g}"
                + (f" (data errors can be amplified {lam:.3g} times)" if lam > LEBESGUE_LIMIT else "")),
        Finding("overshoot", rel, OVERSHOOT_LIMIT, rel > OVERSHOOT_LIMIT,
                f"overshoot between nodes: {over:.4g} ({100 * rel:.3g}% of the data range {hi - lo:.4g})"),
    )
    return CheckReport(source=p.source, findings=findings)
