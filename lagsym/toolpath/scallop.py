"""Row levels from a scallop height measured normal to the surface: walked across the rows, one gap at a time.

Between two passes of a ball of radius ``R`` whose centres run on parallel
lines ``d`` apart, over a cross-section of the surface with normal curvature
``k`` across the passes (positive where it bends up, a hollow), the cusp left
standing, measured along the normal, is

    h(d) = (2 R - k R**2 + k d**2 / 4) / (1 + sqrt((1 - k R)**2 - k**2 d**2 / 4)) - sqrt(R**2 - d**2 / 4)

(the circle of the ball's section about each centre, the centres on the
offset of the section at ``R``; ``k = 0`` gives the flat floor's
``R - sqrt(R**2 - d**2 / 4)``).  On a surface sloping with gradient
``(fp, fc)`` along and across the rows, passes a horizontal distance ``s``
apart run ``d = s * sqrt(1 + fp**2 + fc**2) / sqrt(1 + fp**2)`` apart, so a
flank leaves a cusp many times the flat floor's at the same side step.

:func:`scallop_levels` samples slope and curvature on a grid over the box,
finds at each sample the largest ``s`` whose cusp is at most the request,
and walks across the box: the gap after a row is the smallest allowed ``s``
over every sample along the row and across the band the two passes touch
(from one tool radius before the row to one radius past the next), so the
request holds wherever that band's worst sample holds it.  Where the surface
is a hollow tighter than the ball in any direction (a principal curvature
``k1 R >= 1``, along the rows too) the ball rests on both walls and cannot
reach its bottom at any step, and where the section barely fits (a radius
within 1.6 % of the ball's: the centre distance allowed is below an eighth
of the flat floor's) no practical step meets the request; those samples do
not limit the gap and are counted apart.  The cusp predicted for the gaps
chosen elsewhere is reported with where it is worst; :func:`row_cusps` and
:func:`gap_cusps` predict it for rows given (a fixed side step).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import ToolpathError
from ..evaluate import SurfaceEvaluator
from .pattern import scallop_stepover

__all__ = ["cusp_height", "ScallopRows", "TooManyRows", "scallop_levels", "row_cusps", "gap_cusps"]

_ALONG_SAMPLES = 401  # samples along a row (slopes and curvature are polynomials of low degree)
_CROSS_PER_STEP = 4  # cross samples per flat-floor side step
_MAX_CROSS = 4001
_FLOOR = 1.0 / 50  # the smallest gap, as a fraction of the flat floor's side step
_TIGHT = 1.0 / 8  # a centre distance below this fraction of the flat floor's: a hollow the ball barely fits


def cusp_height(d, k, radius: float) -> np.ndarray:
    """Cusp height normal to the surface between ball centres ``d`` apart over a section of curvature ``k``.

    ``nan`` where the section is a hollow too tight for the centres to be
    ``d`` apart on its offset.

    Examples
    --------
    >>> round(float(cusp_height(0.4895, 0.0, 3.0)), 4)  # the flat floor
    0.01
    >>> bool(cusp_height(0.4895, 0.1, 3.0) > 0.01 > cusp_height(0.4895, -0.1, 3.0))
    True
    """
    d, k = np.broadcast_arrays(np.asarray(d, dtype=float), np.asarray(k, dtype=float))
    r = radius
    a = (1.0 - k * r) ** 2 - k * k * d * d / 4.0
    b = r * r - d * d / 4.0
    ok = (a >= 0) & (b >= 0) & (k * r < 1.0)
    with np.errstate(invalid="ignore"):
        h = (2.0 * r - k * r * r + k * d * d / 4.0) / (1.0 + np.sqrt(np.where(ok, a, 0.0))) - np.sqrt(np.where(ok, b, 0))
    return np.where(ok, h, np.nan)


def _allowed_d(k, radius: float, scallop: float) -> np.ndarray:
    """The largest centre distance whose cusp is at most ``scallop`` (``nan`` where ``k R >= 1``).

    Solved in closed form: with ``q = sqrt(R**2 - d**2 / 4)`` the cusp
    equation gives ``q = (2 (R - h) + k h**2) / (2 (1 - k h))`` on either side
    of ``k = 0``, so ``d**2 / 4 = (R - q) (R + q)`` with ``R - q = h (2 - k (2 R
    + h)) / (2 (1 - k h))``, no cancellation near a flat section.  Where the
    cusp stays below ``h`` up to the largest centre distance the section
    allows, that distance; a root the cusp does not confirm (to a part in
    10**9) is found by bisection instead.
    """
    k = np.asarray(k, dtype=float)
    r, h = radius, scallop
    fits = k * r < 1.0
    hi = np.where(k > 0, np.minimum(2 * r, 2 * (1 - np.minimum(k * r, 1.0)) / np.where(k > 0, k, 1.0)), 2 * r)
    with np.errstate(invalid="ignore", divide="ignore"):
        below = h * (2.0 - k * (2.0 * r + h)) / (2.0 * (1.0 - k * h))  # R - q
        d = np.where(below >= 0, 2.0 * np.sqrt(below * (2.0 * r - below)) * (1.0 - 1e-12), np.inf)  # the safe side
        d = np.minimum(np.where(np.isnan(d), np.inf, d), hi)
        cusp = cusp_height(d, k, r)
    confirmed = np.isfinite(cusp) & (cusp <= h * (1 + 1e-9)) & ((d == hi) | (cusp >= h * (1 - 1e-6)))
    todo = fits & ~confirmed
    if todo.any():
        d[todo] = _bisected_d(k[todo], hi[todo], r, h)
    return np.where(fits, d, np.nan)


def _bisected_d(k, hi, radius: float, scallop: float) -> np.ndarray:
    """The largest centre distance below ``hi`` whose cusp is at most ``scallop``, by bisection."""
    lo = np.zeros_like(hi)
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        h = cusp_height(mid, k, radius)
        good = np.isfinite(h) & (h <= scallop)
        lo, hi = np.where(good, mid, lo), np.where(good, hi, mid)
    return lo


@dataclass(frozen=True)
class ScallopRows:
    """Row levels (surface units) and the worst cusp predicted between them (mm, normal to the surface).

    ``worst_at`` is ``(p, c)``, the surface position (along the rows, across
    them) of the worst predicted cusp; ``tight`` the number of samples where
    the surface is a hollow tighter than the ball (left out of the
    prediction), of ``samples``.
    """

    levels: np.ndarray
    worst_mm: float
    worst_at: tuple[float, float]
    tight: int
    samples: int = 0


def _samples(ev: SurfaceEvaluator, direction: str, mm_per_unit: float, flat_step_mm: float, radius_mm: float):
    """Along and cross sample positions (surface units) and the gap allowed per unit of centre distance.

    Returns ``(along, cross, stretch, k)``: ``stretch = sqrt(1 + fp**2) / w``
    turns a centre distance into a horizontal gap; ``k`` the normal curvature
    (1/mm) across the rows, ``nan`` where the surface is a hollow tighter
    than the ball in some direction (:func:`_across_curvature`); both shaped
    ``(cross, along)``.
    """
    x0, x1, y0, y1 = (float(v) for v in ev.bounds)
    (a0, a1), (c0, c1) = ((x0, x1), (y0, y1)) if direction == "x" else ((y0, y1), (x0, x1))
    along = np.linspace(a0, a1, _ALONG_SAMPLES)
    n_cross = int(min(_MAX_CROSS, max(3, math.ceil((c1 - c0) * mm_per_unit / flat_step_mm * _CROSS_PER_STEP) + 1)))
    cross = np.linspace(c0, c1, n_cross)
    cg, ag = np.meshgrid(cross, along, indexing="ij")
    xy = (ag, cg) if direction == "x" else (cg, ag)

    def d(i, j):  # partial derivative in the (along, cross) frame, per mm
        dx, dy = (i, j) if direction == "x" else (j, i)
        return ev.fast_points(*xy, dx=dx, dy=dy) / mm_per_unit ** (i + j - 1)

    fp, fc, fpp, fpc, fcc = d(1, 0), d(0, 1), d(2, 0), d(1, 1), d(0, 2)
    w = np.sqrt(1.0 + fp * fp + fc * fc)
    return along, cross, np.sqrt(1.0 + fp * fp) / w, _across_curvature(fp, fc, fpp, fpc, fcc, radius_mm)


def _across_curvature(fp, fc, fpp, fpc, fcc, radius: float) -> np.ndarray:
    """The surface's normal curvature across the rows (the tangent direction perpendicular to the path).

    ``nan`` where a principal curvature is ``1 / R`` or more: a hollow
    tighter than the ball in some direction (along the rows too), whose
    bottom the ball cannot reach; there it rests on both walls and the
    cross-section's cusp says nothing.  (On a saddle the section's own
    curvature is the one that counts: a ball swept along rows over
    ``z = a x y`` leaves the flat floor's cusp, measured, to 1 %, with
    ``a R`` up to 0.9.)
    """
    w2 = 1.0 + fp * fp + fc * fc
    w = np.sqrt(w2)
    a, b = -fp * fc, 1.0 + fp * fp
    k = (fpp * a * a + 2 * fpc * a * b + fcc * b * b) / (w * (a * a + b * b + (a * fp + b * fc) ** 2))
    # The larger eigenvalue of the shape operator I^-1 II of z = F.
    s00 = ((1 + fc * fc) * fpp - fp * fc * fpc) / (w2 * w)
    s01 = ((1 + fc * fc) * fpc - fp * fc * fcc) / (w2 * w)
    s10 = ((1 + fp * fp) * fpc - fp * fc * fpp) / (w2 * w)
    s11 = ((1 + fp * fp) * fcc - fp * fc * fpc) / (w2 * w)
    half = (s00 + s11) / 2
    k1 = half + np.sqrt(np.maximum(half * half - (s00 * s11 - s01 * s10), 0.0))
    return np.where(k1 * radius >= 1.0, np.nan, k)


def scallop_levels(ev: SurfaceEvaluator, direction: str, radius_mm: float, scallop_mm: float,
                   mm_per_unit: float, *, max_rows: int | None = None) -> ScallopRows:
    """Row levels across the box whose cusps, normal to the surface, are at most ``scallop_mm`` (see the module).

    Raises :class:`TooManyRows` before the walk when the rows surely exceed
    ``max_rows`` (a lower bound from the gaps the samples allow), or as soon
    as the walk passes it.
    """
    flat = scallop_stepover(radius_mm, scallop_mm)
    along, cross, stretch, k = _samples(ev, direction, mm_per_unit, flat, radius_mm)
    d = _allowed_d(k, radius_mm, scallop_mm)
    d = np.where(d < _TIGHT * flat, np.nan, d)
    k = np.where(np.isnan(d), np.nan, k)  # left out of the prediction too
    gap_mm = d * stretch
    tight = int(np.isnan(gap_mm).sum())
    per_sample = np.where(np.isnan(gap_mm), np.inf, gap_mm).min(axis=1) / mm_per_unit  # (cross,), surface units
    r = radius_mm / mm_per_unit
    floor = flat * _FLOOR / mm_per_unit
    finite = per_sample[np.isfinite(per_sample)]
    top = max(float(finite.max()) if finite.size else 0.0, flat / mm_per_unit)
    per_sample = np.where(np.isfinite(per_sample), per_sample, top)
    levels = _walk(cross, per_sample, r, floor, top, max_rows, scallop_mm=scallop_mm, mm_per_unit=mm_per_unit)
    levels = np.array(levels)
    worst, at = _worst(levels, along, cross, stretch, k, radius_mm=radius_mm, mm_per_unit=mm_per_unit)
    return ScallopRows(levels=levels, worst_mm=worst, worst_at=at, tight=tight, samples=k.size)


class TooManyRows(ToolpathError):
    """A scallop height asks for more rows than allowed: ``at_least`` rows, side steps down to ``smallest_mm``."""

    def __init__(self, at_least: int, smallest_mm: float, scallop_mm: float, max_rows: int):
        super().__init__(f"a scallop height of {scallop_mm:g} mm needs at least {at_least} rows (side steps down "
                         f"to {smallest_mm:.3g} mm), more than the {max_rows} allowed")
        self.at_least, self.smallest_mm = at_least, smallest_mm


def _walk(cross, per_sample, r: float, floor: float, top: float, max_rows: int | None, *, scallop_mm: float,
          mm_per_unit: float) -> list[float]:
    """The row levels walked across ``cross`` (see the module), refused past ``max_rows`` (:class:`TooManyRows`).

    Each gap ``s`` from a row at ``c`` is at most the smallest allowed over
    the samples in ``[c - r, c + s + r]`` (or the floor), so it is at most
    the smallest within ``r - spacing`` of any sample it passes: the sum of
    the spacing over that smallest is a lower bound of the gaps' count,
    known before the walk.
    """
    c0, c1 = float(cross[0]), float(cross[-1])
    if max_rows is not None and len(cross) > 1:
        spacing = (c1 - c0) / (len(cross) - 1)
        m = max(int((r - spacing) / spacing), 0)
        padded = np.pad(per_sample, m, constant_values=np.inf)
        near = np.lib.stride_tricks.sliding_window_view(padded, 2 * m + 1).min(axis=1)
        bound = np.maximum(near, floor)[:-1]
        at_least = int(math.floor(float(np.sum(spacing / bound)) * (1 - 1e-9))) + 1
        if at_least > max_rows:
            raise TooManyRows(at_least, float(bound.min()) * mm_per_unit, scallop_mm, max_rows)
    levels = [c0]
    while levels[-1] < c1:
        c = levels[-1]
        j0 = int(np.searchsorted(cross, c - r, side="left"))
        run = np.minimum.accumulate(per_sample[j0:])

        def allowed(s):  # the smallest gap allowed over the band the passes at c and c + s touch
            j = int(np.searchsorted(cross, c + s + r, side="right")) - 1 - j0
            return run[min(max(j, 0), len(run) - 1)]

        lo, hi = 0.0, top
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if mid <= allowed(mid) else (lo, mid)
        s = max(lo, floor)
        levels.append(min(c + s, c1) if c1 - (c + s) > 1e-9 * (c1 - c0) else c1)
        if max_rows is not None and len(levels) > max_rows:
            gaps = np.diff(levels) * mm_per_unit
            raise TooManyRows(len(levels), float(gaps.min()), scallop_mm, max_rows)
    return levels


def row_cusps(ev: SurfaceEvaluator, direction: str, levels, radius_mm: float, mm_per_unit: float,
              stepover_mm: float) -> ScallopRows:
    """The cusps predicted between rows at given ``levels`` (surface units, across the box), as for a scallop height.

    For a plan with a fixed side step: ``worst_mm`` and ``worst_at`` as
    :func:`scallop_levels` reports them, ``tight`` the samples in hollows
    tighter than the ball, which the prediction leaves out.
    """
    along, cross, stretch, k = _samples(ev, direction, mm_per_unit, stepover_mm, radius_mm)
    levels = np.asarray(levels, dtype=float)
    worst, at = _worst(levels, along, cross, stretch, k, radius_mm=radius_mm, mm_per_unit=mm_per_unit)
    return ScallopRows(levels=levels, worst_mm=worst, worst_at=at, tight=int(np.isnan(k).sum()), samples=k.size)


def gap_cusps(ev: SurfaceEvaluator, direction: str, levels, radius_mm: float, mm_per_unit: float,
              stepover_mm: float) -> tuple[np.ndarray, np.ndarray]:
    """The predicted cusp of each gap between ``levels`` at each sample along the rows: ``(along, cusps)``.

    ``cusps[g, i]`` (mm, normal to the surface) is the largest predicted over
    the band gap ``g`` touches (one tool radius before its first row to one
    past its second) at ``along[i]``; ``nan`` where every sample there is in a
    hollow tighter than the ball.
    """
    along, cross, stretch, k = _samples(ev, direction, mm_per_unit, stepover_mm, radius_mm)
    levels = np.asarray(levels, dtype=float)
    r = radius_mm / mm_per_unit
    out = np.full((max(len(levels) - 1, 0), len(along)), np.nan)
    for g, (c, nxt) in enumerate(zip(levels[:-1], levels[1:])):
        band = slice(int(np.searchsorted(cross, c - r)), int(np.searchsorted(cross, nxt + r, side="right")))
        h = cusp_height((nxt - c) * mm_per_unit / stretch[band], k[band], radius_mm)
        if h.size and np.isfinite(h).any():
            with np.errstate(invalid="ignore"):
                out[g] = np.nanmax(np.where(np.isfinite(h), h, -np.inf), axis=0)
    out[np.isneginf(out)] = np.nan
    return along, out


def _worst(levels, along, cross, stretch, k, *, radius_mm, mm_per_unit):
    """The largest cusp predicted between the rows at ``levels``, over each gap's band, and where.

    The cusp grows with the gap wherever it is defined, so a sample's worst is
    the one the widest gap whose band covers it leaves: one evaluation per
    sample, not one per gap and sample.  Where that gap leaves no defined cusp
    (a hollow the ball barely fits), the gaps covering the sample are tried
    one by one, as a smaller one may leave one.
    """
    r = radius_mm / mm_per_unit
    levels = np.asarray(levels, dtype=float)
    first = np.searchsorted(cross, levels[:-1] - r)
    last = np.searchsorted(cross, levels[1:] + r, side="right")
    widest = np.zeros(len(cross))
    for gap, a, b in zip(np.diff(levels), first, last):
        np.maximum(widest[a:b], gap, out=widest[a:b])
    h = cusp_height(widest[:, None] * mm_per_unit / stretch, k, radius_mm)
    for j in np.flatnonzero((np.isnan(h) & np.isfinite(k)).any(axis=1)):
        covering = np.diff(levels)[(first <= j) & (last > j)]
        with np.errstate(invalid="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # a sample no gap leaves a cusp at stays nan
            h[j] = np.nanmax(cusp_height(covering[:, None] * mm_per_unit / stretch[j], k[j], radius_mm), axis=0,
                             initial=-np.inf) if covering.size else np.nan
    h[np.isneginf(h)] = np.nan
    if not np.isfinite(h).any():
        return 0.0, (float(along[0]), float(cross[0]))
    jc, ja = np.unravel_index(int(np.nanargmax(h)), h.shape)
    worst = float(h[jc, ja])
    return (worst, (float(along[ja]), float(cross[jc]))) if worst > 0.0 else (0.0, (float(along[0]), float(cross[0])))
