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
           "assemble_offset"]

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


def _kept_corners(x, y, z) -> np.ndarray:
    """Indices to emit: the middle of three samples on one straight line at one height is left out."""
    flat = np.zeros(len(z), dtype=bool)
    straight = (x[1:-1] - x[:-2]) * (y[2:] - y[1:-1]) == (y[1:-1] - y[:-2]) * (x[2:] - x[1:-1])
    flat[1:-1] = (z[1:-1] == z[:-2]) & (z[1:-1] == z[2:]) & straight
    return np.flatnonzero(~flat)


def assemble_offset(x, y, floor, up, z_levels, *, stock, spec):
    """The offset path's moves level by level: down beside the block, the loops, up and over to the next."""
    top = stock.top_mm + spec.clearance_mm
    pts, kinds, floors = [], [], []
    for zl in z_levels:
        z = np.maximum(zl, floor + up)
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
        for j in _kept_corners(x, y, z)[1:]:
            pts.append((float(x[j]), float(y[j]), float(z[j])))
            kinds.append(FEED)
            floors.append(float(floor[j]))
    pts.append((pts[-1][0], pts[-1][1], top))
    kinds.append(RAPID)
    floors.append(-np.inf)
    return pts, kinds, floors


def _climb_forward(direction: str, progress: int) -> bool:
    """Whether a row cut forwards (along increasing coordinates) is climb milling, rows advancing by ``progress``.

    With the spindle turning clockwise, climb milling keeps the uncut
    material on the right of the direction of travel.
    """
    return progress < 0 if direction == "x" else progress > 0


def _kept(z: np.ndarray) -> np.ndarray:
    """Indices of a row's samples to emit: the middle of three samples at one height is on a straight move."""
    flat = np.zeros(len(z), dtype=bool)
    flat[1:-1] = (z[1:-1] == z[:-2]) & (z[1:-1] == z[2:])
    return np.flatnonzero(~flat)


def assemble_raster(rows, floors, lifts, z_levels, stock, spec):
    """The moves level by level: rows, links outside the block, and retracts above it for a one-way raster.

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
                fwd = _climb_forward(spec.direction, progress) == (spec.milling == "climb")
            a, ff, uu = (r.along, f, up) if fwd else (r.along[::-1], f[::-1], up[::-1])
            z = np.maximum(zl, ff + uu)
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
            for j in _kept(z)[1:]:
                add(float(a[j]), r.cross, float(z[j]), FEED, float(ff[j]))
    last = pts[-1]
    add(last[0] if along_x else last[1], last[1] if along_x else last[0], top, RAPID)
    return pts, kinds, floor
