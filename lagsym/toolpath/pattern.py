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

__all__ = ["raster_pattern", "levels", "scallop_stepover", "tool_reach", "within_reach"]


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
    count = max(int(math.ceil((hi - lo) / step - 1e-9)), 1)
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
    x0, x1, y0, y1 = (float(v) for v in bounds)
    if direction == "x":
        return levels(y0, y1, stepover), levels(x0, x1, step)
    return levels(x0, x1, stepover), levels(y0, y1, step)


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
