"""The points a macro program should produce, computed on the PC, to check the program against.

Z is the surface height at each raster position (stable evaluation, within
1e-12 of the exact value), placed on the machine, plus the stock to leave; a
ball-end cutter's point is its tip, one radius off the surface along the
normal (:mod:`lagsym.macro.ballend`).  Everything in program units.
"""

from __future__ import annotations

import numpy as np

from ..evaluate import evaluate_points
from ..lagrange import LagrangeSurface
from ..machine import MachineSettings, RasterSpec, Tool
from ._placement import placement
from .ballend import ball_offsets, ball_tips, checked_tip_lift, contact_form, is_ball, refuse_flat_end, tip_points
from .raster import macro_raster, raster_positions
from .rounding import resolution, round_half_away, slope_lift

__all__ = ["points_at", "planned_points"]


def points_at(surface: LagrangeSurface, settings: MachineSettings, tool: Tool | None, x, y) -> np.ndarray:
    """The programmed points (N, 3) for raster positions (x, y), in program units.

    Z is the surface height at each position, scaled, plus the origin and the
    stock to leave.  For a ball-end tool with a diameter the point is the tool
    tip of a ball whose centre sits one radius (plus stock) off the surface
    along its normal.
    """
    refuse_flat_end(tool)
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if is_ball(tool):
        return tip_points(surface, settings, tool, x, y)
    place = placement(settings)
    s = float(place.scale)
    ox, oy, oz = (float(v) for v in place.origin)
    z = evaluate_points(surface, (x - ox) / s, (y - oy) / s) * s + oz + float(place.stock)
    return np.column_stack([x, y, z])


def planned_points(surface: LagrangeSurface, settings: MachineSettings, raster: RasterSpec,
                   tool: Tool | None = None) -> np.ndarray:
    """The points a macro program should move through, computed on the PC: an (N, 3) array in program units.

    Every raster position in the order the program visits them, through
    :func:`points_at`, rounded as the program rounds them on the control
    (:mod:`lagsym.macro.rounding`): the position to the last decimal first
    and the height there, raised by half a unit; for a ball end the tip
    rounded, its height moved along the tangent plane and raised.  The
    program's first feed move (the plunge) ends at the first of these points.
    """
    counted = macro_raster(surface, settings, raster)
    x, y = raster_positions(counted)
    unit = resolution(settings)
    if not is_ball(tool):
        if unit:
            x, y = round_half_away(x, float(unit)), round_half_away(y, float(unit))
        pts = points_at(surface, settings, tool, x, y)
        pts[:, 2] += float(unit / 2 if unit else slope_lift(surface, settings))
        return pts
    radius, offset = ball_offsets(settings, tool)
    form = contact_form(surface, settings, counted.direction)
    lift = checked_tip_lift(form, counted, offset, unit, stock=offset - radius)
    p, r = (x, y) if counted.direction == "x" else (y, x)
    pt, rt, zt = ball_tips(form, radius, offset, p, r, resolution=unit, lift=lift)
    zt = zt + float(0 if unit else slope_lift(surface, settings))
    return np.column_stack([pt, rt, zt] if counted.direction == "x" else [rt, pt, zt])
