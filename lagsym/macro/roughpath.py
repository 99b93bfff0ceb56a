"""The PC's model of the roughing macro's path: the tips the control computes, in the order it visits them.

The control computes each tip from the position: ``b``, the clearance's
height there (:mod:`.clearance`), raised to the level.  Inside a row a
descent steeper than the tool's ramp angle is raised to that angle,

.. code-block:: text

    z[k] = max(b[k], level, z[k-1] - |p[k] - p[k-1]| tan(angle))     k >= 1 in the row's own order

so the bottom face of the end mill never leads into material more steeply
than the angle, whatever the passes before left (the rule holds in the air
too: the control does not know where the material is).  The row's first
position lies beside the block, where each level is entered from the air,
and is not held.  Heights only rise, so the clearance's proof (no position
and no move below the drop-cutter height plus the stock) stands.  The price
is a wedge on a flank that falls along a row, which the neighbouring rows,
running the other way, cut down where they pass.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from ..machine import Tool
from ..toolpath.rough import ramp_slope

__all__ = ["ramp_tangent", "b_mm", "xy", "model", "path"]

_TAN_GRID = 1_000_000  # the tangent the loops multiply by: rounded down to 1e-6, so a ramp is never steeper


def ramp_tangent(tool: Tool) -> Fraction | None:
    """The tangent of the tool's ramp angle as the loops hold it (rounded down); None at 90 degrees (plunges).

    >>> ramp_tangent(Tool("flat", 10.0)), ramp_tangent(Tool("flat", 10.0, ramp_angle_deg=90.0))
    (Fraction(267949, 1000000), None)
    """
    slope = ramp_slope(tool)
    return None if math.isinf(slope) else Fraction(math.floor(slope * _TAN_GRID), _TAN_GRID)


def b_mm(ev, place, radius_mm: float, stock_mm: float, x_mm, y_mm) -> np.ndarray:
    """``F + stock + R |grad F|`` (mm) at box positions ``x_mm, y_mm`` (machine mm), in floats."""
    u, v = place.to_surface(np.asarray(x_mm, float), np.asarray(y_mm, float))
    g = np.hypot(ev.fast_points(u, v, dx=1), ev.fast_points(u, v, dy=1))
    return place.height_mm(ev.fast_points(u, v)) + stock_mm + radius_mm * g


def xy(direction: str, p, r):
    """Positions along and across the rows as ``(x, y)``."""
    return (p, r) if direction == "x" else (r, p)


def model(ev, place, lay, radius_mm: float, stock_mm: float, *, a, b, per_mm: Fraction, direction: str):
    """The rows' and points' positions (mm) and the tip before the level (mm) at each, rows by points.

    ``lay`` is the loops' layout (:class:`lagsym.macro.roughing._Layout`),
    ``a`` and ``b`` the clearance tables in program units.
    """
    f = float(per_mm)
    kk = np.arange(lay.np_ + 1)
    p = np.minimum(float(lay.a0) + (kk - 1) * float(lay.dp), float(lay.a1))
    p[0], p[-1] = float(lay.e0), float(lay.e1)
    r = np.minimum(float(lay.c0) + np.arange(lay.nr + 1) * float(lay.dr), float(lay.c1))
    pc, rc = np.clip(p, float(lay.a0), float(lay.a1)), np.clip(r, float(lay.b0), float(lay.b1))
    ti = np.searchsorted(np.array([float(e) for e in lay.p_edges]), pc)
    tj = np.searchsorted(np.array([float(e) for e in lay.r_edges]), rc)
    at = np.array([[float(v) for v in row] for row in a]) / f
    bt = np.array([[float(v) for v in row] for row in b]) / f
    pp, rr = np.meshgrid(pc / f, rc / f)
    x, y = xy(direction, pp, rr)
    high = b_mm(ev, place, radius_mm, stock_mm, x, y) + at[ti[None, :], tj[:, None]]
    return r / f, p / f, np.minimum(high, bt[ti[None, :], tj[:, None]])


def path(rows, pts, b, levels, direction: str, tan_a: Fraction | None = None) -> np.ndarray:
    """The tips in the order the loops visit them (mm), each row's descents held to ``tan_a`` (None: not held)."""
    out, d = [], 0
    slope = None if tan_a is None else float(tan_a)
    for n, lv in enumerate(levels):
        order = range(len(rows)) if n % 2 == 0 else range(len(rows) - 1, -1, -1)
        for j in order:
            z = np.maximum(b[j], lv)
            p, zz = (pts, z) if d == 0 else (pts[::-1], z[::-1])
            if slope is not None:
                # z[k] = max(z[k], z[m] - (s[k] - s[m]) tan) over every m before k, s the distance along the row
                s = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(p)))]) * slope
                zz = np.maximum(zz, np.maximum.accumulate(zz + s) - s)
            x, y = xy(direction, p, np.full(len(p), rows[j]))
            out.append(np.column_stack([x, y, zz]))
            d = 1 - d
    return np.vstack(out)
