"""Arc fitting: runs of cutter locations along a row replaced by G18/G19 circular moves within the tolerance.

A raster row lies in a vertical plane (rows along X in the XZ plane, along Y
in the YZ plane), so an arc there is a circle in that plane.  Along a row,
:func:`fit_arcs` replaces as many consecutive moves as it can by one arc
from a written point to a written point, greedily as the line filter does,
and keeps the straight moves where no arc fits.  An arc is kept only when,
with its centre on the program's resolution as it will be written, it
passes two checks against the cutter-location heights ``CL`` of the row
(the fine drop-cutter samples the plan chose its points from, and the
points' own exact values):

* **never below the cutter path.**  A control moves from the start to the
  end at a radius between the start's and the end's distance from the
  centre (they differ by a unit or so once the centre is rounded; LinuxCNC
  and Grbl interpolate between them), so the tool lies between the two
  circles of those radii.  Let ``d = CL - low`` with ``low`` the lower of
  the two circles.  Where the tool stays clear of the box edges across the
  row, the cutter path bends down no faster than ``K`` (the surface's largest
  second derivative, as for the line moves, see :mod:`.chordal`), and a
  circle bulging up bends down, so ``d'' >= -K``; a circle hollow upward of
  radius ``r`` with its lowest tip at most ``v`` below the centre bends up by
  at most ``r**2 / v**3``, so ``d'' >= -(K + r**2 / v**3)``.  With ``d`` at
  two neighbouring samples ``-m0`` and ``-m1`` and ``d'' >= -c`` between them
  (``h`` apart), ``d <= -(1-u) m0 - u m1 + c h**2 u (1-u) / 2``; the arc is
  kept only when that maximum is 0 or less over every pair of samples, so
  the arc never passes below the cutter path.
* **at most the tolerance above it.**  The higher circle is at most the
  tolerance above ``CL`` at every interior sample (as the line filter keeps
  its skipped samples within the tolerance).

Moves where the tool crosses a box edge across the row are never replaced
(there the path is not semi-convex, see :mod:`.chordal`), and neither are
the links between rows or the rounded rows beyond a box corner.  The start
and end radii must agree within :data:`RADIUS_AGREE` of what LinuxCNC
accepts (0.002 mm in a millimetre program, 0.0002 inch in an inch one);
radii are at most :data:`MAX_RADIUS_MM`, so centres stay within any
control's axis words, and no arc turns more steeply than
:data:`MIN_COS` from the horizontal.

Grbl does not move on the circle: it cuts an arc into chords no further
than its arc tolerance (``$12``, 0.002 mm by default) inside it, and ends on
a chord from the start radius's circle to the end.  For Grbl
(:attr:`lagsym.controls.Control.chord_mm`) a circle bulging up is checked that much lower and one
hollow upward that much higher; a ``$12`` above the default voids the
guarantee.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import freeze_fields
from ..gcode.numbers import program_ints

__all__ = ["Arcs", "fit_arcs", "RADIUS_LIMIT", "MAX_RADIUS_MM"]

RADIUS_LIMIT = {"mm": 0.002, "inch": 0.0002}  # LinuxCNC: start and end radius may differ by this (program units)
RADIUS_AGREE = 0.75  # the part of that limit a written arc may use
MAX_RADIUS_MM = 1000.0
MIN_COS = 0.1  # both ends at least this part of the radius above (or below) the centre: tangents within 84 degrees


@dataclass(frozen=True)
class Arcs:
    """Circular moves replacing runs of a toolpath's points.

    Attributes
    ----------
    start, end : ndarray of int, shape (M,)
        The first and last point of each arc (indices into the toolpath's
        points); the points between are not written.
    centre_mm : ndarray, shape (M, 2)
        The centre in the plane of the row, ``(along, Z)`` in machine mm
        (``along`` is X for ``G18``, Y for ``G19``), on the program's
        resolution.
    ccw : ndarray of bool, shape (M,)
        True for ``G03`` (counter-clockwise seen from the positive end of the
        plane's normal, +Y for ``G18``, +X for ``G19``), False for ``G02``.
    plane : str
        ``"G18"`` (rows along X) or ``"G19"`` (rows along Y).
    """

    start: np.ndarray
    end: np.ndarray
    centre_mm: np.ndarray
    ccw: np.ndarray
    plane: str

    def __post_init__(self):
        freeze_fields(self, ("start", "end", "centre_mm", "ccw"))

    def __len__(self) -> int:
        return len(self.start)

    def blocks_saved(self) -> int:
        """How many fewer feed blocks the program has with the arcs: each replaces its moves by one."""
        return int(np.sum(self.end - self.start - 1))


@dataclass(frozen=True)
class _Row:
    """One run of points along a row, in a frame where the along coordinate grows: positions and heights in mm."""

    a: np.ndarray  # along (mm, flipped so it grows), written
    z: np.ndarray  # written heights (mm)
    s_a: np.ndarray  # cutter-location samples: along (mm, same frame), sorted
    s_z: np.ndarray  # and their heights (mm)


@dataclass(frozen=True)
class _Bounds:
    """What every arc of one toolpath is checked against; travels together through the fit and its checks."""

    kappa: float  # how fast the cutter path bends down at most (1/mm)
    tol: float  # the chordal tolerance (mm)
    unit_mm: float  # one unit of the program's last decimal (mm)
    limit_mm: float  # how far the start and end radius of a written arc may differ (mm)
    chord_mm: float  # how far inside its arcs the control's chords may lie (mm)


@dataclass(frozen=True)
class _Chord:
    """The chord from an arc's start to its end: its ends ``(along, z)``, length, middle and upward unit normal."""

    start: np.ndarray
    end: np.ndarray
    length: float
    mid: np.ndarray
    normal: np.ndarray


def fit_arcs(points_mm, rows, exact_mm, fine_mm, *, direction: str, kappa: float, tol: float, unit_factor: float,
             digits: int, units: str, reach_mm: tuple[float, float], radius_mm: float, chord_mm: float = 0.0) -> Arcs:
    """The arcs that replace moves of the toolpath ``points_mm`` (see the module docstring).

    Parameters
    ----------
    points_mm, rows, exact_mm
        The toolpath's points (machine mm), rows and exact cutter-location heights.
    fine_mm : ndarray, shape (M, 3)
        The fine drop-cutter samples of the rows (machine mm), on the program's resolution.
    direction : str
        ``"x"`` or ``"y"``.
    kappa : float
        The bound of how fast the cutter path bends down (1/mm), as for the line moves.
    tol : float
        The chordal tolerance (mm).
    unit_factor, digits, units
        Program units per mm, decimals and ``"mm"`` or ``"inch"``.
    reach_mm : tuple of float
        The box's extent along the rows (machine mm): an arc stays a tool
        radius ``radius_mm`` inside it.
    chord_mm : float
        How far inside its arcs the control's chords may lie (:attr:`lagsym.controls.Control.chord_mm`), mm.
    """
    ax, cx = (0, 1) if direction == "x" else (1, 0)
    unit_mm = 10.0 ** -digits / unit_factor
    ints = program_ints(points_mm, unit_factor, digits)
    fine_ints = program_ints(fine_mm, unit_factor, digits)
    lo, hi = reach_mm[0] + radius_mm, reach_mm[1] - radius_mm
    safe = (ints[:, ax] * unit_mm >= lo) & (ints[:, ax] * unit_mm <= hi)
    order = np.lexsort((fine_ints[:, ax], fine_ints[:, cx]))
    f_cross = fine_ints[order, cx]
    bounds = _Bounds(kappa, tol, unit_mm, RADIUS_AGREE * RADIUS_LIMIT[units] / unit_factor, chord_mm)
    out = []
    n = len(ints)
    same = np.zeros(n, dtype=bool)
    same[1:] = (ints[1:, cx] == ints[:-1, cx]) & (rows[1:] == rows[:-1]) & safe[1:] & safe[:-1] \
        & (ints[1:, ax] != ints[:-1, ax])
    breaks = np.flatnonzero(~same)
    for b0, b1 in zip(breaks, np.append(breaks[1:], n)):
        if b1 - b0 < 3:
            continue
        sign = 1 if ints[b1 - 1, ax] > ints[b0, ax] else -1
        k0, k1 = np.searchsorted(f_cross, ints[b0, cx]), np.searchsorted(f_cross, ints[b0, cx], side="right")
        sel = order[k0:k1]
        sa = np.concatenate([fine_ints[sel, ax] * unit_mm, ints[b0:b1, ax] * unit_mm]) * sign
        sz = np.concatenate([fine_mm[sel, 2], exact_mm[b0:b1]])
        a = ints[b0:b1, ax] * unit_mm * sign
        inside = (sa >= a[0]) & (sa <= a[-1])
        k = np.argsort(sa[inside], kind="stable")
        row = _Row(a, ints[b0:b1, 2] * unit_mm, sa[inside][k], sz[inside][k])
        for i, j, centre in _greedy(row, bounds):
            ca = centre[0] * sign
            s3, e3 = points_mm[b0 + i], points_mm[b0 + j]
            v1 = np.array([s3[ax] - ca, s3[2] - centre[1]])
            v2 = np.array([e3[ax] - s3[ax], e3[2] - s3[2]])
            turn = v1[0] * v2[1] - v1[1] * v2[0]  # positive: from the along axis towards Z
            # About +Y (G18) a positive turn takes Z to X; about +X (G19) it takes Y to Z.
            out.append((b0 + i, b0 + j, ca, centre[1], bool(turn < 0) if ax == 0 else bool(turn > 0)))
    arr = np.array(out, dtype=float).reshape(-1, 5)
    return Arcs(start=arr[:, 0].astype(int), end=arr[:, 1].astype(int), centre_mm=arr[:, 2:4],
                ccw=arr[:, 4].astype(bool), plane="G18" if ax == 0 else "G19")


def _greedy(row: _Row, bounds: _Bounds):
    """``(i, j, centre)`` of the arcs along one run, from each point as far as an arc fits."""
    n, i = len(row.a), 0
    while i < n - 2:
        good, bad, step = None, None, 2
        while True:  # the reach doubled while an arc fits, then bisected back
            hi = min(i + step, n - 1)
            c = _fit(row, i, hi, bounds)
            if c is None:
                bad = hi
                break
            good = (hi, c)
            if hi == n - 1:
                break
            step *= 2
        if good is None:
            i += 1
            continue
        while bad is not None and bad - good[0] > 1:
            mid = (good[0] + bad) // 2
            c = _fit(row, i, mid, bounds)
            if c is None:
                bad = mid
            else:
                good = (mid, c)
        yield i, good[0], good[1]
        i = good[0]


def _samples(row: _Row, i: int, j: int):
    """The cutter-location samples from point ``i`` to point ``j``, ends included (along, height)."""
    k0 = np.searchsorted(row.s_a, row.a[i], side="left")
    k1 = np.searchsorted(row.s_a, row.a[j], side="right")
    return row.s_a[k0:k1], row.s_z[k0:k1]


def _fit(row: _Row, i: int, j: int, bounds: _Bounds):
    """The rounded centre ``(along, z)`` (mm) of an arc from point ``i`` to ``j`` that passes both checks, or None.

    The arcs through both ends form a family ordered by their sagitta (the
    height of the arc's middle above the chord): each sample asks for a
    sagitta above the one of the circle through the ends and a point the
    margin above it, and below the one through a point the tolerance above
    it.  The middle of what is left is tried, its centre rounded, and the
    rounded arc (or one a unit beside it) checked in full (:func:`_check`).
    """
    kappa, tol, chord_mm = bounds.kappa, bounds.tol, bounds.chord_mm
    sa, sz = _samples(row, i, j)
    S, E = np.array([row.a[i], row.z[i]]), np.array([row.a[j], row.z[j]])
    chord = E - S
    L = float(np.hypot(*chord))
    normal = np.array([-chord[1], chord[0]]) / L  # the upward side of the chord (the along axis grows)
    mid = (S + E) / 2
    line = _Chord(S, E, L, mid, normal)
    inner = (sa > S[0]) & (sa < E[0])
    if not inner.any():
        return None
    smin = MAX_RADIUS_MM - np.sqrt(MAX_RADIUS_MM**2 - L * L / 4)
    h = np.diff(sa)
    gap = np.maximum(np.concatenate([[0.0], h]), np.concatenate([h, [0.0]]))[inner]
    a, cl = sa[inner], sz[inner]
    first, last = int(np.flatnonzero(inner)[0]), int(np.flatnonzero(inner)[-1])
    m_ends = (S[1] - chord_mm - sz[first - 1], E[1] - chord_mm - sz[last + 1])
    hi = _sagittas(a, cl + tol, line).min()
    bend, s = 0.0, None
    for _ in range(2):  # once for a dome, again with a hollow's own bend
        c = kappa + bend
        need = c * gap**2 / 8
        for k, h_end, m in ((0, sa[first] - sa[first - 1], m_ends[0]), (-1, sa[last + 1] - sa[last], m_ends[1])):
            q = c * h_end**2 / 2
            need[k] = max(need[k], (np.sqrt(q) - np.sqrt(max(m, 0.0))) ** 2 if m < q else 0.0)
        lo = _sagittas(a, cl + need + chord_mm, line).max()
        if lo > hi:
            return None
        s = 0.5 * (lo + hi)
        if abs(s) < smin:  # the range holds the chord: the flattest arc on the wider side
            s = smin * (1 + 1e-6) * (1.0 if hi > -lo else -1.0)
        if s > 0:
            break
        r = (L * L / 4 + s * s) / (2 * abs(s))
        cz = (mid + normal * (s + r))[1]
        v = cz - max(S[1], E[1])
        if v < MIN_COS * r:
            return None
        bend = r * r / v**3
    if abs(s) > 0.45 * L:
        return None
    r = (L * L / 4 + s * s) / (2 * abs(s))
    centre = mid + normal * (s - np.sign(s) * r)
    base = np.rint(centre / bounds.unit_mm)
    for step in ((0, 0), (0, -1), (0, 1), (-1, 0), (1, 0), (-1, -1), (1, 1), (-1, 1), (1, -1)):
        c = (base + step) * bounds.unit_mm
        if _check(c, line, sa, sz, bounds):
            return c
    return None


def _sagittas(a, z, line: _Chord):
    """The signed sagitta of the circle through the chord's ends and each point ``(a, z)`` (positive: bulging up)."""
    L, mid, normal = line.length, line.mid, line.normal
    d = np.stack([a - mid[0], z - mid[1]], axis=1)
    tangent = np.array([normal[1], -normal[0]])
    u, w = d @ tangent, d @ normal
    aw = np.maximum(np.abs(w), 1e-300)
    e = (L * L / 4 - u * u - w * w) / (2 * aw)
    root = np.sqrt(e * e + L * L / 4)
    mag = np.where(e >= 0, (L * L / 4) / (e + root), root - e)
    return np.where(w == 0, 0.0, np.sign(w) * mag)


def _heights(centre_a, centre_z, radius, dome, a):
    """Heights of circles (rows) at abscissae ``a``: the upper half for a dome, the lower one otherwise."""
    root = np.sqrt(np.maximum(radius**2 - (a - centre_a) ** 2, 0.0))
    return np.where(dome, centre_z + root, centre_z - root)


def _passes(low, high, sa, sz, bounds: _Bounds, bend):
    """Both checks of a circle's heights: ``low`` never below the path, ``high`` within ``tol`` above it.

    ``low - sz`` at two neighbouring samples is ``m0`` and ``m1``; with the
    path less the circle bending down no faster than ``c = bounds.kappa + bend``,
    the path rises above the circle between them by at most the largest of
    ``-(1-u) m0 - u m1 + c h**2 u (1-u) / 2`` (``h`` apart), which must be 0
    or less.
    """
    m = low - sz
    q = (bounds.kappa + bend) * np.diff(sa) ** 2 / 2.0
    m0, m1 = m[:-1], m[1:]
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.clip(np.where(q > 0, (m0 - m1 + q) / (2 * q), 0.0), 0.0, 1.0)
    if np.any(m < 0.0) or np.any(-(1 - u) * m0 - u * m1 + q * u * (1 - u) > 0.0):
        return False
    inner = (sa > sa[0]) & (sa < sa[-1])  # the ends are written points, kept as the line moves keep them
    return bool(np.all(high[inner] - sz[inner] <= bounds.tol))


def _check(c, line: _Chord, sa, sz, bounds: _Bounds):
    """Whether the rounded arc about ``c`` along the chord ``line`` passes both checks."""
    S, E, limit_mm, chord_mm = line.start, line.end, bounds.limit_mm, bounds.chord_mm
    rs, re = float(np.hypot(*(S - c))), float(np.hypot(*(E - c)))
    if abs(rs - re) > limit_mm or max(rs, re) > MAX_RADIUS_MM:
        return False
    dome = S[1] > c[1] and E[1] > c[1]
    if not dome and not (S[1] < c[1] and E[1] < c[1]):
        return False
    r_lo, r_hi = min(rs, re), max(rs, re)
    if np.any(np.abs(sa - c[0]) >= r_lo):
        return False
    low = _heights(c[0], c[1], r_lo if dome else r_hi, dome, sa) - (chord_mm if dome else 0.0)
    high = _heights(c[0], c[1], r_hi if dome else r_lo, dome, sa) + (0.0 if dome else chord_mm)
    v = (min(S[1], E[1]) - c[1]) if dome else (c[1] - max(S[1], E[1]))
    v -= r_hi - r_lo
    if v < MIN_COS * r_hi:
        return False
    return _passes(low, high, sa, sz, bounds, 0.0 if dome else r_hi * r_hi / v**3)
