"""The height map a cut leaves: a tool pressed into a grid of cells along straight moves.

``cut[i, j]`` is the lowest height any part of the tool reached over the
cell centre ``(xs[i], ys[j])``.  Every move is split into straight segments
at most a cell long sideways, and each segment lowers every cell centre its
tool passes over to the lowest point the tool's lower surface
(:func:`lagsym.cutter.cutter_profile`) reaches there along the whole
segment, in closed form (:mod:`lagsym.verify.swept`): one evaluation per
segment and cell, not one per sampled position.  Segments whose nearest cells
differ are swept together, one offset of the footprint at a time, so each
NumPy operation covers thousands of segments.  Work that would run away is
refused before it starts: more cells than ``max_cells``
(:func:`height_map_axes`) or more segments times cells under the tool than
``max_contacts``.
"""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..errors import InputError, ToolpathError
from ..machine import Tool
from ..progress import Progress, Tally
from .swept import bull_resolution, lowest_ball, lowest_bull, lowest_flat

__all__ = ["press_moves", "height_map_axes", "sweep", "tool_grid", "check_work", "segments", "MAX_CELLS", "MAX_CONTACTS"]

_MOVES_PER_PASS = 200_000  # moves split and swept at a time
_PIECE_CELLS = 8.0  # longest segment swept, sideways, in cells
_CHUNK = 16384  # segments swept together
_FEW = 1024  # fewer segments than this are swept over their whole footprint at once (see _sweep_few)
_FEW_CELLS = 1 << 20  # footprint cells _sweep_few takes at once: its arrays stay within tens of MB
MAX_CELLS = 16_000_000  # height-map cells by default: 4000 x 4000, about 0.5 GB with the arrays compared
MAX_CONTACTS = 20_000_000_000  # segments (all, before those far from the box are dropped) times cells under the tool


def sweep(cut, a_all, b_all, xs, ys, *, r, corner, workers: int | None = None, progress: Progress | None = None,
          winner: np.ndarray | None = None) -> int:
    """Lower ``cut`` to the tool's lowest surface along every move (in place); the number of segments swept.

    Moves are split into segments no longer sideways than ``_PIECE_CELLS``
    cells, and each segment lowers every cell centre its tool can reach by
    the exact lowest point over it (:mod:`lagsym.verify.swept`).  With
    ``workers`` threads (default 1: each NumPy call here gathers and scatters
    a few thousand cells, which holds the interpreter lock about as long as it
    computes, so a second thread gained nothing on a finishing program and
    lost half the speed on a bull nose's bisections) the cells the moves
    reach are cut into ``2 * workers`` stripes across X, each at least a
    footprint wide: the even ones are swept at the same time, then the odd
    ones, so no two threads ever write the same cell.  ``progress`` is told
    the segments swept (stage ``sweeping moves``), those far from the map
    counted as they are dropped.  ``winner``, an integer array the shape of
    ``cut``, if given, is set at every cell a move lowers to the index of that
    move in ``a_all`` (a move whose tool reaches the cell's lowest height).
    """
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    piece = _PIECE_CELLS * max(hx, hy)
    lowest = _kernel(r, corner)
    kx, ky = int(math.ceil((r + piece / 2) / hx)) + 1, int(math.ceil((r + piece / 2) / hy)) + 1
    workers = 1 if workers is None else max(int(workers), 1)
    count = 0
    swept = Tally(progress, "sweeping moves", segments(a_all, b_all, piece) if progress is not None else None)
    swept.start()
    for s in range(0, len(a_all), _MOVES_PER_PASS):
        a, b, move = _pieces(np.asarray(a_all[s:s + _MOVES_PER_PASS], dtype=float),
                             np.asarray(b_all[s:s + _MOVES_PER_PASS], dtype=float), piece)
        move += s
        near = ((np.maximum(a[:, 0], b[:, 0]) >= xs[0] - r - hx) & (np.minimum(a[:, 0], b[:, 0]) <= xs[-1] + r + hx)
                & (np.maximum(a[:, 1], b[:, 1]) >= ys[0] - r - hy) & (np.minimum(a[:, 1], b[:, 1]) <= ys[-1] + r + hy))
        swept.add(len(a) - int(near.sum()))
        a, b, move = a[near], b[near], move[near]
        count += len(a)
        if not len(a):
            continue
        # Segments beside the map reach it from within kx, ky cells of its edges.
        mid = 0.5 * (a + b)
        ix = np.clip(np.rint((mid[:, 0] - xs[0]) / hx).astype(np.int64), -kx, len(xs) - 1 + kx)
        iy = np.clip(np.rint((mid[:, 1] - ys[0]) / hy).astype(np.int64), -ky, len(ys) - 1 + ky)
        # The window of cells they reach, with room for every offset of the footprint.
        i0, j0 = int(ix.min()) - kx, int(iy.min()) - ky
        pad = np.full((int(ix.max()) + kx + 1 - i0, int(iy.max()) + ky + 1 - j0), np.inf)
        rows = slice(max(i0, 0), min(i0 + pad.shape[0], len(xs)))
        cols = slice(max(j0, 0), min(j0 + pad.shape[1], len(ys)))
        inner = (slice(rows.start - i0, rows.stop - i0), slice(cols.start - j0, cols.stop - j0))
        pad[inner] = cut[rows, cols]
        wpad = None
        if winner is not None:
            wpad = np.full(pad.shape, -1, dtype=np.int64)
            wpad[inner] = winner[rows, cols]
        stripes = 2 * workers if workers > 1 and pad.shape[0] >= 2 * workers * (2 * kx + 1) else 1
        work = [[] for _ in range(stripes)]
        for stripe, chunk in _chunks(a, b, (ix - i0, iy - j0), (i0, j0), (xs, ys, r), shape=pad.shape,
                                      stripes=stripes, move=move):
            work[stripe].append(chunk)
        geometry = (hx, hy, r, kx, ky, pad.shape[1], pad.reshape(-1), None if wpad is None else wpad.reshape(-1))

        def run(chunks):
            with np.errstate(invalid="ignore"):
                for chunk in chunks:
                    (_sweep_chunk if len(chunk[1]) >= _FEW else _sweep_few)(chunk, geometry, lowest)
                    swept.add(len(chunk[1]))

        if stripes == 1:
            run(work[0])
        else:
            with ThreadPoolExecutor(workers) as pool:
                for phase in (0, 1):
                    list(pool.map(run, work[phase::2]))
        if winner is not None:
            winner[rows, cols] = wpad[inner]
        np.minimum(cut[rows, cols], pad[inner], out=cut[rows, cols])
    swept.finish()
    return count


def segments(a, b, piece: float) -> int:
    """How many segments :func:`_pieces` splits the moves ``a -> b`` into."""
    d = np.asarray(b, dtype=float)[:, :2] - np.asarray(a, dtype=float)[:, :2]
    return int(np.maximum(np.ceil(np.hypot(d[:, 0], d[:, 1]) / piece), 1).sum()) if len(d) else 0


def _kernel(r, corner):
    """The closed-form lowest point of the tool over a cell along a segment (:mod:`lagsym.verify.swept`)."""
    if corner <= 0.0:
        return lambda ca, ce, seg, above: lowest_flat(ca, ce, seg, r)
    if corner >= r:
        return lambda ca, ce, seg, above: lowest_ball(ca, ce, seg, r)
    # The bull nose is searched, not solved: it skips the cells it cannot lower (``above``, their heights so far).
    return lambda ca, ce, seg, above: lowest_bull(ca, ce, seg, r, corner, above=above)


def _pieces(a, b, piece):
    """The moves turned to rise (``b_z >= a_z``) and split into segments at most ``piece`` long sideways.

    Returns the segments' ends and the index of the move each comes from.
    """
    up = b[:, 2] >= a[:, 2]
    a, b = np.where(up[:, None], a, b), np.where(up[:, None], b, a)
    d = b - a
    n = np.maximum(np.ceil(np.hypot(d[:, 0], d[:, 1]) / piece), 1).astype(np.int64)
    if not len(n) or int(n.max()) == 1:
        return a, b, np.arange(len(a))
    k = np.repeat(np.arange(len(a)), n)
    i = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
    t0, t1 = i / n[k], (i + 1) / n[k]
    return a[k] + t0[:, None] * d[k], a[k] + t1[:, None] * d[k], k


def _chunks(a, b, anchor, origin, grid, *, shape, stripes, move):
    """Segments in groups whose nearest cells (to their middles) differ, so one offset reaches distinct cells.

    ``anchor`` holds each segment's nearest cell in the window ``shape``, whose first cell is ``origin`` in the map.
    Yields the stripe of each group and ``(seg, base, bx, by, u, longest)``:
    ``seg = (az, az + r, length, m, k)`` per segment (:func:`lowest_ball`),
    the flat index of its nearest cell in the window, that cell's offset from
    the segment's start, the unit direction ``(ux, uy)`` and the group's
    longest segment (the groups are sorted by length, so short segments are
    swept over a small footprint), and the moves they come from.
    """
    xs, ys, r = grid
    ix, iy = anchor
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    d = b - a
    length = np.hypot(d[:, 0], d[:, 1])
    moving = length > 0.0
    ux = np.where(moving, d[:, 0] / np.where(moving, length, 1.0), 1.0)
    uy = np.where(moving, d[:, 1] / np.where(moving, length, 1.0), 0.0)
    m = np.where(moving, d[:, 2] / np.where(moving, length, 1.0), 0.0)
    k = m / np.sqrt(1.0 + m * m)
    key = ix * shape[1] + iy
    order = np.argsort(key, kind="stable")
    sk = key[order]
    first = np.concatenate([[True], sk[1:] != sk[:-1]])
    rank = np.empty(len(sk), dtype=np.int64)
    rank[order] = np.arange(len(sk)) - np.maximum.accumulate(np.where(first, np.arange(len(sk)), 0))
    stripe = np.minimum(ix * stripes // shape[0], stripes - 1)
    order = np.lexsort((length, rank, stripe))
    group = (stripe * (int(rank.max()) + 1) + rank)[order]
    bx, by = xs[0] + (ix + origin[0]) * hx - a[:, 0], ys[0] + (iy + origin[1]) * hy - a[:, 1]
    for run in np.split(order, np.flatnonzero(np.diff(group)) + 1):
        for g in np.array_split(run, -(-len(run) // _CHUNK)):
            yield int(stripe[g[0]]), ((a[g, 2], a[g, 2] + r, length[g], m[g], k[g]), key[g], bx[g], by[g],
                                      (ux[g], uy[g]), float(length[g].max()), move[g])


def _sweep_chunk(chunk, geometry, lowest):
    """Lower the padded map over every cell the segments of one group can reach (rows ``di``, columns ``dj``)."""
    seg, base, bx, by, (ux, uy), longest, move = chunk
    hx, hy, r, kx, ky, stride, flat, wflat = geometry
    # The segment lies within longest / 2 of its middle, the middle within half a cell of its nearest cell.
    reach = r + longest / 2 + 1e-9
    lo = kx * stride + ky  # offsets are taken from a view this far back, so the index arrays stay as they are
    base = base - lo
    dj = np.arange(-ky, ky + 1)
    wy = by[None, :] + dj[:, None] * hy
    ay, ey = wy * uy, wy * ux
    for di in range(-kx, kx + 1):
        gx = max(abs(di) * hx - hx / 2, 0.0)
        if gx > reach:
            continue
        span = min(int(math.floor(math.sqrt(reach * reach - gx * gx) / hy + 0.5)), ky)
        wx = bx + di * hx
        ax, ex = wx * ux, -wx * uy
        for j in range(-span, span + 1):
            view = flat[lo + di * stride + j:]
            cur = view[base]
            v = lowest(ax + ay[j + ky], ex + ey[j + ky], seg, cur)
            if wflat is not None:
                won = v < cur
                if won.any():
                    wview = wflat[lo + di * stride + j:]
                    wview[base[won]] = move[won]
            np.fmin(cur, v, out=cur)
            view[base] = cur


def _sweep_few(chunk, geometry, lowest):
    """As :func:`_sweep_chunk` for a handful of segments: all offsets at once, a few segments at a time.

    The offset loop costs the same Python work for two segments as for
    thousands; here each NumPy operation covers every cell of the square
    footprint of up to 64 segments, and ``np.fmin.at`` lowers the map.  A
    large footprint (a large tool over small cells) is taken in bands of its
    rows, so no array holds more than :data:`_FEW_CELLS` cells.
    """
    (az, azr, length, m, k), base, bx, by, (ux, uy), _, move = chunk
    hx, hy, _, kx, ky, stride, flat, wflat = geometry
    dj = np.arange(-ky, ky + 1)
    band = max(1, _FEW_CELLS // len(dj))  # footprint rows at a time
    for r0 in range(-kx, kx + 1, band):
        di = np.arange(r0, min(r0 + band, kx + 1))
        offsets = (di * stride)[:, None] + dj[None, :]
        group = max(1, min(64, _FEW_CELLS // offsets.size))  # segments at a time
        for s in range(0, len(base), group):
            g = slice(s, s + group)
            wx, wy = bx[g, None] + di * hx, by[g, None] + dj * hy
            ca = (wx * ux[g, None])[:, :, None] + (wy * uy[g, None])[:, None, :]
            ce = (-wx * uy[g, None])[:, :, None] + (wy * ux[g, None])[:, None, :]
            every = base[g, None, None] + offsets
            v = lowest(ca, ce, tuple(p[g, None, None] for p in (az, azr, length, m, k)), flat[every])
            under = ~np.isnan(v)
            cells = every[under]
            np.fmin.at(flat, cells, v[under])
            if wflat is not None:
                # Any move whose value is the cell's new lowest reaches it there.
                won = flat[cells] == v[under]
                wflat[cells[won]] = np.broadcast_to(move[g, None, None], v.shape)[under][won]


def height_map_axes(box_mm, cell_mm: float | None, max_cells: int | None) -> tuple[np.ndarray, np.ndarray]:
    """Cell centres in x and y of a height map over ``box_mm`` ``(x0, x1, y0, y1)``, refused beyond ``max_cells``.

    ``cell_mm`` defaults to the longer side / 400.
    """
    x0, x1, y0, y1 = box_mm
    if cell_mm is None:
        cell_mm = max(x1 - x0, y1 - y0) / 400.0
    if not cell_mm > 0:
        raise ToolpathError(f"cell size {cell_mm!r} must be a positive number of mm")
    nx = max(int(math.ceil((x1 - x0) / cell_mm)) + 1, 2)
    ny = max(int(math.ceil((y1 - y0) / cell_mm)) + 1, 2)
    if max_cells is not None and nx * ny > max_cells:
        raise InputError(f"a height map of {nx} x {ny} cells of {cell_mm:g} mm is {nx * ny:.3g} cells, more than the "
                         f"limit of {max_cells:.3g}; use a larger cell (--cell) or raise the limit (--max-cells)")
    return np.linspace(x0, x1, nx), np.linspace(y0, y1, ny)


def check_work(a, b, piece: float, r: float, hx: float, hy: float, *, max_contacts: int | None) -> None:
    """Refuse a simulation whose segments swept times cells each can reach would exceed ``max_contacts``."""
    if max_contacts is None:
        return
    d = b - a
    segments = float(np.maximum(np.ceil(np.hypot(d[:, 0], d[:, 1]) / piece), 1).sum())
    footprint = (2 * math.ceil((r + piece / 2) / hx) + 3) * (2 * math.ceil((r + piece / 2) / hy) + 3)
    if segments * footprint > max_contacts:
        raise InputError(
            f"simulating {segments:.3g} segments over {footprint:.3g} cells under the tool each is "
            f"{segments * footprint:.3g} contacts, more than the limit of {max_contacts:.3g}; check the program's "
            f"moves and the tool diameter, use a larger cell (--cell), or raise the limit (--max-contacts)")


def press_moves(cut: np.ndarray, xs: np.ndarray, ys: np.ndarray, a: np.ndarray, b: np.ndarray, tool: Tool, *,
                max_contacts: int | None = MAX_CONTACTS, progress: Progress | None = None,
                winner: np.ndarray | None = None) -> tuple[int, float]:
    """Lower the height map ``cut`` (in place) to the tool's lower surface along the moves ``a[k] -> b[k]`` (mm).

    ``cut[i, j]`` is the height over ``(xs[i], ys[j])``, evenly spaced cell
    centres.  Returns the number of segments swept and the simulation's
    vertical resolution (as :func:`simulate_cut` states it); ``progress`` as
    :func:`sweep` tells it, ``winner`` as :func:`sweep` sets it.
    """
    r, corner, piece, resolution = tool_grid(tool, xs, ys)
    if not len(a):
        return 0, resolution
    check_work(a, b, piece, r, xs[1] - xs[0], ys[1] - ys[0], max_contacts=max_contacts)
    return sweep(cut, a, b, xs, ys, r=r, corner=corner, progress=progress, winner=winner), resolution


def tool_grid(tool: Tool, xs: np.ndarray, ys: np.ndarray) -> tuple[float, float, float, float]:
    """The simulated tool's radius and corner, the longest segment swept and the simulation's vertical resolution.

    The ball and the flat end are swept exactly (resolution 0, floating-point
    rounding apart); the bull nose to :func:`lagsym.verify.swept.bull_resolution`.
    """
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    r = tool.radius_mm if tool.radius_mm > 0 else 0.5 * min(hx, hy)
    corner = tool.corner_mm if tool.radius_mm > 0 else 0.0
    piece = _PIECE_CELLS * max(hx, hy)
    resolution = bull_resolution(corner, piece) if 0.0 < corner < r else 0.0
    return r, corner, piece, resolution
