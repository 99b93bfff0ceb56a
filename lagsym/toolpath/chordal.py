"""Chordal error: how far the true cutter path rises above the straight moves between cutter locations.

Between two cutter locations the control moves in a straight line, which cuts
below the true cutter path where the path bends down.  Each row is therefore
sampled more finely than it is emitted, and every move is lifted (both ends)
by how far the true path may rise above it:

* where the tool stays clear of the box edges across the move (an edge along
  the move cuts the same part off the tool all along it), the cutter path is
  *semi-convex*: it is the upper envelope of copies of the surface shifted
  under the tool, so it bends down no faster than the surface, ``K`` (the
  :meth:`~lagsym.evaluate.SurfaceEvaluator.curvature_bound`).  Between samples
  ``h`` apart it rises at most ``K h**2 / 8`` above their polyline, so the sag
  the samples show plus that bound is a bound of the move's sag
  (:func:`move_sags`).  (A quarter of the path's downward second difference
  at each sample, :func:`bends`, is taken too, when larger.)
* where the tool crosses a box edge across the move (:func:`crosses_box_edge`)
  and the samples show the path bending there (:func:`bent_moves`), it may
  start to rest on the edge or a corner between two samples and the path
  can bend down sharply (a square-root onset, or a bend a few hundredths of a
  millimetre wide); no such bound holds.  Each of these moves is checked
  against the true path (:func:`check_moves`): drop-cutter at evenly spaced
  interior points (at least six, at most a sixteenth of the tool radius apart
  or else 48), each taken with a quarter of the downward second difference
  of the samples there.  A move that dips more than the tolerance gets the
  cutter location at its worst point as a new point, and both halves are
  checked again, until every move is within the tolerance.  The move is then
  lifted by the dip found.

Emitted points thus lie on or above the exact drop-cutter value and at most the
chordal tolerance above it, and no move passes
below the true cutter path by more than what the checks may miss between their
samples (in the tests, never above ``1e-4`` mm, a tenth of a program's
resolution).

Heights and tolerances here are in mm; positions along a path are in mm, the
tool positions of a move in surface units.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ToolpathError
from ..evaluate import SurfaceEvaluator

__all__ = ["tolerance_step", "check_tolerance", "forward_steps", "bends", "semi_convex_sag", "move_sags", "move_rises",
           "crosses_box_edge", "bent_moves", "check_moves", "lift"]

_CHECK_SAMPLES = 6  # interior samples of a checked move, at least
_CHECK_SPLITS = 40  # at most this many rounds of splitting


def tolerance_step(ev: SurfaceEvaluator, tol: float, mm_per_unit: float) -> float:
    """A sampling step whose own chordal error on the surface is a quarter of ``tol`` (mm)."""
    kappa = ev.curvature_bound() / mm_per_unit  # 1/mm
    x0, x1, y0, y1 = ev.bounds
    longest = max(x1 - x0, y1 - y0) * mm_per_unit
    if kappa <= 0:
        return longest / 4
    return float(min(math.sqrt(2.0 * tol / kappa), longest / 4))


def bends(z: np.ndarray) -> np.ndarray:
    """A quarter of each sample's downward second difference: how far the path between samples may bend below them.

    For a parabola this is half the sag of a move over two samples that the
    middle sample shows; for the square-root onset where a ball starts to
    roll over a box edge it covers the part of the sag the samples miss.
    """
    out = np.zeros(len(z))
    if len(z) > 2:
        out[1:-1] = np.maximum(0.0, -(z[:-2] - 2.0 * z[1:-1] + z[2:])) / 4.0
    return out


def semi_convex_sag(s_mm: np.ndarray, kappa: float) -> np.ndarray:
    """At each sample, ``kappa h**2 / 8`` for the longer of its two steps ``h``: the sag a semi-convex path may hide there."""
    h = np.diff(s_mm)
    return kappa * np.maximum(np.concatenate([[0.0], h]), np.concatenate([h, [0.0]])) ** 2 / 8.0


def move_sags(t, z, keep, extra, kappa):
    """How far the cutter path may rise above each kept move (0 where the move lies above it).

    Returns the estimate and the sag the fine samples show alone.  The
    estimate is the larger of the sag the fine samples show plus their
    ``extra`` bend, and the largest sag they show plus ``kappa * h**2 / 8``,
    the bound of the sag between two samples ``h`` apart of a path that bends
    down no faster than ``kappa``.
    """
    keep = np.asarray(keep, dtype=int)
    if len(keep) < 2:
        return np.zeros(0), np.zeros(0)
    k, i, dev, starts = _deviations(t, z, keep)
    seen = np.maximum(np.maximum.reduceat(dev, starts), 0.0)
    inner = np.where(k == i, -np.inf, dev + extra[k])
    semi = kappa * np.maximum.reduceat(t[k + 1] - t[k], starts) ** 2 / 8.0
    sag = np.maximum(np.maximum(np.maximum.reduceat(inner, starts), 0.0), seen + semi)
    return sag, seen


def move_rises(t, z, keep):
    """How far each kept move lies above the fine samples it skips (0 where none lies below it).

    A move above the cutter path does not gouge but leaves that much
    material: in a hollow the ball barely fits, the path bends up fast and a
    fixed step would ride well above it.
    """
    keep = np.asarray(keep, dtype=int)
    if len(keep) < 2:
        return np.zeros(0)
    _, _, dev, starts = _deviations(t, z, keep)
    return np.maximum(np.maximum.reduceat(-dev, starts), 0.0)


def _deviations(t, z, keep):
    """Each fine sample from the first kept to the last against the move it lies in: ``(k, i, dev, starts)``.

    ``k`` the samples, ``i`` the start of each one's move, ``dev`` how far
    the sample lies above the move, ``starts`` where each move's samples
    begin in ``k`` (for ``reduceat``).
    """
    k = np.arange(keep[0], keep[-1])
    m = np.searchsorted(keep, k, side="right") - 1  # the move each fine sample starts or lies inside
    i, j = keep[m], keep[m + 1]
    span = t[j] - t[i]
    # Samples rounded onto one written position make a move straight up or down:
    # a sample there is measured from the nearest point of that vertical move.
    frac = np.divide(t[k] - t[i], span, out=np.zeros_like(span, dtype=float), where=span != 0)
    vertical = np.clip(z[k], np.minimum(z[i], z[j]), np.maximum(z[i], z[j]))
    dev = z[k] - np.where(span != 0, z[i] + frac * (z[j] - z[i]), vertical)
    return k, i, dev, keep[:-1] - keep[0]


def crosses_box_edge(vx, vy, bounds, radius):
    """Which moves between the points ``(vx, vy)`` bring the tool onto a box edge across the move.

    An end within the tool radius of an edge, and the move not along that
    edge: there the tool starts to rest on the edge or a corner and the
    cutter path can bend down sharply between samples.  (An edge along the
    move cuts the same part off the tool all along it, which leaves the path
    semi-convex.)
    """
    x0, x1, y0, y1 = bounds
    reach = radius * (1 + 1e-9)
    near_x = np.minimum(vx - x0, x1 - vx) < reach
    near_y = np.minimum(vy - y0, y1 - vy) < reach
    return (((near_x[:-1] | near_x[1:]) & (vx[:-1] != vx[1:]))
            | ((near_y[:-1] | near_y[1:]) & (vy[:-1] != vy[1:])))


BENT_MM = 1e-5
"""A quarter of a downward second difference of the fine samples above which the path counts as bent there."""


def bent_moves(keep: np.ndarray, bend: np.ndarray, threshold: float = BENT_MM) -> np.ndarray:
    """Which kept moves have a fine sample within one of them where the path bends down more than ``threshold``.

    ``bend`` is :func:`bends` of the fine samples.  A bend hidden between two
    samples shows in their second differences: where the path rises to a
    ridge between samples ``h`` apart with slopes ``s1`` and ``-s2``, the
    ridge stands at most ``(s1 + s2) h / 4`` above their chord, and the
    quarter second differences at the two samples add up to that; so a
    move with no bent sample near it has no such ridge above ``2 * threshold``.
    """
    b = np.asarray(bend, dtype=float)
    near = b.copy()
    near[1:] = np.maximum(near[1:], b[:-1])
    near[:-1] = np.maximum(near[:-1], b[1:])
    # Largest value over each move's fine samples, its ends and one beyond them included.
    top = np.maximum.reduceat(near, keep[:-1]) if len(keep) > 1 else np.zeros(0)
    return np.maximum(top, near[keep[1:]]) > threshold


def _move_dips(cl, move, length, radius):
    """How far the true cutter path may rise above each straight move ``a -> b``, where, and the path there.

    Samples the path at evenly spaced interior points (at least
    :data:`_CHECK_SAMPLES`, no further apart than a sixteenth of the tool
    radius unless that takes more than eight times as many).  At each sample
    the height above the move plus :func:`bends` of the samples (the move's
    ends included) bounds the path between it and its neighbours, as for the
    fine samples of a row (see :func:`bent_moves` for a ridge between two
    samples); the largest is the move's dip.  Returns the dip (0 or more,
    mm), the fraction along the move where it was found and the cutter
    location there (mm).  ``move`` is ``(ax, ay, az, bx, by, bz)``, the
    ends of the moves.
    """
    ax, ay, az, bx, by, bz = move
    m = len(ax)
    if m == 0:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    per_radius = np.ceil(np.minimum(length * 16.0 / max(radius, 1e-300), 8 * _CHECK_SAMPLES))
    n_move = np.maximum(_CHECK_SAMPLES, per_radius).astype(int)
    # Ragged samples as one flat vector: move of each sample and its fraction along the move.
    idx = np.repeat(np.arange(m), n_move)
    start = np.concatenate([[0], np.cumsum(n_move)[:-1]])
    u = (np.arange(idx.size) - start[idx] + 1) / (n_move[idx] + 1)
    zc = cl(ax[idx] + u * (bx[idx] - ax[idx]), ay[idx] + u * (by[idx] - ay[idx]))
    d = zc - (az[idx] + u * (bz[idx] - az[idx]))
    # Neighbours of each sample along its move; the ends of the move lie on it (0 above it).
    first, last = u == u[start][idx], np.zeros(idx.size, dtype=bool)
    last[np.cumsum(n_move) - 1] = True
    left = np.where(first, 0.0, np.roll(d, 1))
    right = np.where(last, 0.0, np.roll(d, -1))
    est = d + np.maximum(0.0, 2.0 * d - left - right) / 4.0
    order = np.lexsort((-est, idx))
    worst = order[start]  # the worst sample of each move
    # The zoom's first round reaches the worst sample's neighbours, a move's end where it is one: known already.
    lo, hi = np.maximum(worst - 1, 0), np.minimum(worst + 1, idx.size - 1)
    ends = (np.where(first[worst], az, zc[lo]), np.where(last[worst], bz, zc[hi]))
    du, dz, zw = _zoom(cl, move, u[worst], d[worst], zc[worst], 1.0 / (n_move + 1), ends=ends)
    return np.maximum(np.maximum(est[worst], dz), 0.0), du, zw


_ZOOM_SAMPLES, _ZOOM_ROUNDS = 6, 3


def _zoom(cl, move, u, d, z, half, *, ends=None):
    """The dip of each move searched closer around its worst sample ``u`` (fraction along it; ``half`` apart).

    A path that bends sharply next to a sample (where the tool starts to
    rest on a box edge) can rise above the move between two samples by more
    than their second differences show; :data:`_ZOOM_ROUNDS` rounds of
    :data:`_ZOOM_SAMPLES` samples, each over a third of the span before,
    find that peak.  ``ends``, where given, are the cutter locations at the
    first round's two outer samples, ``u - half`` and ``u + half`` (the
    samples either side, or the move's ends).  Returns the best fraction,
    the dip there and the cutter location there.
    """
    ax, ay, az, bx, by, bz = move
    t = np.linspace(-1.0, 1.0, _ZOOM_SAMPLES)
    for r in range(_ZOOM_ROUNDS):
        q = np.clip(u[:, None] + half[:, None] * t[None, :], 0.0, 1.0)
        known = r == 0 and ends is not None
        qn = q[:, 1:-1] if known else q
        zq = cl((ax[:, None] + qn * (bx - ax)[:, None]).ravel(), (ay[:, None] + qn * (by - ay)[:, None]).ravel())
        zq = np.asarray(zq).reshape(qn.shape)
        if known:
            zq = np.concatenate([ends[0][:, None], zq, ends[1][:, None]], axis=1)
        dq = zq - (az[:, None] + q * (bz - az)[:, None])
        k = np.argmax(dq, axis=1)
        rows = np.arange(len(u))
        better = dq[rows, k] > d
        u, d, z = np.where(better, q[rows, k], u), np.where(better, dq[rows, k], d), np.where(better, zq[rows, k], z)
        half = half / 3.0
    return u, d, z


def check_moves(cl, vx, vy, vz, vrow, sag, *, seen, dense, tol, radius):
    """Check the moves marked ``dense`` against the true cutter path; with a tolerance, split those that dip more.

    ``cl(x, y, **search)`` gives the cutter locations (mm) over surface
    positions, and ``cl.snap_between(x, y, ax, ay, bx, by)``, where it has
    one, the position a new point on the move ``a -> b`` is written at.  The sag of a checked move becomes the larger of the dip found
    and the sag its fine samples show (``seen``).  A move whose sag exceeds
    ``tol`` gets the cutter location at its worst point as a new point, and
    both halves are checked again.  Returns the points and each move's sag.
    """
    check = np.flatnonzero(dense)
    seen = seen[check]
    for _ in range(_CHECK_SPLITS + 1):
        a, b = check, check + 1
        length = np.hypot(vx[b] - vx[a], vy[b] - vy[a])
        d, u, zc = _move_dips(cl, (vx[a], vy[a], vz[a], vx[b], vy[b], vz[b]), length, radius)
        sag[check] = np.maximum(d, seen)
        if tol is None:
            break
        over = d > tol
        split = check[over]
        if not split.size:
            break
        w = u[over]
        nx = vx[split] + w * (vx[split + 1] - vx[split])
        ny = vy[split] + w * (vy[split + 1] - vy[split])
        if hasattr(cl, "snap_between"):  # a new point is written: on the program's resolution, along its move
            nx, ny = cl.snap_between(nx, ny, vx[split], vy[split], vx[split + 1], vy[split + 1])
        vx, vy = np.insert(vx, split + 1, nx), np.insert(vy, split + 1, ny)
        # Few points are added, so their cutter locations get a three times finer, more thorough search.
        vz = np.insert(vz, split + 1, cl(nx, ny, lattice=24, starts=8))
        vrow = np.insert(vrow, split + 1, vrow[split])
        sag = np.insert(sag, split + 1, 0.0)
        moved = split + np.arange(split.size)
        check = np.sort(np.concatenate([moved, moved + 1]))
        seen = np.zeros(check.size)
    return vx, vy, vz, vrow, sag


def lift(sag: np.ndarray) -> np.ndarray:
    """How far to raise each point: the larger sag of the moves on either side of it (both ends of a move rise)."""
    out = np.zeros(len(sag) + 1)
    if len(sag):
        out[:-1] = sag
        out[1:] = np.maximum(out[1:], sag)
    return out


def check_tolerance(tolerance_mm: float, program) -> None:
    """Refuse a chordal tolerance finer than the positions the program writes: it cannot be held there.

    Such a tolerance also asks for samples far closer than the written
    positions can tell apart (1e-6 mm planned for minutes before).
    """
    if tolerance_mm < program.resolution_mm:
        raise ToolpathError(f"a chordal tolerance of {tolerance_mm:g} mm is finer than the {program.resolution_mm:g} mm "
                            f"the program writes positions in (decimals {program.digits}), so it cannot be held: "
                            f"give a tolerance of at least {program.resolution_mm:g} mm, or more decimals (--decimals)")


def forward_steps(ev: SurfaceEvaluator, tolerance_mm: float, step_mm: float | None, mm_per_unit: float,
                  program) -> tuple[float, float]:
    """A raster's longest move (mm) and the finer sampling step the filter chooses points from (mm).

    The sampling step is one whose own chordal error on the surface is a
    quarter of the tolerance, and with a fixed step at most half of it.  A
    program (:class:`~lagsym.machine.ProgramFormat`) that writes positions
    as far apart as the sampling step or further is refused: its samples would fall
    on one another, and so is a tolerance finer than the positions it writes.
    """
    fine = tolerance_step(ev, tolerance_mm, mm_per_unit)
    step, fine = (fine, fine) if step_mm is None else (step_mm, min(step_mm / 2.0, fine))
    if program.resolution_mm >= fine:  # samples one resolution apart can round onto one position
        raise ToolpathError(f"decimals {program.digits} write positions {program.resolution_mm:g} mm apart, not finer "
                            f"than the sampling step of {fine:.3g} mm: give more decimals (--decimals), or a "
                            f"larger --step and --tolerance")
    check_tolerance(tolerance_mm, program)
    return step, fine
