"""The path pattern: a zig-zag of evenly spaced rows over the control points' box.

Rows run along x or y; the side step between rows comes from the raster
settings or from a scallop height (:func:`scallop_stepover`), and positions
along a row are evenly spaced no wider than the forward step.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ToolpathError
from ..machine import BOUNDARIES, DIRECTIONS
from ..values import choice, finite, positive

__all__ = ["raster_pattern", "levels", "scallop_stepover", "tool_reach", "within_reach", "past_reach", "reach_levels",
           "fixed_step_samples", "every_step", "MAX_LEVELS"]

MAX_LEVELS = 10_000_000  # rows, or positions along a row, of one raster: 80 MB of floats each


def scallop_stepover(radius_mm: float, scallop_mm: float) -> float:
    """Side step of a ball-end cutter that leaves cusps ``scallop_mm`` high on a flat floor.

    ``2 * sqrt(2 R h - h**2)``, from the circle of the ball over the cusp.

    Examples
    --------
    >>> round(scallop_stepover(3.0, 0.01), 4)
    0.4895
    """
    r, h = finite(radius_mm, "tool radius"), positive(scallop_mm, "scallop height")
    if r <= 0:
        raise ToolpathError("a scallop height needs a ball-end cutter with a diameter above 0")
    if h >= r:
        raise ToolpathError(f"scallop height {h:g} mm must be less than the tool radius {r:g} mm")
    return 2.0 * math.sqrt(2.0 * r * h - h * h)


def levels(lo: float, hi: float, step: float) -> np.ndarray:
    """Evenly spaced positions from ``lo`` to ``hi``, both included, no further apart than ``step``.

    Examples
    --------
    >>> levels(0.0, 1.0, 0.4).tolist()
    [0.0, 0.3333333333333333, 0.6666666666666666, 1.0]
    """
    span = (hi - lo) / step
    if not math.isfinite(span) or span + 1 > MAX_LEVELS:
        raise ToolpathError(f"{lo:g} to {hi:g} in steps of {step:g} is {span + 1:.4g} positions, more than the "
                            f"limit of {MAX_LEVELS:,} in one direction: give a larger step")
    count = max(int(math.ceil(span - 1e-9)), 1)
    return np.linspace(lo, hi, count + 1)


def raster_pattern(bounds, direction: str, stepover: float, step: float):
    """A zig-zag over ``bounds`` = ``(x0, x1, y0, y1)``: row levels and along-row positions.

    Rows run along ``direction``; both are evenly spaced, never wider than the
    steps given, and include the box edges.  Odd rows run backwards.

    Returns
    -------
    levels : ndarray
        Cross coordinate of each row.
    along : ndarray
        Positions along a row (forwards).
    """
    choice(direction, DIRECTIONS, "raster direction")
    stepover, step = positive(stepover, "side step"), positive(step, "forward step")
    x0, x1, y0, y1 = _box(bounds)
    if direction == "x":
        return levels(y0, y1, stepover), levels(x0, x1, step)
    return levels(x0, x1, stepover), levels(y0, y1, step)


def _box(bounds) -> tuple[float, float, float, float]:
    """``(x0, x1, y0, y1)`` as finite floats with ``x0 <= x1`` and ``y0 <= y1``; the message names a bad one."""
    try:
        values = tuple(bounds)
    except TypeError:
        raise ToolpathError(f"bounds {bounds!r:.80} is not (x0, x1, y0, y1)") from None
    if len(values) != 4:
        raise ToolpathError(f"bounds {values!r:.80} is not (x0, x1, y0, y1)")
    x0, x1, y0, y1 = (finite(v, f"bounds {name}") for v, name in zip(values, ("x0", "x1", "y0", "y1")))
    if x1 < x0 or y1 < y0:
        raise ToolpathError(f"bounds {values!r:.80} is not a box: x0 <= x1 and y0 <= y1 are needed")
    return x0, x1, y0, y1


def tool_reach(bounds, radius: float, boundary: str, past: float | None = None):
    """The box the tool axis ranges over, ``(x0, x1, y0, y1)``, for a boundary mode (see :class:`~lagsym.machine.RasterSpec`).

    ``inside`` shrinks the control points' box by the tool radius (surface
    units), ``centre`` keeps it, ``past`` widens it by ``past`` (by default
    the radius); with ``past`` the rows round the box corners
    (:func:`within_reach`).

    Examples
    --------
    >>> tool_reach((0.0, 4.0, 0.0, 2.0), 0.5, "past")
    (-0.5, 4.5, -0.5, 2.5)
    """
    choice(boundary, BOUNDARIES, "boundary")
    x0, x1, y0, y1 = (float(v) for v in bounds)
    grow = {"inside": -radius, "centre": 0.0, "past": radius if past is None else past}[boundary]
    if x1 - x0 + 2 * grow < 0 or y1 - y0 + 2 * grow < 0:
        raise ToolpathError(f"a tool of radius {radius:g} does not fit inside the control points' box "
                            f"x {x0:g}..{x1:g}, y {y0:g}..{y1:g}; choose another boundary")
    return (x0 - grow, x1 + grow, y0 - grow, y1 + grow)


def within_reach(x, y, bounds, radius: float):
    """Positions brought within ``radius`` of the box: beyond a corner, onto the arc around it.

    Examples
    --------
    >>> [round(float(v), 6) for v in within_reach(3.0, 3.0, (0.0, 2.0, 0.0, 2.0), 1.0)]
    [2.707107, 2.707107]
    """
    x0, x1, y0, y1 = bounds
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    nx, ny = np.clip(x, x0, x1), np.clip(y, y0, y1)
    d = np.hypot(x - nx, y - ny)
    f = np.where(d > radius, radius / np.where(d > 0, d, 1.0), 1.0)
    return nx + (x - nx) * f, ny + (y - ny) * f


_SLOPE_SAMPLES = 257  # points along each box edge where the steepest slope is measured


def past_reach(ev, radius: float, corner: float) -> float:
    """How far beyond the box the tool axis goes with ``--boundary past`` (surface units).

    ``ev`` is the surface's evaluator, ``corner`` the corner radius (the
    radius for a ball, 0 for a flat end).  A cutter touches a slope of angle
    ``a`` on its corner, at ``(radius - corner) + corner * sin(a)`` from its
    axis: a flat end touches the box edge up to its radius beyond it, a ball
    at ``radius * sin(a)``.  Beyond that distance for the steepest slope on
    the box edges the tool reaches nothing the positions nearer the box have
    not; further out it would touch the part's edge only low on its corner,
    where a sideways rounding of the position moves the tool a long way down
    the edge.
    """
    if corner <= 0 or radius == 0:
        return radius
    x0, x1, y0, y1 = ev.bounds
    t = np.linspace(0.0, 1.0, _SLOPE_SAMPLES)
    ex = np.concatenate([x0 + t * (x1 - x0), x0 + t * (x1 - x0), np.full_like(t, x0), np.full_like(t, x1)])
    ey = np.concatenate([np.full_like(t, y0), np.full_like(t, y1), y0 + t * (y1 - y0), y0 + t * (y1 - y0)])
    slope = float(np.hypot(ev.fast_points(ex, ey, dx=1), ev.fast_points(ex, ey, dy=1)).max())
    # A little further than the samples show, for the slope between them.
    return min(radius, radius - corner + 1.02 * corner * slope / math.hypot(1.0, slope))


def reach_levels(inner, lo: float, hi: float) -> np.ndarray:
    """Row levels across the box (``inner``, ascending, from edge to edge) fitted to the reach ``lo..hi``.

    A reach inside the box keeps the rows within it and adds its ends; one
    beyond the box continues the rows past each edge with the gap of the
    first (last) one inside, ending on the reach.

    Examples
    --------
    >>> reach_levels([0.0, 0.4, 1.0], -0.5, 1.25).tolist()
    [-0.5, -0.25, 0.0, 0.4, 1.0, 1.25]
    >>> reach_levels([0.0, 0.4, 1.0], 0.1, 0.9).tolist()
    [0.1, 0.4, 0.9]
    """
    inner = np.asarray(inner, dtype=float)
    if len(inner) < 2 or hi <= lo:
        return np.array([lo, hi]) if hi > lo else np.array([lo])
    gap_lo, gap_hi = inner[1] - inner[0], inner[-1] - inner[-2]
    before = levels(lo, inner[0], gap_lo)[:-1] if lo < inner[0] else np.zeros(0)
    after = levels(inner[-1], hi, gap_hi)[1:] if hi > inner[-1] else np.zeros(0)
    eps = 1e-9 * (inner[-1] - inner[0])
    mid = inner[(inner > lo + eps) & (inner < hi - eps)]
    ends = ([lo] if lo >= inner[0] else []), ([hi] if hi <= inner[-1] else [])
    return np.concatenate([before, ends[0], mid, ends[1], after])


def fixed_step_samples(a0: float, a1: float, step: float, fine: float, snap):
    """Samples along a row for a fixed step, and how many samples make one move (surface units).

    The row is cut into equal moves no longer than ``step`` once moved onto
    the program's resolution (``snap``), each sampled at least twice and no
    further apart than ``fine``.
    """
    moves = max(int(math.ceil((a1 - a0) / step - 1e-9)), 1)
    while True:
        every = max(2, int(math.ceil((a1 - a0) / moves / fine - 1e-9)))
        along = np.linspace(a0, a1, moves * every + 1)
        if np.diff(snap(along[::every])).max() <= step * (1 + 1e-9):
            return along, every
        moves += 1


def every_step(s_mm: np.ndarray, lo: int, hi: int, longest_mm: float) -> np.ndarray:
    """The samples ``lo..hi`` of one piece a move apart: from each, the furthest no more than ``longest_mm`` on."""
    s = s_mm[lo:hi + 1] - s_mm[lo]
    reach = np.maximum(np.searchsorted(s, s + longest_mm * (1 + 1e-9), side="right") - 1, np.arange(len(s)) + 1)
    out, i = [0], 0
    while i < len(s) - 1:
        i = int(min(reach[i], len(s) - 1))
        out.append(i)
    return np.array(out, dtype=int) + lo
