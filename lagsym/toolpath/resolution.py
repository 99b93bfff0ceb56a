"""Tool positions on the program's resolution: the X and Y a program can write, before the tool is dropped there.

A program writes X and Y with a fixed number of decimals (3 in mm, 4 in
inch), so the control goes to the written position, not to the one planned.
On a path sloping ``g`` the cutter location there differs by up to ``g``
times half a unit of the last decimal (1.4 um on a 70 degree flank at 3
decimals).  The planner therefore moves every position it drops the tool at
onto that grid first (:meth:`ResolutionGrid.snap`); the written X and Y are
then exactly the positions whose cutter heights were computed, and rounding
Z up keeps the tool at or above them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..machine import Placement, ProgramFormat

__all__ = ["ResolutionGrid", "without_repeats"]


@dataclass(frozen=True)
class ResolutionGrid:
    """The positions a program can write, as seen from the surface.

    Attributes
    ----------
    unit_mm : float
        One unit of the program's last decimal, in mm (0.001, or 0.00254 for
        4 decimals in inch).
    mm_per_unit : float
        Millimetres per surface unit.
    origin_mm : tuple of float
        The work offset in X and Y.
    bounds : tuple of float
        The control points' box ``(x0, x1, y0, y1)`` in surface units; a
        position inside it is snapped to a grid position inside it.
    """

    unit_mm: float
    mm_per_unit: float
    origin_mm: tuple[float, float]
    bounds: tuple[float, float, float, float]

    @classmethod
    def of(cls, placement: Placement, program: ProgramFormat, bounds) -> ResolutionGrid:
        """The grid of a program written as ``program`` for the surface at ``placement``, over the box ``bounds``."""
        ox, oy, _ = placement.origin_mm
        return cls(program.resolution_mm, placement.mm_per_unit, (ox, oy), tuple(float(v) for v in bounds))

    def snap(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Surface positions moved to the nearest ones the program writes, never across a box edge.

        Examples
        --------
        >>> g = ResolutionGrid(0.001, 1.0, (0.0, 0.0), (0.0, 1 / 3, 0.0, 1.0))
        >>> [round(float(v), 6) for v in g.snap([0.12345, 1 / 3], [0.5, 0.0])[0]]
        [0.123, 0.333]
        """
        return self.snap_axis(x, 0), self.snap_axis(y, 1)

    def snap_between(self, x, y, ax, ay, bx, by) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`snap` of points added on moves ``a -> b``, kept off both ends where the move is long enough.

        A point that would snap onto an end of its move goes one unit further in.
        """
        out = []
        for axis, v, a, b in ((0, x, ax, bx), (1, y, ay, by)):
            s = self.snap_axis(v, axis)
            step = np.sign(np.asarray(b, dtype=float) - a) * self.unit_mm / self.mm_per_unit
            for end, toward in ((a, step), (b, -step)):
                inner = s + toward
                room = np.abs(np.asarray(b, dtype=float) - a) > 2.5 * self.unit_mm / self.mm_per_unit
                s = np.where((np.abs(s - end) < 0.5 * self.unit_mm / self.mm_per_unit) & room, inner, s)
            out.append(s)
        return out[0], out[1]

    def snap_axis(self, v, axis: int) -> np.ndarray:
        """:meth:`snap` of positions on one axis, 0 for x and 1 for y."""
        lo, hi = self.bounds[2 * axis:2 * axis + 2]
        return self._axis(v, lo, hi, self.origin_mm[axis])

    def _axis(self, v, lo: float, hi: float, origin: float) -> np.ndarray:
        v = np.asarray(v, dtype=float)
        s, q = self.mm_per_unit, self.unit_mm
        n = np.rint((v * s + origin) / q)
        n_lo = np.ceil((lo * s + origin) / q - 1e-9)  # the first grid position inside the box
        n_hi = np.floor((hi * s + origin) / q + 1e-9)
        n = np.where((v >= lo) & (n < n_lo), n_lo, n)
        n = np.where((v <= hi) & (n > n_hi), n_hi, n)
        return (n * q - origin) / s


def without_repeats(points_mm, rows, exact_mm, unit_mm: float) -> dict:
    """The points without those at the same X and Y as the one before and within ``unit_mm`` of its Z.

    Beyond a box corner several samples can land on one position of the
    program's grid; the program would write no block for the repeat.  The
    point kept takes the higher of the heights.  Returns the keyword
    arguments ``points_mm``, ``rows`` and ``exact_mm`` of a toolpath.
    """
    same = np.zeros(len(points_mm), dtype=bool)
    same[1:] = ((points_mm[1:, 0] == points_mm[:-1, 0]) & (points_mm[1:, 1] == points_mm[:-1, 1])
                & (np.abs(np.diff(points_mm[:, 2])) < unit_mm))
    if not same.any():
        return dict(points_mm=points_mm, rows=rows, exact_mm=exact_mm)
    first = np.cumsum(~same) - 1  # the kept point each one merges into
    keep = np.flatnonzero(~same)
    z, e = np.full(len(keep), -np.inf), np.full(len(keep), -np.inf)
    np.maximum.at(z, first, points_mm[:, 2])
    np.maximum.at(e, first, exact_mm)
    p = points_mm[keep].copy()
    p[:, 2] = z
    return dict(points_mm=p, rows=rows[keep], exact_mm=e)
