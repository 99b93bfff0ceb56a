"""The samples a straight move of waterline finishing is checked at: evenly spaced, closer across a box edge.

:func:`move_samples` lays out the cutter locations along straight moves for
:mod:`.waterline`'s checks of its moves and links: where the whole tool
stays clear of the box edges a move runs across, the cutter path bends no
faster than the surface (:mod:`.chordal`) and samples ``spacing`` apart with
the sag bound between them suffice; where a move beyond the box brings the
tool onto an edge, its height rises like a square root, and the samples are
:data:`EDGE_DENSER` times closer across that edge.
"""

from __future__ import annotations

import numpy as np

__all__ = ["EDGE_DENSER", "move_samples"]

EDGE_DENSER = 32
"""How many times closer across a box edge a move with the tool axis beyond the box is checked near that edge."""


def move_samples(heights, a: np.ndarray, b: np.ndarray, spacing: float, bounds, radius: float):
    """Cutter locations along each straight move ``a[k] -> b[k]``: ``(move, t, z on the move, tip height, bend)``.

    Each move is sampled at its ends and at points at most ``spacing``
    (surface units) apart inside it, :data:`EDGE_DENSER` times closer
    where a move with an end beyond the box has the tool within its
    radius of a box edge it runs across (where the tool rolls onto the
    edge its height rises like a square root, faster than any bound on
    the surface's bending; clear of such edges the path bends no faster
    than the surface, :mod:`.chordal`).  ``bend`` is, at each sample
    inside its move, a quarter of the downward second difference there
    (for unequal steps, the second derivative the three samples show times
    the longer step squared over four), 0 at the ends.

    ``heights(x, y)`` gives the tip heights (mm) at surface positions, ``a``
    and ``b`` are ``(x, y, z)`` (surface units, z in mm), ``bounds`` the box
    and ``radius`` the tool's (surface units).
    """
    span, n = _pieces(a, b, spacing, bounds, radius)
    per = n.sum(axis=1) + 1  # samples of each move: the pieces share their ends
    k = np.repeat(np.arange(len(a)), per)
    pos = np.arange(k.size) - np.repeat(np.cumsum(per) - per, per)  # index within the move
    cum = np.concatenate([np.zeros((len(a), 1), dtype=int), np.cumsum(n, axis=1)], axis=1)
    piece = np.minimum((pos[:, None] >= cum[k, 1:]).sum(axis=1), n.shape[1] - 1)
    lo_t = np.concatenate([np.zeros((len(a), 1)), np.cumsum(span, axis=1)], axis=1)
    nk = np.maximum(n[k, piece], 1)
    t = lo_t[k, piece] + (pos - cum[k, piece]) / nk * span[k, piece]
    t = np.where(pos == per[k] - 1, 1.0, t)
    p = a[k] + t[:, None] * (b[k] - a[k])
    z = heights(p[:, 0], p[:, 1])
    return k, t, p[:, 2], z, _bends(k, t, z, piece)


def _pieces(a: np.ndarray, b: np.ndarray, spacing: float, bounds, radius: float):
    """Each move's pieces (fractions of it, five a move, some empty) and the steps each is sampled in."""
    x0, x1, y0, y1 = bounds
    beyond = ((a[:, 0] < x0) | (a[:, 0] > x1) | (a[:, 1] < y0) | (a[:, 1] > y1)
              | (b[:, 0] < x0) | (b[:, 0] > x1) | (b[:, 1] < y0) | (b[:, 1] > y1))
    # Along each move, the interval [enter, leave] of each axis with the tool clear of that axis's box edges: a
    # move along an edge keeps the same part of the tool off the box all along it, so that edge bends it no
    # faster than the surface (:func:`.chordal.crosses_box_edge`) and counts as clear.
    r = radius * (1 + 1e-9)
    length = np.hypot(b[:, 0] - a[:, 0], b[:, 1] - a[:, 1])
    enter, leave, across = [], [], []
    for c, lo, hi in ((0, x0 + r, x1 - r), (1, y0 + r, y1 - r)):
        d = b[:, c] - a[:, c]
        with np.errstate(divide="ignore", invalid="ignore"):
            ta, tb = (lo - a[:, c]) / d, (hi - a[:, c]) / d
            across.append(np.where(length > 0, np.abs(d) / length, 1.0))  # the move's share across the edges
        flat = d == 0
        enter.append(np.where(flat, -np.inf, np.minimum(ta, tb)))
        leave.append(np.where(flat, np.inf, np.maximum(ta, tb)))
    # Five pieces a move between those bounds, each evenly sampled: at ``spacing``, or where a move beyond the
    # box has the tool near an edge it runs across, at most ``spacing / EDGE_DENSER`` apart across that edge
    # (the square-root onset is across it: as close as on a move straight across), along the move near edges
    # of both axes (a corner).  A move with no end beyond is one piece.
    cuts = np.sort(np.clip(np.stack([enter[0], leave[0], enter[1], leave[1]], axis=1), 0.0, 1.0), axis=1)
    cuts = np.where(beyond[:, None], cuts, 1.0)
    ends = np.concatenate([np.zeros((len(a), 1)), cuts, np.ones((len(a), 1))], axis=1)
    span = np.diff(ends, axis=1)
    mid = 0.5 * (ends[:, :-1] + ends[:, 1:])
    near_x = (mid < enter[0][:, None]) | (mid > leave[0][:, None])
    near_y = (mid < enter[1][:, None]) | (mid > leave[1][:, None])
    share = np.where(near_x & near_y, 1.0, np.where(near_x, across[0][:, None],
                                                    np.where(near_y, across[1][:, None], 0.0)))
    with np.errstate(divide="ignore"):
        steps = np.where(beyond[:, None], np.minimum(spacing, spacing / EDGE_DENSER / share), spacing)
    n = np.where(span > 0, np.maximum(np.ceil(span * length[:, None] / steps), 1), 0).astype(int)
    widest = np.argmax(span, axis=1)  # two steps at least, as for a move of length 0
    n[np.arange(len(a)), widest] = np.where(n.sum(axis=1) < 2, 2, n[np.arange(len(a)), widest])
    return span, n


def _bends(k: np.ndarray, t: np.ndarray, z: np.ndarray, piece: np.ndarray) -> np.ndarray:
    """A quarter of the downward second difference at each sample inside its move (0 at its ends).

    Within an evenly sampled piece as :func:`.chordal.bends`; where two
    pieces meet, the second derivative the three samples show times the
    longer of the two steps squared over four.
    """
    bend = np.zeros(len(z))
    inner = np.flatnonzero(k[:-2] == k[2:]) + 1  # samples with both neighbours on their move
    if inner.size:
        even = piece[inner - 1] == piece[inner + 1]  # within one evenly sampled piece
        h1, h2 = t[inner] - t[inner - 1], t[inner + 1] - t[inner]
        hmax = np.maximum(h1, h2)
        with np.errstate(divide="ignore", invalid="ignore"):
            uneven = ((z[inner + 1] - z[inner]) / h2 - (z[inner] - z[inner - 1]) / h1) / (h1 + h2) * hmax * hmax / 2.0
        second = (z[inner - 1] - 2.0 * z[inner] + z[inner + 1]) / 4.0
        bend[inner] = np.maximum(0.0, -np.where(even, second, uneven))
    return bend
