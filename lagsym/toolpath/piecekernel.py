"""What a piece of a piecewise surface can lift a cutter to, bounded part by part, compiled by Numba.

Drop-cutter on a piecewise surface (:mod:`.dropcutter`) searches a piece
only where it could lift the tool above the height already found.  The bound
for a tool position and a piece cuts the piece's cell in ``P x P`` equal
parts: no point of a part lies above the part's highest Bezier control point
(``tops``, :meth:`lagsym.surfaces.piecewise_numeric.PiecewiseEvaluator.part_upper_heights`),
and the cutter's profile (its height above the tip at a distance from the
axis) is at least its value at the part's nearest point, so no contact on
the part puts the tip above their difference.  The bound is the largest of
these over the parts within the tool's reach (``-inf`` where none is).

This runs once per pair of a position and a piece near it, tens of pairs a
position and sixteen to a few hundred parts a pair: compiled, it costs a
small part of the searches it rules out.  Numba compiles it on the first
piecewise plan and keeps it in its cache beside this file.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["part_bounds"]


@njit(cache=True, nogil=True, error_model="numpy")
def part_bounds(cx, cy, pos, pi, pk, bx, by, tops, radius, corner, reach2):
    """``bound[j]`` for the pair of position ``pos[j]`` (of ``cx, cy``) and piece ``(pi[j], pk[j])``.

    ``bx, by`` are the cells' breaks, ``tops[i, k, a, b]`` the bound of part
    ``(a, b)`` of piece ``(i, k)``, already padded for rounding; ``corner``
    is ``radius`` for a ball, 0 for a flat end.
    """
    parts = tops.shape[2]
    flat = radius - corner
    out = np.empty(pos.size)
    for j in range(pos.size):
        x, y = cx[pos[j]], cy[pos[j]]
        i, k = pi[j], pk[j]
        x0, y0 = bx[i], by[k]
        wx, wy = bx[i + 1] - x0, by[k + 1] - y0
        best = -np.inf
        for a in range(parts):
            lo = x0 + wx * (a / parts)
            hi = bx[i + 1] if a == parts - 1 else x0 + wx * ((a + 1) / parts)
            gx = x - min(max(x, lo), hi)
            for b in range(parts):
                lo_y = y0 + wy * (b / parts)
                hi_y = by[k + 1] if b == parts - 1 else y0 + wy * ((b + 1) / parts)
                gy = y - min(max(y, lo_y), hi_y)
                d2 = gx * gx + gy * gy
                if d2 > reach2:
                    continue
                if corner <= 0.0:
                    profile = 0.0
                elif flat <= 0.0:
                    profile = radius - math.sqrt(max(radius * radius - d2, 0.0))
                else:
                    o = max(math.sqrt(d2) - flat, 0.0)
                    profile = corner - math.sqrt(max(corner * corner - o * o, 0.0))
                v = tops[i, k, a, b] - profile
                if v > best:
                    best = v
        out[j] = best
    return out
