"""Ball-end cutters on the control: the tool tip one radius off the surface along its normal, and the gouge check.

For a ball of radius ``rho`` whose centre stays ``rho + stock`` from the
surface ``Z(P, R)`` along the unit normal ``(-Zp, -Zr, 1) / w``, with
``w = sqrt(1 + Zp**2 + Zr**2)`` and ``Zp``, ``Zr`` the exact partial
derivatives, the programmed tip is

    P' = P - q * Zp,   R' = R - q * Zr,   Z' = Z + q - rho,   q = (rho + stock) / w.

The control computes ``Zp`` and ``Zr`` from the same well-conditioned form as
``Z``.  Where the surface is concave with a radius of curvature below the
ball's, the offset point is not the nearest and the ball cuts into the part;
:func:`check_gouge` finds that off-line, over the raster (every position, or
1001 x 1001 of them evenly spread for a finer one), and refuses.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import ToolpathError
from ..evaluate import power_partials
from ..lagrange import LagrangeSurface
from ..machine import MachineSettings, RasterSpec, Tool
from .form import RowForm, point_statements, row_form, row_statements
from .model import Assign, add, const, div, mul, sqrt, sub, var
from .plan import exact, macro_raster, sample_positions

__all__ = ["ballend_plan", "offset_points", "tip_points", "check_gouge", "derivatives"]


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


def _no_stock(settings: MachineSettings) -> MachineSettings:
    return dataclasses.replace(settings, stock_to_leave_mm=0.0)


def check_gouge(form: RowForm, p, r, radius: float, source: str = "<surface>", unit: float = 1.0) -> None:
    """Refuse a normal offset where the surface is concave tighter than the ball (radius in program units).

    The larger principal curvature of the graph ``Z(P, R)`` (positive where the
    surface is concave, seen from the tool) is checked at every point (p, r).
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


def ballend_plan(surface: LagrangeSurface, settings: MachineSettings, raster: RasterSpec, tool: Tool,
                 form: str = "horner"):
    """The loop plan for a ball-end cutter: height, exact slopes and the normal offset on the control."""
    from .program import MacroPlan, loop_plan

    plan = macro_raster(surface, settings, raster)
    rf = row_form(surface, _no_stock(settings), plan.direction, form)
    uf = settings.unit_factor
    radius = tool.radius_mm * uf
    offset = (tool.radius_mm + settings.stock_to_leave_mm) * uf
    xs, ys = sample_positions(plan, 1001)
    pr, rr = (xs, ys) if plan.direction == "x" else (ys, xs)
    check_gouge(rf, pr, rr, offset, surface.grid.source, uf)
    p, r, z = var("p"), var("r"), var("z")
    zp, zr, q = var("zp"), var("zr"), var("q")
    row_code = tuple(row_statements(rf, r, slopes=True))
    point_code = tuple(point_statements(rf, p, z, slopes=True)) + (
        Assign(q, add(add(mul(zp, zp), mul(zr, zr)), const(1))),
        Assign(q, div(const(exact(offset)), sqrt(q))),
        Assign(var("pt"), sub(p, mul(q, zp))),
        Assign(var("rt"), sub(r, mul(q, zr))),
        Assign(var("zt"), sub(add(z, q), const(exact(radius)))),
    )
    outputs = ("pt", "rt", "zt")
    p0, r0, z0 = offset_points(rf, radius, offset, np.array([float(plan.points.start)]),
                               np.array([float(plan.rows.start)]))
    start = (float(p0[0]), float(r0[0]), float(z0[0]))
    if plan.direction == "y":
        start = (start[1], start[0], start[2])
    return MacroPlan(body=loop_plan(plan, rf, row_code, point_code, outputs), raster=plan, form=rf, start=start,
                     row_code=row_code, point_code=point_code, outputs=outputs,
                     ball_radius=radius, ball_offset=offset)


def tip_points(surface: LagrangeSurface, settings: MachineSettings, tool: Tool, x, y) -> np.ndarray:
    """The tool-tip points (N, 3) of a ball-end cutter in contact at raster positions (x, y), program units."""
    rf = row_form(surface, _no_stock(settings), "x")
    uf = settings.unit_factor
    px, py, pz = offset_points(rf, tool.radius_mm * uf, (tool.radius_mm + settings.stock_to_leave_mm) * uf, x, y)
    return np.column_stack([px, py, pz])
