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
           "check_gouge", "check_gouge_over", "tightest_concave", "concave_message", "checked_tip_lift", "ball_tips", "tip_points", "derivatives"]

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


def _curvature(form: RowForm, p, r):
    """The larger principal curvature of ``Z(P, R)`` (positive where concave seen from the tool), and ``|grad|**2``."""
    f = derivatives(form, p, r)
    fx, fy, fxx, fxy, fyy = f["zp"], f["zr"], f["zpp"], f["zpr"], f["zrr"]
    g = 1.0 + fx**2 + fy**2
    mean = ((1 + fx**2) * fyy - 2 * fx * fy * fxy + (1 + fy**2) * fxx) / (2 * g**1.5)
    gauss = (fxx * fyy - fxy**2) / g**2
    return mean + np.sqrt(np.maximum(mean**2 - gauss, 0.0)), g - 1.0


_CANDIDATES = 16  # the highest samples refined: the tightest hollow may lie between samples near any of them
_ROUNDS = 16  # each round a 9 x 9 lattice a third the size of the last: the maximum to 1e-7 of a sample spacing


def tightest_concave(form: RowForm, p, r) -> tuple[float, float, float]:
    """The largest principal curvature over the box the positions (p, r) span, and where: ``(k, p, r)``.

    The samples are a lattice; the tightest hollow usually lies between
    them, so the largest curvature is refined around the highest samples by
    zooming lattices (clamped to the box) until it is known to about 1e-7 of
    a sample spacing.  The result is at least the samples' largest, so a
    ball it allows is never larger than the surface allows at the samples.
    """
    p, r = np.asarray(p, float).ravel(), np.asarray(r, float).ravel()
    k, _ = _curvature(form, p, r)
    lo, hi = (float(p.min()), float(r.min())), (float(p.max()), float(r.max()))
    side = max(int(np.sqrt(p.size)) - 1, 1)
    step = 2.0 * max(hi[0] - lo[0], hi[1] - lo[1]) / side
    best = (float(k.max()), float(p[k.argmax()]), float(r[k.argmax()]))
    for i in np.argsort(k)[::-1][:_CANDIDATES]:
        cp, cr, h = float(p[i]), float(r[i]), step
        for _ in range(_ROUNDS):
            g = np.linspace(-h, h, 9)
            gp, gr = np.meshgrid(np.clip(cp + g, lo[0], hi[0]), np.clip(cr + g, lo[1], hi[1]))
            kk, _ = _curvature(form, gp.ravel(), gr.ravel())
            j = int(np.argmax(kk))
            cp, cr, h = float(gp.ravel()[j]), float(gr.ravel()[j]), h / 3.0
            if kk[j] > best[0]:
                best = (float(kk[j]), cp, cr)
    return best


def _down(v: float, decimals: int) -> float:
    """``v`` rounded down to ``decimals``: a limit stated from the safe side."""
    return float(np.floor(v * 10.0**decimals + 1e-9) / 10.0**decimals)


def concave_message(rc: float, offset: float, stock: float, at: tuple[float, float], source: str) -> str:
    """The refusal of a ball whose offset ``offset`` (mm, radius plus ``stock``) exceeds the radius ``rc`` (mm).

    Every figure is rounded down (the radius of curvature, the largest ball
    allowed, ``2 (rc - stock)``), with as many decimals as it takes for none
    to read as the refused value: never "2.6 below 2.6".

    Examples
    --------
    >>> concave_message(2.5971099, 2.6, 0.0, (100.0, 20.19), "ex4.json")  # doctest: +NORMALIZE_WHITESPACE
    'ex4.json: the surface is concave with a radius of curvature of 2.5971 mm near (100.000, 20.190) mm, below the
    offset radius 2.6 mm (ball radius plus stock): an offset along the normal would gouge there; use a ball of
    diameter at most 5.194 mm, or the point-list toolpath (lagsym toolpath, drop-cutter)'
    >>> m = concave_message(2.599999, 2.6, 0.0, (0.0, 0.0), "s")  # not "2.6 mm, below the offset radius 2.6 mm"
    >>> "curvature of 2.5999 mm" in m and "at most 5.199 mm" in m
    True
    """
    refused = 2.0 * (offset - stock)
    for d in range(4, 10):
        shown, ball = _down(rc, d), _down(2.0 * (rc - stock), d - 1)
        if shown < round(offset, d) and ball < round(refused, d):
            break
    ball_text = (f"use a ball of diameter at most {ball:.{d - 1}f} mm, or" if rc > stock
                 else f"no ball fits with stock {stock:g} mm; use")
    return (f"{source}: the surface is concave with a radius of curvature of {shown:.{d}f} mm near "
            f"({at[0]:.3f}, {at[1]:.3f}) mm, below the offset radius {offset:g} mm (ball radius plus stock): "
            f"an offset along the normal would gouge there; {ball_text} the point-list toolpath "
            "(lagsym toolpath, drop-cutter)")


def check_gouge(form: RowForm, p, r, radius: float, source: str = "<surface>", unit: float = 1.0, *,
                stock: float = 0.0):
    """Refuse a normal offset where the surface is concave tighter than the ball (radius in program units).

    The larger principal curvature of the graph ``Z(P, R)`` (positive where the
    surface is concave, seen from the tool) is checked at every point (p, r)
    and, between them, at its largest over the box they span
    (:func:`tightest_concave`).  ``radius`` is the offset, the ball's radius
    plus ``stock`` (both in program units); the refusal states the largest
    ball that fits, ``2 (rc - stock)``, rounded down (:func:`concave_message`).
    Returns the curvature at the points, and ``Zp**2 + Zr**2`` there.
    """
    kmax, slopes_sq = _curvature(form, np.asarray(p, float), np.asarray(r, float))
    k, pp, rr = tightest_concave(form, p, r)
    if k * radius > 1.0:
        raise ToolpathError(concave_message(1.0 / k / unit, radius / unit, stock / unit, (pp / unit, rr / unit),
                                            source))
    return kmax, slopes_sq


def check_gouge_over(form: RowForm, raster: MacroRaster, offset: float, source: str, unit: float, *,
                     stock: float = 0.0):
    """:func:`check_gouge` over the raster: every position, or 1001 x 1001 of them evenly spread, and between."""
    xs, ys = sample_positions(raster, 1001)
    p, r = (xs, ys) if raster.direction == "x" else (ys, xs)
    return check_gouge(form, p, r, offset, source, unit, stock=stock)


def checked_tip_lift(form: RowForm, raster: MacroRaster, offset: float, resolution: Fraction, source: str = "<surface>",
                     unit: float = 1.0, *, stock: float = 0.0) -> Fraction:
    """:func:`check_gouge_over`, then the lift of the rounded tips (:func:`lagsym.macro.rounding.tip_lift`)."""
    kmax, slopes_sq = check_gouge_over(form, raster, offset, source, unit, stock=stock)
    return tip_lift(kmax, slopes_sq, offset, resolution) if resolution else Fraction(0)


def tip_points(surface: LagrangeSurface, settings: MachineSettings, tool: Tool, x, y) -> np.ndarray:
    """The tool-tip points (N, 3) of a ball-end cutter in contact at raster positions (x, y), program units."""
    radius, offset = ball_offsets(settings, tool)
    px, py, pz = offset_points(contact_form(surface, settings, "x"), radius, offset, x, y)
    return np.column_stack([px, py, pz])
