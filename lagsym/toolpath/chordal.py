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
* where the tool crosses a box edge across the move (:func:`crosses_box_edge`),
  it starts to rest on the edge or a corner between two samples and the path
  can bend down sharply (a square-root onset, or a bend a few hundredths of a
  millimetre wide); no such bound holds.  Each of these moves is checked
  against the true path (:func:`check_moves`): drop-cutter at evenly spaced
  interior points (at least six, at most a sixteenth of the tool radius apart
  or else 48), then three rounds of denser samples around the worst one.
  With a tolerance, a move that dips more than the tolerance gets the cutter
  location at its worst point as a new point, and both halves are checked
  again, until every move is within the tolerance.  The move is then lifted
  by the dip found.

Emitted points thus lie on or above the exact drop-cutter value and at most the
chordal error (the tolerance, when one is given) above it, and no move passes
below the true cutter path by more than what the checks may miss between their
samples (in the tests, never above ``1e-4`` mm, a tenth of a program's
resolution).

Heights and tolerances here are in mm; positions along a path are in mm, the
tool positions of a move in surface units.
"""

from __future__ import annotations

import math

import numpy as np

from ..evaluate import SurfaceEvaluator

__all__ = ["tolerance_step", "bends", "semi_convex_sag", "move_sags", "crosses_box_edge", "check_moves", "lift"]

_CHECK_SAMPLES = 6  # interior samples of a checked move, at least
_CHECK_ZOOM = 6  # rounds of local refinement around the worst sample
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
    sag = np.zeros(len(keep) - 1)
    seen = np.zeros(len(keep) - 1)
    for m, (i, j) in enumerate(zip(keep[:-1], keep[1:])):
        s = (t[i:j + 1] - t[i]) / (t[j] - t[i])
        dev = z[i:j + 1] - (z[i] + s * (z[j] - z[i]))
        seen[m] = max(0.0, float(dev.max()))
        semi = kappa * float(np.diff(t[i:j + 1]).max()) ** 2 / 8.0
        sag[m] = max(float(np.max(dev[1:-1] + extra[i + 1:j], initial=0.0)), seen[m] + semi)
    return sag, seen


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


def _move_dips(cl, ax, ay, az, bx, by, bz, length, radius):
    """Largest height of the true cutter path above each straight move ``a -> b``, where, and the path there.

    Samples the path at evenly spaced interior points (at least
    :data:`_CHECK_SAMPLES`, no further apart than a sixteenth of the tool
    radius unless that takes more than eight times as many), then, where the
    path rises above the move, zooms in around the worst sample.  Returns the
    dip (0 or more, mm), the fraction along the move where it was found and
    the cutter location there (mm).
    """
    m = len(ax)
    if m == 0:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    per_radius = np.ceil(np.minimum(length * 16.0 / max(radius, 1e-300), 8 * _CHECK_SAMPLES))
    n_move = np.maximum(_CHECK_SAMPLES, per_radius).astype(int)
    # Ragged samples as one flat vector: move of each sample and its fraction along the move.
    idx = np.repeat(np.arange(m), n_move)
    start = np.concatenate([[0], np.cumsum(n_move)[:-1]])
    u = (np.arange(idx.size) - start[idx] + 1) / (n_move[idx] + 1)

    def dips(idx, u):
        zc = cl(ax[idx] + u * (bx[idx] - ax[idx]), ay[idx] + u * (by[idx] - ay[idx]))
        return zc - (az[idx] + u * (bz[idx] - az[idx])), zc

    d, zc = dips(idx, u)
    order = np.lexsort((-d, idx))
    first = order[start]  # the worst sample of each move
    best_d, best_u, best_z = d[first], u[first], zc[first]
    # Zoom in where the path rises above the move; elsewhere the samples show it below all along.
    zoom = np.flatnonzero(best_d > 0.0)
    width = 1.0 / (n_move[zoom] + 1)
    offs = np.array([-2.0, -1.0, 1.0, 2.0]) / 3.0
    for _ in range(_CHECK_ZOOM):
        uu = np.clip(best_u[zoom, None] + width[:, None] * offs, 0.0, 1.0)
        d, zc = dips(np.repeat(zoom, len(offs)), uu.ravel())
        d, zc = d.reshape(uu.shape), zc.reshape(uu.shape)
        j = np.argmax(d, axis=1)
        r = np.arange(zoom.size)
        better = d[r, j] > best_d[zoom]
        k = zoom[better]
        best_d[k], best_u[k], best_z[k] = d[r, j][better], uu[r, j][better], zc[r, j][better]
        width = width / 3.0
    return np.maximum(best_d, 0.0), best_u, best_z


def check_moves(cl, vx, vy, vz, vrow, sag, seen, dense, tol, radius):
    """Check the moves marked ``dense`` against the true cutter path; with a tolerance, split those that dip more.

    ``cl(x, y, **search)`` gives the cutter locations (mm) over surface
    positions.  The sag of a checked move becomes the larger of the dip found
    and the sag its fine samples show (``seen``).  A move whose sag exceeds
    ``tol`` gets the cutter location at its worst point as a new point, and
    both halves are checked again.  Returns the points and each move's sag.
    """
    check = np.flatnonzero(dense)
    seen = seen[check]
    for _ in range(_CHECK_SPLITS + 1):
        a, b = check, check + 1
        length = np.hypot(vx[b] - vx[a], vy[b] - vy[a])
        d, u, zc = _move_dips(cl, vx[a], vy[a], vz[a], vx[b], vy[b], vz[b], length, radius)
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
