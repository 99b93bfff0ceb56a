"""How a roughing path's moves are put together: the raster's rows and links, the offset clearing's loops.

Both take the samples with their floors (drop-cutter height plus stock)
and lifts from :mod:`lagsym.toolpath.rough` and put the tip at
``max(level, floor + lift)`` at each level.

*Raster*: rows start and end beside the block; a zig-zag stays down on
links outside it, a one-way raster goes back above the block.

*Offset*: at each level the tool comes down beside the block (by the tool
radius plus the clearance, in the air), feeds in along the block's edge to
a corner of its outline and runs concentric rectangles inwards, the
outline's first, each at most the side step inside the one before and the
last on the middle line (a rectangle of no width), so the rectangles cover
the block as the raster's rows do.  Each rectangle runs one way: clockwise
seen from above (the uncut middle on the right of the tool: climb milling
with the spindle turning clockwise) or counter-clockwise (conventional).
From one rectangle's corner to the next the tool moves along the side just
cut, then inwards.  After the last rectangle it goes straight up (the
column above the tool was cleared by the levels above, which visit the same
positions no lower) and over the block to the next level's entry.  Every
straight piece is sampled like a raster row: the forward step, the box
edges and where the tool starts to touch the box.
"""

from __future__ import annotations

import math

import numpy as np

from .pattern import levels as spaced

__all__ = ["FEED", "RAPID", "PLUNGE", "PATTERNS", "along_samples", "assemble_raster", "offset_line",
           "assemble_offset", "ramped", "clear_of_block", "kept_visits", "climb_forward"]

FEED, RAPID, PLUNGE = 0, 1, 2
"""How the tool moves into a point: at the cutting feed, at rapid, or at the plunge feed."""
PATTERNS = ("raster", "offset")


def along_samples(lo: float, hi: float, cross: float, box_along, box_cross, *, radius: float,
                  step: float) -> np.ndarray:
    """Positions from ``lo`` to ``hi`` on a line at ``cross``: the forward step plus where the drop-cutter
    height has a corner (the box edges, and where the disc under the tool starts to meet an edge or corner)."""
    b_a0, b_a1 = box_along
    b_c0, b_c1 = box_cross
    extra = [b_a0, b_a1, b_a0 + radius, b_a1 - radius]
    for edge_gap in (abs(cross - b_c0), abs(cross - b_c1)):
        if edge_gap <= radius:
            w = math.sqrt(radius * radius - edge_gap * edge_gap)
            extra += [b_a0 + w, b_a1 - w]
    gap = max(b_c0 - cross, cross - b_c1, 0.0)
    if gap <= radius:
        w = math.sqrt(radius * radius - gap * gap)
        extra += [b_a0 - w, b_a1 + w]
    e = np.array(extra)
    a, b = min(lo, hi), max(lo, hi)
    out = np.unique(np.concatenate([spaced(a, b, step), e[(e > a) & (e < b)]]))
    return out if lo <= hi else out[::-1]


_MAX_SWEEPS = 64  # back-and-forth pairs over one dip: each lowers it by its width times the slope, or stops
_SWEEP_GAIN_MM = 1e-4  # a pair of sweeps that lowers the tool by less than this anywhere is not made


def _ramp_step(z_prev: float, mat_prev: float, cut: float, mat: float, dist: float, tan_a: float) -> float:
    """The lowest tip at a sample after ``z_prev`` one ``dist`` back: down to ``cut`` at most ``tan_a`` per mm where
    it may meet material, at once where the tool stays on or above what the passes before left at both ends, or
    where it ends clear of the block."""
    ramp = z_prev - tan_a * dist
    if mat == -math.inf:  # the tool is clear of the block there: nothing to enter
        return cut
    if z_prev >= mat_prev:
        ramp = min(mat, ramp) if ramp > mat else ramp
    return cut if ramp <= cut else ramp


def _sweep(order, z_start: float, cut, mat, gaps, tan_a: float) -> dict:
    """One pass over the samples ``order`` (consecutive indices, either way) from ``z_start``: each sample's tip."""
    out = {order[0]: z_start}
    z = z_start
    for a, b in zip(order, order[1:]):
        z = _ramp_step(z, mat[a], cut[b], mat[b], gaps[min(a, b)], tan_a)
        out[b] = z
    return out


def ramped(gaps, cut, mat, tan_a: float):
    """Tip heights along one pass that never descends into material steeper than ``tan_a`` (rise per mm).

    ``cut`` is the height wanted at each sample (the level or the floor),
    ``mat`` the most material there can be under the tool at each sample
    (the tip heights of the pass before over the same samples: the tool
    passed there at that height, so its whole disc is clear down to it;
    ``-inf`` where the disc misses the block), ``gaps`` the distances
    between consecutive samples.  A descent steeper than ``tan_a`` is made
    only from a sample where the tool is on or above that material to one
    where it is too (the straight move between stays above the pass
    before's); any other descent ramps down along the pass at ``tan_a``.
    Where the ramp leaves the tool above ``cut`` (a wedge on a slope down),
    the tool goes on to where it is back at ``cut``, then back over the
    wedge and forward again, each sweep ramping down into what the one
    before left, until it is cut (or a pair of sweeps gains nothing: a dip
    narrower than the ramp can reach, whose rest the next level or the
    finishing takes).

    Returns the visits (sample index and tip, in the order the tool makes
    them) and the lowest tip at each sample (the next level's ``mat``).

    Examples
    --------
    >>> visits, low = ramped([1.0, 1.0, 1.0], [5.0, 5.0, 2.0, 2.0], [5.0, 5.0, 5.0, 5.0], 1.0)
    >>> visits
    [(0, 5.0), (1, 5.0), (2, 4.0), (3, 3.0), (2, 2.0), (1, 5.0), (2, 2.0), (3, 2.0)]
    >>> low.tolist()
    [5.0, 5.0, 2.0, 2.0]
    """
    cut = np.asarray(cut, float)
    mat = np.asarray(mat, float)
    mat = np.where(mat == -np.inf, mat, np.maximum(mat, cut))
    n = len(cut)
    if not math.isfinite(tan_a):
        return [(i, float(cut[i])) for i in range(n)], cut.copy()
    drop = cut[:-1] - cut[1:]
    steep = (drop > tan_a * np.asarray(gaps)) & ~((cut[:-1] >= mat[:-1]) & (cut[1:] >= mat[1:]))
    steep &= mat[1:] > -np.inf
    if not steep.any():
        return [(i, float(cut[i])) for i in range(n)], cut.copy()
    gaps, cut_l, mat_l = list(gaps), cut.tolist(), mat.tolist()
    first = _sweep(list(range(n)), cut_l[0], cut_l, mat_l, gaps, tan_a)
    low = np.array([first[i] for i in range(n)])
    wedge = low > cut + 1e-9
    visits, done = [], 0
    runs = np.flatnonzero(np.diff(np.concatenate([[0], wedge.astype(np.int8), [0]])))
    for p, q in zip(runs[::2], runs[1::2]):  # samples p..q-1 stand above cut
        lo, hi = max(p - 1, 0), min(q, n - 1)
        visits += [(i, float(low[i])) for i in range(done, hi + 1)]
        done = hi + 1
        span = list(range(lo, hi + 1))
        for _ in range(_MAX_SWEEPS):
            here = low.tolist()
            back = _sweep(span[::-1], here[hi], cut_l, here, gaps, tan_a)
            fwd = _sweep(span, back[lo], cut_l, [back.get(i, here[i]) for i in range(n)], gaps, tan_a)
            gain = max(here[i] - fwd[i] for i in span)
            if gain < _SWEEP_GAIN_MM:
                break
            visits += [(i, back[i]) for i in span[::-1][1:]] + [(i, fwd[i]) for i in span[1:]]
            for i in span:
                low[i] = min(fwd[i], back[i], low[i])
            if (low[span] <= cut[span] + 1e-9).all():
                break
    visits += [(i, float(low[i])) for i in range(done, n)]
    return visits, low


def clear_of_block(x, y, stock, radius: float) -> np.ndarray:
    """Where a tool of ``radius`` centred at ``x, y`` (mm) has no part of the block under it."""
    gx = np.maximum(np.maximum(stock.x0 - np.asarray(x), np.asarray(x) - stock.x1), 0.0)
    gy = np.maximum(np.maximum(stock.y0 - np.asarray(y), np.asarray(y) - stock.y1), 0.0)
    return np.hypot(gx, gy) > radius


def _segment(p, q, box, radius: float, step: float):
    """Samples of the axis-parallel segment ``p -> q`` (x, y arrays), ``p`` included, ``q`` left out."""
    if p[1] == q[1]:
        a = along_samples(p[0], q[0], p[1], box[:2], box[2:], radius=radius, step=step)
        return a[:-1], np.full(len(a) - 1, p[1])
    a = along_samples(p[1], q[1], p[0], box[2:], box[:2], radius=radius, step=step)
    return np.full(len(a) - 1, p[0]), a[:-1]


def offset_line(stock, box, radius: float, spec) -> tuple[np.ndarray, np.ndarray]:
    """One level's offset path (x, y, mm): the lead-in from beside the block, the rectangles inwards, the links."""
    x0, x1, y0, y1 = stock.box
    half = min(x1 - x0, y1 - y0) / 2
    count = max(int(math.ceil(half / spec.stepover_mm - 1e-9)), 1)
    corners = [(x0 - radius - spec.clearance_mm, y0)]
    for k, s in enumerate(np.linspace(0.0, half, count + 1)):
        a0, a1, b0, b1 = x0 + s, x1 - s, y0 + s, y1 - s
        if k:
            corners.append((a0, corners[-1][1]))  # along the side just cut, then inwards
        loop = [(a0, b0), (a0, b1), (a1, b1), (a1, b0)]
        if spec.milling == "conventional":
            loop = [(a0, b0), (a1, b0), (a1, b1), (a0, b1)]
        corners += loop + [(a0, b0)]
    xs, ys = [], []
    for p, q in zip(corners, corners[1:]):
        if p != q:
            sx, sy = _segment(p, q, box, radius, spec.step_mm)
            xs.append(sx)
            ys.append(sy)
    xs.append([corners[-1][0]])
    ys.append([corners[-1][1]])
    return np.concatenate(xs), np.concatenate(ys)


def kept_visits(idx, z, x=None, y=None) -> np.ndarray:
    """Indices into the visits to emit: the middle of three at one height, on one straight line and passed one
    way, is on a straight move (a turn back over the same samples is kept)."""
    idx, z = np.asarray(idx), np.asarray(z)
    flat = np.zeros(len(z), dtype=bool)
    one_way = (idx[1:-1] - idx[:-2]) * (idx[2:] - idx[1:-1]) > 0
    flat[1:-1] = (z[1:-1] == z[:-2]) & (z[1:-1] == z[2:]) & one_way
    if x is not None:
        px, py = np.asarray(x)[idx], np.asarray(y)[idx]
        flat[1:-1] &= (px[1:-1] - px[:-2]) * (py[2:] - py[1:-1]) == (py[1:-1] - py[:-2]) * (px[2:] - px[1:-1])
    return np.flatnonzero(~flat)


def assemble_offset(x, y, floor, up, z_levels, *, stock, spec, radius: float = 0.0, tan_a: float = math.inf):
    """The offset path's moves level by level: down beside the block, the loops, up and over to the next.

    No descent into material is steeper than ``tan_a`` (rise per mm):
    :func:`ramped`, the material under each position taken from the level
    before (the block's top at the first), none where the tool of
    ``radius`` is clear of the block.
    """
    top = stock.top_mm + spec.clearance_mm
    pts, kinds, floors = [], [], []
    gaps = np.hypot(np.diff(x), np.diff(y))
    mat = np.where(clear_of_block(x, y, stock, radius), -np.inf, stock.top_mm)
    for zl in z_levels:
        visits, low = ramped(gaps, np.maximum(zl, floor + up), mat, tan_a)
        mat = np.where(np.isfinite(mat), low, -np.inf)
        idx = np.array([v[0] for v in visits])
        z = np.array([v[1] for v in visits])
        if pts:
            pts.append((pts[-1][0], pts[-1][1], top))
            kinds.append(RAPID)
            floors.append(-np.inf)
        pts.append((x[0], y[0], top))
        kinds.append(RAPID)
        floors.append(-np.inf)
        if zl + spec.clearance_mm < top:
            pts.append((x[0], y[0], zl + spec.clearance_mm))
            kinds.append(RAPID)
            floors.append(-np.inf)
        pts.append((x[0], y[0], float(z[0])))
        kinds.append(PLUNGE)
        floors.append(-np.inf)
        for j in kept_visits(idx, z, x, y)[1:]:
            i = idx[j]
            pts.append((float(x[i]), float(y[i]), float(z[j])))
            kinds.append(FEED)
            floors.append(float(floor[i]))
    pts.append((pts[-1][0], pts[-1][1], top))
    kinds.append(RAPID)
    floors.append(-np.inf)
    return pts, kinds, floors


def climb_forward(direction: str, progress: int) -> bool:
    """Whether a row cut forwards (along increasing coordinates) is climb milling, rows advancing by ``progress``.

    With the spindle turning clockwise, climb milling keeps the uncut
    material on the right of the direction of travel.
    """
    return progress < 0 if direction == "x" else progress > 0


def assemble_raster(rows, floors, lifts, z_levels, stock, spec, *, radius: float = 0.0, tan_a: float = math.inf):
    """The moves level by level: rows, links outside the block, and retracts above it for a one-way raster.

    No descent into material is steeper than ``tan_a`` (rise per mm): each
    row is :func:`ramped`, the material under each sample taken from the
    level before on the same row (the block's top at the first), none
    where the tool of ``radius`` is clear of the block.

    Long because the three kinds of link (along a row end, down between
    levels, back above the block) are decided here together with the row
    directions they depend on.
    """
    along_x = spec.direction == "x"
    top = stock.top_mm + spec.clearance_mm
    pts, kinds, floor = [], [], []

    def add(a, c, z, kind, f=-np.inf):
        pts.append((a, c, z) if along_x else (c, a, z))
        kinds.append(kind)
        floor.append(f)

    mats = []
    for r in rows:
        rx, ry = (r.along, np.full(len(r.along), r.cross)) if along_x else (np.full(len(r.along), r.cross), r.along)
        mats.append(np.where(clear_of_block(rx, ry, stock, radius), -np.inf, stock.top_mm))
    toggle = 0
    for k, zl in enumerate(z_levels):
        order = range(len(rows)) if k % 2 == 0 else range(len(rows) - 1, -1, -1)
        progress = 1 if k % 2 == 0 else -1
        for i in order:
            r, f, up = rows[i], floors[i], lifts[i]
            if spec.milling == "zigzag":
                fwd = toggle % 2 == 0
                toggle += 1
            else:
                fwd = climb_forward(spec.direction, progress) == (spec.milling == "climb")
            a, ff, uu, mm = (r.along, f, up, mats[i]) if fwd else (r.along[::-1], f[::-1], up[::-1], mats[i][::-1])
            visits, low = ramped(np.abs(np.diff(a)), np.maximum(zl, ff + uu), mm, tan_a)
            low = np.where(np.isfinite(mm), low, -np.inf)
            mats[i] = low if fwd else low[::-1]
            idx = np.array([v[0] for v in visits])
            z = np.array([v[1] for v in visits])
            if not pts:
                add(a[0], r.cross, top, RAPID)
                add(a[0], r.cross, float(z[0]), PLUNGE)
            elif spec.milling == "zigzag":
                # The row ends lie outside the block by the tool radius and the clearance: clear at any height.
                add(a[0], r.cross, float(z[0]), PLUNGE if pts[-1][2] > z[0] else FEED)
            else:
                last = pts[-1]
                add(last[0] if along_x else last[1], last[1] if along_x else last[0], top, RAPID)
                add(a[0], r.cross, top, RAPID)
                if zl + spec.clearance_mm < top:
                    add(a[0], r.cross, zl + spec.clearance_mm, RAPID)
                add(a[0], r.cross, float(z[0]), PLUNGE)
            for j in kept_visits(idx, z)[1:]:
                add(float(a[idx[j]]), r.cross, float(z[j]), FEED, float(ff[idx[j]]))
    last = pts[-1]
    add(last[0] if along_x else last[1], last[1] if along_x else last[0], top, RAPID)
    return pts, kinds, floor
