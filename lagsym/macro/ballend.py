"""Ball-end cutters on the control: the tool tip one radius off the surface along its normal, and the gouge check.

For a ball of radius ``rho`` whose centre stays ``rho + stock`` from the
surface ``Z(P, R)`` along the unit normal ``(-Zp, -Zr, 1) / w``, with
``w = sqrt(1 + Zp**2 + Zr**2)`` and ``Zp``, ``Zr`` the exact partial
derivatives, the programmed tip is

    P' = P - q * Zp,   R' = R - q * Zr,   Z' = Z + q - rho,   q = (rho + stock) / w.

The control computes ``Zp`` and ``Zr`` from the same well-conditioned form as
``Z`` (:func:`offset_statements`); the PC computes the same tip in floats
(:func:`offset_points`).  Where the surface is concave with a radius of
curvature below the ball's, the offset point is not the nearest and the ball
cuts into the part: :func:`check_gouge` finds that off-line, over the raster
(every position, or 1001 x 1001 of them evenly spread for a finer one), and
refuses.
"""

from __future__ import annotations

import dataclasses
from fractions import Fraction

import numpy as np

from ..errors import ToolpathError
from ..evaluate import power_partials
from ..lagrange import LagrangeSurface
from ..machine import MachineSettings, Tool
from ..values import as_exact
from .form import RowForm, row_form
from .model import Assign, add, const, div, mul, sqrt, sub, var
from .raster import MacroRaster, sample_positions
from .rounding import tip_lift, tips_on_grid

__all__ = ["is_ball", "refuse_flat_end", "ball_offsets", "contact_form", "offset_points", "offset_statements", "TIP_OUTPUTS",
           "check_gouge", "check_gouge_over", "checked_tip_lift", "ball_tips", "tip_points", "derivatives"]

TIP_OUTPUTS = ("pt", "rt", "zt")  # the variables the tool tip (P', R', Z') is computed into


def is_ball(tool: Tool | None) -> bool:
    """True for a ball-end cutter with a diameter: one that is offset along the normal."""
    return tool is not None and tool.is_ball and tool.diameter_mm > 0


def refuse_flat_end(tool: Tool | None) -> None:
    """Refuse a cutter a macro cannot drive: a flat end or bull nose with a diameter (the cutter says why,
    :meth:`lagsym.cutter.Cutter.check_macro`)."""
    if tool is not None:
        tool.check_macro()


def ball_offsets(settings: MachineSettings, tool: Tool) -> tuple[float, float]:
    """The ball's radius and its centre's distance from the surface (radius plus stock), in program units."""
    uf = settings.unit_factor
    return tool.radius_mm * uf, (tool.radius_mm + settings.stock_to_leave_mm) * uf


def contact_form(surface: LagrangeSurface, settings: MachineSettings, direction: str = "x",
                 kind: str = "horner") -> RowForm:
    """The row form of the surface the ball touches: without the stock, which is in the offset."""
    return row_form(surface, dataclasses.replace(settings, stock_to_leave_mm=0.0), direction, kind)


def derivatives(form: RowForm, p, r) -> dict[str, np.ndarray]:
    """Height and first and second partial derivatives of ``form`` at (p, r), in program units (floats)."""
    f = power_partials(form.coefficients, p, r, centre=(form.pc, form.rc), inverse_half_width=(form.pk, form.rk))
    return {"z": f[0, 0] + float(form.z0), "zp": f[1, 0], "zr": f[0, 1],
            "zpp": f[2, 0], "zpr": f[1, 1], "zrr": f[0, 2]}


def offset_points(form: RowForm, radius: float, offset: float, p, r):
    """The programmed tip (P', R', Z') for contact points (p, r): arrays in program units."""
    f = derivatives(form, p, r)
    q = offset / np.sqrt(1.0 + f["zp"] ** 2 + f["zr"] ** 2)
    return np.asarray(p) - q * f["zp"], np.asarray(r) - q * f["zr"], f["z"] + q - radius


def ball_tips(form: RowForm, radius: float, offset: float, p, r, *, resolution: Fraction = Fraction(0),
              lift: Fraction = Fraction(0)):
    """The tips the program moves to for contact points (p, r): offset, then rounded as on the control.

    With a ``resolution`` (see :mod:`lagsym.macro.rounding`) the tip is
    rounded to it and its height moved along the tangent plane and raised by ``lift``.
    """
    pt, rt, zt = offset_points(form, radius, offset, p, r)
    if not resolution:
        return pt, rt, zt
    f = derivatives(form, p, r)
    return tips_on_grid(pt, rt, zt, f["zp"], f["zr"], unit=float(resolution), lift=float(lift))


def offset_statements(radius: float, offset: float) -> tuple:
    """Statements run once per point after the height and slopes: the tip into :data:`TIP_OUTPUTS`."""
    p, r, z = var("p"), var("r"), var("z")
    zp, zr, q = var("zp"), var("zr"), var("q")
    pt, rt, zt = (var(n) for n in TIP_OUTPUTS)
    return (
        Assign(q, add(add(mul(zp, zp), mul(zr, zr)), const(1))),
        Assign(q, div(const(as_exact(offset, "ball offset")), sqrt(q))),
        Assign(pt, sub(p, mul(q, zp))),
        Assign(rt, sub(r, mul(q, zr))),
        Assign(zt, sub(add(z, q), const(as_exact(radius, "ball radius")))),
    )


def check_gouge(form: RowForm, p, r, radius: float, source: str = "<surface>", unit: float = 1.0):
    """Refuse a normal offset where the surface is concave tighter than the ball (radius in program units).

    The larger principal curvature of the graph ``Z(P, R)`` (positive where the
    surface is concave, seen from the tool) is checked at every point (p, r).
    Returns it, and ``Zp**2 + Zr**2`` there.
    """
    f = derivatives(form, p, r)
    fx, fy, fxx, fxy, fyy = f["zp"], f["zr"], f["zpp"], f["zpr"], f["zrr"]
    g = 1.0 + fx**2 + fy**2
    mean = ((1 + fx**2) * fyy - 2 * fx * fy * fxy + (1 + fy**2) * fxx) / (2 * g**1.5)
    gauss = (fxx * fyy - fxy**2) / g**2
    kmax = mean + np.sqrt(np.maximum(mean**2 - gauss, 0.0))
    k = int(np.argmax(kmax))
    if kmax[k] * radius > 1.0:
        rc = 1.0 / kmax[k] / unit
        pp, rr = (float(np.asarray(p).ravel()[k]) / unit, float(np.asarray(r).ravel()[k]) / unit)
        raise ToolpathError(
            f"{source}: the surface is concave with a radius of curvature of {rc:.3g} mm near "
            f"({pp:.3f}, {rr:.3f}) mm, below the offset radius {radius / unit:g} mm (ball radius plus stock): "
            f"an offset along the normal would gouge there; use a ball of diameter at most {2 * rc:.3g} mm, "
            f"or the point-list toolpath (lagsym toolpath, drop-cutter)")
    return kmax, g - 1.0


def check_gouge_over(form: RowForm, raster: MacroRaster, offset: float, source: str, unit: float):
    """:func:`check_gouge` over the raster: every position, or 1001 x 1001 of them evenly spread."""
    xs, ys = sample_positions(raster, 1001)
    p, r = (xs, ys) if raster.direction == "x" else (ys, xs)
    return check_gouge(form, p, r, offset, source, unit)


def checked_tip_lift(form: RowForm, raster: MacroRaster, offset: float, resolution: Fraction, source: str = "<surface>",
                     unit: float = 1.0) -> Fraction:
    """:func:`check_gouge_over`, then the lift of the rounded tips (:func:`lagsym.macro.rounding.tip_lift`)."""
    kmax, slopes_sq = check_gouge_over(form, raster, offset, source, unit)
    return tip_lift(kmax, slopes_sq, offset, resolution) if resolution else Fraction(0)


def tip_points(surface: LagrangeSurface, settings: MachineSettings, tool: Tool, x, y) -> np.ndarray:
    """The tool-tip points (N, 3) of a ball-end cutter in contact at raster positions (x, y), program units."""
    radius, offset = ball_offsets(settings, tool)
    px, py, pz = offset_points(contact_form(surface, settings, "x"), radius, offset, x, y)
    return np.column_stack([px, py, pz])
