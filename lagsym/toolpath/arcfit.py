"""One arc's fit and checks (see :mod:`.arcs`), for many arcs at once: the runs of a toolpath are fitted side by side.

The greedy search along a run is sequential (each arc starts where the last
ended), but the runs are independent, so :mod:`.arcs` asks here for one
candidate arc of every run at a time.  The candidates' samples are slices
of the runs' sample arrays laid end to end (:class:`Runs`); every least, greatest
or any over a candidate's samples is a ``reduceat`` over its slice.  Each candidate gets
exactly the arithmetic a fit of it alone would, element by element.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Runs", "Bounds", "fit", "MAX_RADIUS_MM", "MIN_COS"]

MAX_RADIUS_MM = 1000.0
MIN_COS = 0.1  # both ends at least this part of the radius above (or below) the centre: tangents within 84 degrees
_STEPS = ((0, 0), (0, -1), (0, 1), (-1, 0), (1, 0), (-1, -1), (1, 1), (-1, 1), (1, -1))  # the rounded centres tried


@dataclass(frozen=True)
class Bounds:
    """What every arc of one toolpath is checked against; travels together through the fit and its checks."""

    kappa: float  # how fast the cutter path bends down at most (1/mm)
    tol: float  # the chordal tolerance (mm)
    unit_mm: float  # one unit of the program's last decimal (mm)
    limit_mm: float  # how far the start and end radius of a written arc may differ (mm)
    chord_mm: float  # how far inside its arcs the control's chords may lie (mm)


@dataclass(frozen=True)
class Runs:
    """The runs of points along rows, end to end, each in a frame where the along coordinate grows (mm).

    ``a``, ``z`` are the written points; ``sa``, ``sz`` the cutter-location
    samples of each run between its first and last point (the points' own
    along values among them), sorted within the run.  ``left[p]`` and
    ``right[p]`` bound the samples at point ``p``'s along value (the first
    sample not below it, the first above it); ``gap[t]`` is the larger of the
    spacings either side of sample ``t``.
    """

    a: np.ndarray
    z: np.ndarray
    sa: np.ndarray
    sz: np.ndarray
    left: np.ndarray
    right: np.ndarray
    gap: np.ndarray

    @classmethod
    def of(cls, runs) -> Runs:
        """From ``(a, z, sa, sz)`` of each run."""
        a, z, sa, sz, left, right = [], [], [], [], [], []
        base = 0
        for ra, rz, rsa, rsz in runs:
            a.append(ra), z.append(rz), sa.append(rsa), sz.append(rsz)
            left.append(base + np.searchsorted(rsa, ra, side="left"))
            right.append(base + np.searchsorted(rsa, ra, side="right"))
            base += len(rsa)
        cat = [np.concatenate(v) if v else np.zeros(0) for v in (a, z, sa, sz, left, right)]
        h = np.diff(cat[2])
        gap = np.maximum(np.concatenate([[0.0], h]), np.concatenate([h, [0.0]]))  # used only inside a run
        return cls(*cat[:4], cat[4].astype(np.int64), cat[5].astype(np.int64), gap)


@dataclass(frozen=True)
class _Line:
    """The chords of the candidates: ends, length, middle and upward unit normal, one row per candidate."""

    s: np.ndarray  # (Q, 2) start (along, z)
    e: np.ndarray  # (Q, 2) end
    length: np.ndarray
    mid: np.ndarray
    normal: np.ndarray

    def take(self, k) -> _Line:
        return _Line(self.s[k], self.e[k], self.length[k], self.mid[k], self.normal[k])


def _spans(start, stop):
    """The indices of the slices ``[start, stop)`` end to end, which slice each belongs to, and where each begins."""
    n = stop - start
    begin = np.cumsum(n) - n
    owner = np.repeat(np.arange(len(n)), n)
    return start[owner] + np.arange(int(n.sum())) - begin[owner], owner, begin


def fit(runs: Runs, i, j, bounds: Bounds):
    """The rounded centres ``(along, z)`` (mm) of the arcs from point ``i[q]`` to ``j[q]`` and which passed.

    For one candidate this is the fit of :mod:`.arcs`: the arcs through both
    ends form a family ordered by their sagitta; each sample asks for a
    sagitta above the one of the circle through the ends and a point the
    margin above it, and below the one through a point the tolerance above
    it.  The middle of what is left is tried, its centre rounded, and the
    rounded arc (or one a unit beside it) checked in full (:func:`_check`).
    Returns ``(ok, centre)``, a bool array and a ``(Q, 2)`` array.
    """
    q_all = len(i)
    ok, out = np.zeros(q_all, dtype=bool), np.zeros((q_all, 2))
    first, last = runs.right[i], runs.left[j] - 1  # the samples strictly between the ends
    live = np.flatnonzero(last >= first)
    if not len(live):
        return ok, out
    i, j, first, last = i[live], j[live], first[live], last[live]
    s = np.stack([runs.a[i], runs.z[i]], axis=1)
    e = np.stack([runs.a[j], runs.z[j]], axis=1)
    chord = e - s
    length = np.hypot(chord[:, 0], chord[:, 1])
    normal = np.stack([-chord[:, 1], chord[:, 0]], axis=1) / length[:, None]
    line = _Line(s, e, length, (s + e) / 2, normal)
    centre, good = _centres(runs, line, first, last, bounds)
    live, line, centre = live[good], line.take(good), centre[good]
    start, stop = runs.left[i[good]], runs.right[j[good]]
    base = np.rint(centre / bounds.unit_mm)
    todo = np.arange(len(live))
    for step in _STEPS:
        if not len(todo):
            break
        c = (base[todo] + step) * bounds.unit_mm
        passed = _check(runs, c, line.take(todo), start[todo], stop[todo], bounds)
        ok[live[todo[passed]]] = True
        out[live[todo[passed]]] = c[passed]
        todo = todo[~passed]
    return ok, out


def _centres(runs: Runs, line: _Line, first, last, bounds: Bounds):
    """The unrounded centres of the middle arcs the samples allow, and which candidates have one.

    Every candidate is tried as a dome first; one whose middle arc turns out
    hollow is tried again with the hollow's own bend (``r**2 / v**3``).
    """
    q = len(first)
    smp = _Inner.of(runs, first, last)
    s, e, length = line.s, line.e, line.length
    ends = _Ends(np.stack([runs.sa[first] - runs.sa[first - 1], runs.sa[last + 1] - runs.sa[last]], axis=1),
                 np.stack([s[:, 1] - bounds.chord_mm - runs.sz[first - 1],
                           e[:, 1] - bounds.chord_mm - runs.sz[last + 1]], axis=1),
                 MAX_RADIUS_MM - np.sqrt(MAX_RADIUS_MM**2 - length * length / 4),
                 np.minimum.reduceat(_sagittas(smp.a, smp.cl + bounds.tol, line, smp.owner), smp.begin))
    good, sag = np.zeros(q, dtype=bool), np.zeros(q)
    cand, c = np.arange(q), np.full(q, bounds.kappa)
    for _ in range(2):  # once for a dome, again with a hollow's own bend
        st, ok, bend = _round(smp, line.take(cand), ends.take(cand), c, bounds)
        sag[cand], good[cand] = st, ok
        again = ok & (st <= 0)
        if not again.any():
            break
        smp, cand, c = smp.take(again), cand[again], bounds.kappa + bend[again]
    good &= ~(np.abs(sag) > 0.45 * length)
    with np.errstate(invalid="ignore", divide="ignore"):
        r = (length * length / 4 + sag * sag) / (2 * np.abs(sag))
    return line.mid + line.normal * (sag - np.sign(sag) * r)[:, None], good


@dataclass(frozen=True)
class _Ends:
    """Per candidate: the spacings and margins at its two ends, the flattest sagitta allowed and the highest one."""

    h: np.ndarray  # (Q, 2) the spacing from each end's point to the sample next to it
    m: np.ndarray  # (Q, 2) how far each end's point lies above that sample's height, less the chords
    smin: np.ndarray  # the sagitta of the largest radius
    hi: np.ndarray  # the highest sagitta the tolerance allows

    def take(self, k) -> _Ends:
        return _Ends(self.h[k], self.m[k], self.smin[k], self.hi[k])


@dataclass(frozen=True)
class _Inner:
    """The samples strictly between each candidate's ends, end to end: which candidate owns each, where each begins."""

    a: np.ndarray
    cl: np.ndarray
    gap: np.ndarray
    owner: np.ndarray
    begin: np.ndarray
    last: np.ndarray

    @classmethod
    def of(cls, runs: Runs, first, last) -> _Inner:
        idx, owner, begin = _spans(first, last + 1)
        return cls(runs.sa[idx], runs.sz[idx], runs.gap[idx], owner, begin, begin + (last - first))

    def take(self, keep) -> _Inner:
        """The samples of the candidates ``keep`` (a mask over them) only, renumbered."""
        flat = keep[self.owner]
        owner = (np.cumsum(keep) - 1)[self.owner[flat]]
        counts = np.bincount(owner, minlength=int(keep.sum()))
        begin = np.cumsum(counts) - counts
        return _Inner(self.a[flat], self.cl[flat], self.gap[flat], owner, begin, begin + counts - 1)


def _round(smp: _Inner, line: _Line, ends: _Ends, c, bounds: Bounds):
    """One round of the fit with the bends ``c``: the middle sagitta, whether it stands, and a hollow's own bend."""
    need = c[smp.owner] * smp.gap**2 / 8
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for k, side in ((smp.begin, 0), (smp.last, 1)):
            q, m = c * ends.h[:, side] ** 2 / 2, ends.m[:, side]
            fix = np.where(m < q, (np.sqrt(q) - np.sqrt(np.maximum(m, 0.0))) ** 2, 0.0)
            need[k] = np.maximum(need[k], fix)
        lo = np.maximum.reduceat(_sagittas(smp.a, smp.cl + need + bounds.chord_mm, line, smp.owner), smp.begin)
        hi, smin = ends.hi, ends.smin
        s = 0.5 * (lo + hi)
        # the range holds the chord: the flattest arc on the wider side
        s = np.where(np.abs(s) < smin, smin * (1 + 1e-6) * np.where(hi > -lo, 1.0, -1.0), s)
        r = (line.length * line.length / 4 + s * s) / (2 * np.abs(s))
        cz = (line.mid + line.normal * (s + r)[:, None])[:, 1]
        v = cz - np.maximum(line.s[:, 1], line.e[:, 1])
        ok = ~(lo > hi) & ~((s <= 0) & (v < MIN_COS * r))
        return s, ok, r * r / v**3


def _sagittas(a, z, line: _Line, owner):
    """The signed sagitta of the circle through each sample's chord ends and the point ``(a, z)`` (positive: up)."""
    ll4 = (line.length * line.length / 4)[owner]
    n0, n1 = line.normal[owner, 0], line.normal[owner, 1]
    d0, d1 = a - line.mid[owner, 0], z - line.mid[owner, 1]
    u, w = d0 * n1 - d1 * n0, d0 * n0 + d1 * n1
    aw = np.maximum(np.abs(w), 1e-300)
    e = (ll4 - u * u - w * w) / (2 * aw)
    root = np.sqrt(e * e + ll4)
    mag = np.where(e >= 0, ll4 / (e + root), root - e)
    return np.where(w == 0, 0.0, np.sign(w) * mag)


def _heights(centre_a, centre_z, radius, dome, a):
    """Heights of circles at abscissae ``a``: the upper half for a dome, the lower one otherwise."""
    root = np.sqrt(np.maximum(radius**2 - (a - centre_a) ** 2, 0.0))
    return np.where(dome, centre_z + root, centre_z - root)


def _check(runs: Runs, c, line: _Line, start, stop, bounds: Bounds):
    """Which of the rounded arcs about ``c`` along the chords ``line`` pass both checks (all samples ``[start, stop)``).

    ``low - sz`` at two neighbouring samples is ``m0`` and ``m1``; with the
    path less the circle bending down no faster than ``c = kappa + bend``,
    the path rises above the circle between them by at most the largest of
    ``-(1-u) m0 - u m1 + c h**2 u (1-u) / 2`` (``h`` apart), which must be 0
    or less; the higher circle must stay within the tolerance above the
    samples between the ends.
    """
    s, e, limit_mm, chord_mm = line.s, line.e, bounds.limit_mm, bounds.chord_mm
    rs, re = np.hypot(s[:, 0] - c[:, 0], s[:, 1] - c[:, 1]), np.hypot(e[:, 0] - c[:, 0], e[:, 1] - c[:, 1])
    dome = (s[:, 1] > c[:, 1]) & (e[:, 1] > c[:, 1])
    ok = ~(np.abs(rs - re) > limit_mm) & ~(np.maximum(rs, re) > MAX_RADIUS_MM)
    ok &= dome | ((s[:, 1] < c[:, 1]) & (e[:, 1] < c[:, 1]))
    r_lo, r_hi = np.minimum(rs, re), np.maximum(rs, re)
    v = np.where(dome, np.minimum(s[:, 1], e[:, 1]) - c[:, 1], c[:, 1] - np.maximum(s[:, 1], e[:, 1]))
    v -= r_hi - r_lo
    ok &= ~(v < MIN_COS * r_hi)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        bend = np.where(dome, 0.0, r_hi * r_hi / v**3)
    idx, o, begin = _spans(start, stop)
    sa, sz = runs.sa[idx], runs.sz[idx]
    ca, cz, dm = c[o, 0], c[o, 1], dome[o]
    far = np.abs(sa - ca) >= r_lo[o]
    low = _heights(ca, cz, np.where(dome, r_lo, r_hi)[o], dm, sa) - np.where(dome, chord_mm, 0.0)[o]
    high = _heights(ca, cz, np.where(dome, r_hi, r_lo)[o], dm, sa) + np.where(dome, 0.0, chord_mm)[o]
    m = low - sz
    pair = o[:-1] == o[1:]
    m0, m1 = m[:-1][pair], m[1:][pair]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        q = (bounds.kappa + bend[o[:-1][pair]]) * np.diff(sa)[pair] ** 2 / 2.0
        u = np.clip(np.where(q > 0, (m0 - m1 + q) / (2 * q), 0.0), 0.0, 1.0)
        above = -(1 - u) * m0 - u * m1 + q * u * (1 - u) > 0.0
    # the ends are written points, kept as the line moves keep them
    inner = (sa > runs.sa[start][o]) & (sa < runs.sa[stop - 1][o])
    bad = far | (m < 0.0) | (inner & ~(high - sz <= bounds.tol))
    ok &= ~np.logical_or.reduceat(bad, begin)
    ok &= ~np.logical_or.reduceat(above, begin - np.arange(len(begin)))
    return ok
