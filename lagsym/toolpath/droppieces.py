"""Drop-cutter on a piecewise surface (:mod:`lagsym.surfaces.piecewise`): the highest drop onto any piece in reach.

:func:`.dropcutter.drop_cutter` hands a piecewise surface's positions here.
Each piece is one polynomial on its cell, dropped on with the same search
and lattice as a whole polynomial (:func:`.dropcutter._drop_polynomial`'s
kernel); the work is in choosing which pieces to search at each position:
a bound of what each piece can lift the tool to (:mod:`.piecekernel`) rules
most of them out.
"""

from __future__ import annotations

import numpy as np

from ..surfaces.piecewise import PiecewiseEvaluator
from .droplattice import CL_MARGIN, _HEIGHT_SCALES, _inside_box, _kept_within, _kernel_surface, _lattice
from .workers import Workers

__all__ = ["drop_piecewise"]


def drop_piecewise(ev: PiecewiseEvaluator, x, y, radius: float, corner: float, *, lattice: int, starts: int,
                   margin: bool, workers: Workers | None = None) -> np.ndarray:
    """Drop-cutter on a piecewise surface: the highest of the drops onto every piece within the tool's reach.

    The box is the union of the cells, so the maximum over the disc and the
    box is the largest of the maxima over the disc and each cell; each is
    drop-cutter on the piece (a polynomial) restricted to its own cell, with
    the same search and lattice as on one polynomial.  A piece is searched
    only where it could rise above the height found: each position takes
    its pieces in the order of a bound no contact on them exceeds (from the
    Bezier control points of the parts of the piece, :func:`_piecewise_chunk`)
    and stops where the next bound is not above the height found.  The
    margin is :data:`CL_MARGIN` of the largest height scale of any piece, the
    same at every position.  With ``workers``, the positions are shared out
    among them in large chunks; the values are the same as without.
    """
    x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    shape_out = x.shape
    cx, cy = _inside_box(x.ravel(), y.ravel(), ev.bounds, radius)
    if radius == 0:
        return ev.fast_points(cx, cy).reshape(shape_out)
    parallel = workers is not None and workers.parallel and workers.evaluator is ev
    for n in (_PARTS, _fine_parts(ev)):  # made here once, not in each worker
        ev.part_upper_heights(n)
    if parallel and corner == radius:
        ev.piece_jets  # noqa: B018 (every piece's evaluator and a ball's jets at once, here, not in each worker)
    # Each position's value is independent of the chunk it is computed in; a chunk takes its pieces in rounds
    # from Python, so chunks are large.
    chunk = max(_PIECEWISE_CHUNK, -(-cx.size // (2 * workers.processes))) if parallel else cx.size
    tasks = [(cx[s:s + chunk], cy[s:s + chunk], (radius, corner), (lattice, starts)) for s in range(0, cx.size, chunk)]
    parts = workers.map(_piecewise_chunk, tasks) if parallel else [_piecewise_chunk(ev, *t) for t in tasks]
    out = np.concatenate(parts) if parts else np.empty(0)
    span = _piecewise_height_scale(ev) + radius + 1.0
    return (out + (CL_MARGIN * span if margin else 0.0)).reshape(shape_out)


_PIECEWISE_CHUNK = 2048  # positions per worker's task on a piecewise surface, at least


def _piecewise_chunk(ev: PiecewiseEvaluator, cx, cy, cutter: tuple[float, float],
                     search: tuple[int, int]) -> np.ndarray:
    """The highest drop onto any piece at each of the positions ``cx, cy`` (inside the box's reach), no margin;
    ``cutter`` is ``(radius, corner)``, ``search`` ``(lattice, starts)`` as :func:`drop_cutter` takes them.

    Each piece within reach of a position has a bound no contact on it
    exceeds (:mod:`.piecekernel`), from :data:`_PARTS` x :data:`_PARTS` parts
    of its cell.  In rounds, each position drops onto its piece of highest
    bound not yet dropped on, while that bound is above the height found; so
    the piece the tool rests on usually comes first.  After the first round,
    the pieces still in question get the closer bound of
    :func:`_fine_parts` parts, which rules out most of them.
    """
    (radius, corner), (lattice, starts) = cutter, search
    bx, by = ev.breaks_x, ev.breaks_y
    # The pieces' joins are where the surface's nodes are, as a polynomial's features are its nodes' spacing.
    feature = 0.5 * min(np.diff(bx).min(), np.diff(by).min())
    scale = _piecewise_height_scale(ev)
    # Drop-cutter on each piece as on one polynomial (dropcutter._drop_polynomial), its arguments made once a piece.
    from .kernel import drop_chunk

    spacing = max(min(radius / lattice, feature / 2), radius / 40)
    grid = [np.require(a, requirements="W") for a in _lattice(radius, spacing)]
    settle = 0.01 * CL_MARGIN * (scale + radius + 1.0)  # one settling threshold for every piece, the whole surface's
    surfaces = {}
    pos, i, k = _piece_pairs(ev, cx, cy, radius)
    bound = _piece_bounds(ev, cx, cy, (pos, i, k), radius, corner, parts=_PARTS)
    near = bound > -np.inf
    pos, piece, bound = pos[near], (i * (len(by) - 1) + k)[near], bound[near]
    out = np.full(cx.shape, -np.inf)
    columns = len(by) - 1
    fine = _fine_parts(ev)
    while pos.size:
        # The first pair of each position, by highest bound: its next piece to drop on.
        order = np.lexsort((-bound, pos))
        pos, piece, bound = pos[order], piece[order], bound[order]
        first = np.ones(pos.size, dtype=bool)
        first[1:] = pos[1:] != pos[:-1]
        now_pos, now_piece = pos[first], piece[first]
        by_piece = np.argsort(now_piece, kind="stable")
        now_pos, now_piece = now_pos[by_piece], now_piece[by_piece]
        cuts = np.flatnonzero(np.diff(now_piece)) + 1
        for group, p in zip(np.split(now_pos, cuts), now_piece[np.r_[0, cuts]]):
            i, k = divmod(int(p), columns)
            found = surfaces.get(p)
            if found is None:
                found = surfaces[p] = _kernel_surface(ev.piece_evaluator(i, k), radius, corner, spacing, settle,
                                                      jets=ev.jets_if_made(), at=(i, k))
            gx, gy = cx[group], cy[group]
            nx, ny = np.clip(gx, bx[i], bx[i + 1]), np.clip(gy, by[k], by[k + 1])
            gx, gy = _kept_within(gx, gy, nx, ny, np.hypot(gx - nx, gy - ny), radius)
            z = drop_chunk(*found, gx, gy, *grid, int(starts), corner == radius)
            out[group] = np.maximum(out[group], z)
        keep = ~first & (bound > out[pos])
        pos, piece, bound = pos[keep], piece[keep], bound[keep]
        if fine > _PARTS and pos.size:
            bound = _piece_bounds(ev, cx, cy, (pos, *np.divmod(piece, columns)), radius, corner, parts=fine)
            keep = bound > out[pos]
            pos, piece, bound = pos[keep], piece[keep], bound[keep]
            fine = _PARTS
    return out


_PARTS = 4  # parts of a piece's cell each way, for the bounds of what the piece can lift the tool to


def _fine_parts(ev: PiecewiseEvaluator) -> int:
    """Parts each way of the closer bounds: 16 (256 bounds a piece kept) while the pieces are few enough for
    them to take tens of megabytes at most, fewer for more pieces."""
    pieces = (len(ev.breaks_x) - 1) * (len(ev.breaks_y) - 1)
    return 16 if pieces <= 20_000 else 8 if pieces <= 80_000 else _PARTS


def _piece_pairs(ev: PiecewiseEvaluator, cx, cy, radius: float):
    """``(position, i, k)`` for every piece ``(i, k)`` whose cell's bounding columns and rows come within the
    tool's reach of each position."""
    bx, by = ev.breaks_x, ev.breaks_y
    reach = radius + _piece_eps(ev, radius)
    ni, nk = len(bx) - 1, len(by) - 1
    # The columns and rows of cells within reach of each position: lo..hi.
    i_lo = np.clip(np.searchsorted(bx[1:], cx - reach, "left"), 0, ni - 1)
    i_hi = np.clip(np.searchsorted(bx[:-1], cx + reach, "right") - 1, 0, ni - 1)
    k_lo = np.clip(np.searchsorted(by[1:], cy - reach, "left"), 0, nk - 1)
    k_hi = np.clip(np.searchsorted(by[:-1], cy + reach, "right") - 1, 0, nk - 1)
    wi, wk = int((i_hi - i_lo).max()) + 1, int((k_hi - k_lo).max()) + 1
    pos = np.repeat(np.arange(cx.size), wi * wk)
    di, dk = np.divmod(np.tile(np.arange(wi * wk), cx.size), wk)
    i, k = i_lo[pos] + di, k_lo[pos] + dk
    inside = (i <= i_hi[pos]) & (k <= k_hi[pos])
    return pos[inside], i[inside], k[inside]


def _piece_eps(ev: PiecewiseEvaluator, radius: float) -> float:
    """Rounding allowed in reach and height, as the box's own reach allows."""
    bx, by = ev.breaks_x, ev.breaks_y
    return 1e-9 * max(bx[-1] - bx[0], by[-1] - by[0], radius)


def _piece_bounds(ev: PiecewiseEvaluator, cx, cy, pairs, radius: float, corner: float, *, parts: int) -> np.ndarray:
    """For each pair ``(position, i, k)`` of ``pairs``, a height no contact on piece ``(i, k)`` puts the tool
    tip above at that position, from ``parts`` x ``parts`` parts of its cell (:mod:`.piecekernel`); ``-inf``
    where no part is within reach."""
    from .piecekernel import part_bounds

    pos, i, k = (np.ascontiguousarray(a, dtype=np.int64) for a in pairs)
    eps = _piece_eps(ev, radius)
    tops = ev.part_upper_heights(parts)
    return part_bounds(np.ascontiguousarray(cx, dtype=float), np.ascontiguousarray(cy, dtype=float), pos, i, k,
                       np.ascontiguousarray(ev.breaks_x), np.ascontiguousarray(ev.breaks_y),
                       np.ascontiguousarray(tops), float(radius), float(corner), (radius + eps) ** 2) + eps


def _piecewise_height_scale(ev: PiecewiseEvaluator) -> float:
    found = _HEIGHT_SCALES.get(ev)
    if found is None:
        # Each piece's power-basis spread on its normalized cell, as for one polynomial.
        found = _HEIGHT_SCALES[ev] = float(np.ptp(ev.local, axis=(2, 3)).max())
    return found
