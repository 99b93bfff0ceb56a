"""Filtering: of the finely sampled cutter locations of a row, the fewest whose straight moves stay within a tolerance."""

from __future__ import annotations

import numpy as np

from ..values import finite

__all__ = ["filter_rows"]


def filter_rows(along: np.ndarray, z: np.ndarray, tolerance: float, extra: np.ndarray | None = None,
                longest: float | None = None) -> np.ndarray:
    """Indices of the points of one row to keep so that straight moves stay within ``tolerance`` of ``z``.

    Greedy, as OpenCAMLib's line filter: from each kept point the move reaches
    as far as every skipped point lies within ``tolerance`` (vertically) of it.
    The first and last points are always kept.  ``extra`` (per point) is added
    to a skipped point's distance below the chord: the part of the true path's
    bend between samples that they do not show.  With ``longest``, no move
    is longer than that along the row (a fixed forward step is then the
    longest move, and the tolerance adds points where the path bends).

    Examples
    --------
    >>> filter_rows(np.arange(5.0), np.array([0.0, 1.0, 2.0, 2.0, 2.0]), 0.01).tolist()
    [0, 2, 4]
    """
    tolerance = finite(tolerance, "chordal tolerance", low=0.0)
    n = len(along)
    if extra is None:
        extra = np.zeros(n)
    keep = [0]
    if longest is not None and n > 1:
        # Each point's farthest reach within the longest move, at least its neighbour.
        last = np.maximum(np.searchsorted(along, along + longest * (1 + 1e-9), side="right") - 1,
                          np.minimum(np.arange(n) + 1, n - 1))
    else:
        last = np.full(n, n - 1)
    i = 0
    while i < n - 1:
        end = int(last[i])
        lo, hi = i + 1, min(end, i + 2)
        # Grow the reach by doubling, then bisect back to the last good end.
        while hi < end and _within(along, z, i, hi, tolerance, extra):
            lo, hi = hi, min(end, i + 2 * (hi - i))
        if _within(along, z, i, hi, tolerance, extra):
            lo = hi
        else:
            while hi - lo > 1:
                mid = (lo + hi) // 2
                if _within(along, z, i, mid, tolerance, extra):
                    lo = mid
                else:
                    hi = mid
        keep.append(lo)
        i = lo
    return np.array(keep, dtype=int)


def _within(t, z, i, j, tol, extra):
    """Whether the move from point ``i`` to point ``j`` keeps every point between within ``tol``."""
    if j - i < 2:
        return True
    s = (t[i + 1:j] - t[i]) / (t[j] - t[i])
    dev = z[i + 1:j] - (z[i] + s * (z[j] - z[i]))
    return bool(np.all((-dev <= tol) & (dev + extra[i + 1:j] <= tol)))
