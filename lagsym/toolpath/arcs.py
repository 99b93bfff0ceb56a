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
:data:`.arcfit.MIN_COS` from the horizontal.

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
from .arcfit import MAX_RADIUS_MM, Bounds, Runs, fit

__all__ = ["Arcs", "fit_arcs", "RADIUS_LIMIT", "MAX_RADIUS_MM"]

RADIUS_LIMIT = {"mm": 0.002, "inch": 0.0002}  # LinuxCNC: start and end radius may differ by this (program units)
RADIUS_AGREE = 0.75  # the part of that limit a written arc may use


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
    bounds = Bounds(kappa, tol, unit_mm, RADIUS_AGREE * RADIUS_LIMIT[units] / unit_factor, chord_mm)
    n = len(ints)
    same = np.zeros(n, dtype=bool)
    same[1:] = (ints[1:, cx] == ints[:-1, cx]) & (rows[1:] == rows[:-1]) & safe[1:] & safe[:-1] \
        & (ints[1:, ax] != ints[:-1, ax])
    breaks = np.flatnonzero(~same)
    spans = [(b0, b1) for b0, b1 in zip(breaks, np.append(breaks[1:], n)) if b1 - b0 >= 3]
    signs, rows_ = [], []
    for b0, b1 in spans:
        sign = 1 if ints[b1 - 1, ax] > ints[b0, ax] else -1
        k0, k1 = np.searchsorted(f_cross, ints[b0, cx]), np.searchsorted(f_cross, ints[b0, cx], side="right")
        sel = order[k0:k1]
        sa = np.concatenate([fine_ints[sel, ax] * unit_mm, ints[b0:b1, ax] * unit_mm]) * sign
        sz = np.concatenate([fine_mm[sel, 2], exact_mm[b0:b1]])
        a = ints[b0:b1, ax] * unit_mm * sign
        inside = (sa >= a[0]) & (sa <= a[-1])
        k = np.argsort(sa[inside], kind="stable")
        signs.append(sign)
        rows_.append((a, ints[b0:b1, 2] * unit_mm, sa[inside][k], sz[inside][k]))
    run, i, j, centre = _greedy(Runs.of(rows_), np.array([b1 - b0 for b0, b1 in spans], dtype=np.int64), bounds)
    offset = np.array([b0 for b0, _ in spans], dtype=np.int64)
    first, end = offset[run] + i, offset[run] + j
    ca = centre[:, 0] * np.array(signs, dtype=float)[run]
    s3, e3 = points_mm[first], points_mm[end]
    turn = (s3[:, ax] - ca) * (e3[:, 2] - s3[:, 2]) - (s3[:, 2] - centre[:, 1]) * (e3[:, ax] - s3[:, ax])
    # turn > 0: from the along axis towards Z.  About +Y (G18) a positive turn takes Z to X; about +X (G19)
    # it takes Y to Z.
    ccw = turn < 0 if ax == 0 else turn > 0
    return Arcs(start=first, end=end, centre_mm=np.stack([ca, centre[:, 1]], axis=1), ccw=ccw,
                plane="G18" if ax == 0 else "G19")


def _greedy(runs: Runs, counts, bounds: Bounds):
    """``(run, i, j, centre)`` of the arcs along every run: from each point as far as an arc fits, runs side by side.

    Along one run, from point ``i`` the reach is doubled while an arc fits,
    then bisected back between the last that fitted and the first that did
    not; the arc is kept and the next one starts at its end.  Where no arc
    fits from ``i``, the search moves on to ``i + 1``.  Every round asks
    :func:`.arcfit.fit` for one candidate of every run still searching.
    """
    nrun = len(counts)
    base = np.cumsum(counts) - counts
    i, step = np.zeros(nrun, dtype=np.int64), np.full(nrun, 2, dtype=np.int64)
    good, bad = np.full(nrun, -1, dtype=np.int64), np.full(nrun, -1, dtype=np.int64)
    good_c, bisect = np.zeros((nrun, 2)), np.zeros(nrun, dtype=bool)
    found = []
    live = np.flatnonzero(i < counts - 2)
    while len(live):
        j = np.where(bisect[live], (good[live] + bad[live]) // 2, np.minimum(i[live] + step[live], counts[live] - 1))
        ok, c = fit(runs, base[live] + i[live], base[live] + j, bounds)
        was_bisect = bisect[live]
        good[live[ok]], good_c[live[ok]] = j[ok], c[ok]
        bad[live[~ok]] = j[~ok]
        at_end = ok & (j == counts[live] - 1)
        grow = ~was_bisect & ok & ~at_end
        none = ~was_bisect & ~ok & (good[live] < 0)
        settle = at_end | (~grow & ~none & (bad[live] - good[live] <= 1))
        step[live[grow]] *= 2
        bisect[live[~grow & ~none & ~settle]] = True
        done = live[settle]
        found.append((done, i[done], good[done], good_c[done]))
        i[done] = good[done]
        i[live[none]] += 1
        reset = live[settle | none]
        step[reset], good[reset], bad[reset], bisect[reset] = 2, -1, -1, False
        live = live[i[live] < counts[live] - 2]
    run, first, end, centre = (np.concatenate(v) for v in zip(*found)) if found else \
        (np.zeros(0, dtype=np.int64),) * 3 + (np.zeros((0, 2)),)
    k = np.lexsort((first, run))
    return run[k], first[k], end[k], centre[k]
