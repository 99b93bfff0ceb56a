"""Positions rounded on the control before the height is computed there, and the matching model on the PC.

A control goes to X and Y at its input resolution, not to the value a macro
computes: a Fanuc rounds a variable used as an axis address to the least
input increment.  On a steep surface the height computed at the unrounded
position is then not the height at the position the tool reaches.  Where the
macro language has ``ROUND`` (Fanuc Custom Macro B, LinuxCNC), the program
rounds every X and Y to the program's last decimal itself, ``ROUND[p*S]/S``
with ``S = 10**decimals``, and computes Z there:

* a point on the surface (tool diameter 0): the row position and the point
  position are rounded, then the surface is evaluated at them;
* a ball end: the tip, one radius off the surface along its normal, is
  rounded, and its height moved along the tangent plane of the tip's path to
  the rounded position, ``Z' + Zp dP + Zr dR`` (the tip's path has the
  surface's slopes at the contact point), plus a bound of that plane's error
  over the half unit moved, ``c dmax**2 / 2`` with ``c`` the largest upward
  bend of the tip's path over the raster (rounded up to a thousandth of a unit).

Z is then raised by half a unit, so that a control rounding it to the
nearest unit still goes at or above it.

Heidenhain FN arithmetic has no rounding function: the TNC 355 and TNC 2500
era controls of Bridgeport Interact mills offer ``FN 0``-``FN 14`` (assign,
the four operations, square root, sine, cosine, root of a sum of squares,
four conditional jumps, an angle from two sides, an error number), and none
of them gives a whole number (``INT`` and the formula entry came with later
TNCs).  So the program cannot compute Z at the position the control will go
to; instead every Z is raised by a proved bound of how much the height can
change between the computed position and the one reached
(:func:`slope_lift`).  The TNC takes a position at its resolution, the
program's last decimal, rounding or truncating: X, Y and Z each move by less
than one unit ``u``.  The programmed height is a function of the position
whose slopes are the surface's own (for a ball end, the tip's height over the
tip position has the slopes of the surface at the contact point), so by the
mean value theorem it changes by at most ``(Lx + Ly) u`` with ``Lx`` and
``Ly`` bounds of ``|F_x|`` and ``|F_y|`` over the box: the largest on a
257 x 257 grid plus how much they can grow between its nodes, from bounds of
the second partials (the sums of their absolute Chebyshev coefficients: every
``|T_i T_j|`` is at most 1 there).  Z is raised by ``(1 + Lx + Ly) u``,
rounded up to a thousandth of a unit, which also covers Z itself.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from ..controls import CONTROLS
from ..machine import MachineSettings
from .model import Assign, Var, add, const, div, mul, round_, sub, var

__all__ = ["ROUNDING_DIALECTS", "resolution", "slope_lift", "round_statement", "round_half_away", "tip_statements",
           "tips_on_grid", "tip_lift"]

ROUNDING_DIALECTS = tuple(c.name for c in CONTROLS.values() if c.macro is not None and c.macro.rounds)
"""The controls whose macro language has ``ROUND[..]`` (:attr:`lagsym.controls.MacroLanguage.rounds`)."""


def _rounds(settings: MachineSettings) -> bool:
    macro = settings.control.macro
    return macro is not None and macro.rounds


def resolution(settings: MachineSettings) -> Fraction:
    """One unit of the program's last decimal where the control rounds positions itself, else 0."""
    if not _rounds(settings):
        return Fraction(0)
    return Fraction(1, 10 ** settings.digits)


def slope_lift(surface, settings: MachineSettings) -> Fraction:
    """For a control that cannot round (Heidenhain FN): the proved raise of Z, ``(1 + Lx + Ly) u``, exact.

    0 where the macro rounds on the control (:data:`ROUNDING_DIALECTS`).  See
    the module docstring for the bound.

    Examples
    --------
    >>> from lagsym.grid import grid_from_points
    >>> from lagsym.lagrange import lagrange_surface
    >>> s = lagrange_surface(grid_from_points([(0, 0, 0), (0, 1, 0), (1, 0, 2), (1, 1, 2)]))  # z = 2 x
    >>> slope_lift(s, MachineSettings(dialect="heidenhain"))
    Fraction(3, 1000)
    """
    if _rounds(settings):
        return Fraction(0)
    from ..evaluate import surface_evaluator

    slopes = sum(_slope_bounds(surface_evaluator(surface)))
    unit = Fraction(1, 10 ** settings.digits)
    step = unit / 1000
    # 1e-12 of the slopes for the coefficients' float rounding; a millionth of a step (1e-9 of a unit) keeps a
    # whole number whole.
    return step * math.ceil((1.0 + slopes * (1 + 1e-12)) * 1000 - 1e-6)


def _slope_bounds(ev, samples: int = 257) -> tuple[float, float]:
    """Proved bounds of ``|F_x|`` and ``|F_y|`` over the box: the largest on a grid plus how far they can grow off it.

    Between grid nodes ``hx``, ``hy`` apart a point is within ``hx / 2`` and
    ``hy / 2`` of one, where ``F_x`` differs by at most ``Bxx hx / 2 + Bxy hy / 2``,
    with ``B`` the sums of the absolute Chebyshev coefficients of the second
    partials (bounds of them over the box, as every ``|T_i T_j| <= 1`` there).
    """
    from numpy.polynomial import chebyshev as C

    x0, x1, y0, y1 = (float(v) for v in ev.bounds)
    hx, hy = (x1 - x0) / (samples - 1), (y1 - y0) / (samples - 1)
    u = np.linspace(-1.0, 1.0, samples)
    b = {d: float(np.abs(ev.partial(*d)).sum()) for d in ((2, 0), (1, 1), (0, 2))}
    lx = float(np.abs(C.chebgrid2d(u, u, ev.partial(1, 0))).max()) + (b[2, 0] * hx + b[1, 1] * hy) / 2
    ly = float(np.abs(C.chebgrid2d(u, u, ev.partial(0, 1))).max()) + (b[1, 1] * hx + b[0, 2] * hy) / 2
    return lx, ly


def round_statement(v: Var, unit: Fraction, target: Var | None = None) -> Assign:
    """``target = ROUND[v*S]/S``: ``v`` to the nearest multiple of ``unit`` (into ``v`` itself by default)."""
    s = const(1 / unit)
    return Assign(v if target is None else target, div(round_(mul(v, s)), s))


def round_half_away(x: np.ndarray, unit: float) -> np.ndarray:
    """``x`` to the nearest multiple of ``unit``, halves away from zero, as ``ROUND[x*S]/S`` on the control."""
    v = np.asarray(x, dtype=float) / unit
    return np.sign(v) * np.floor(np.abs(v) + 0.5) * unit


def tip_statements(unit: Fraction, lift: Fraction) -> tuple:
    """After the tip ``(pt, rt, zt)``: the tip rounded, its height moved along the tangent plane and lifted."""
    pt, rt, zt, zp, zr, q = var("pt"), var("rt"), var("zt"), var("zp"), var("zr"), var("q")
    out = [Assign(zt, add(zt, const(lift)))]
    for v, slope in ((pt, zp), (rt, zr)):
        out += [round_statement(v, unit, q), Assign(zt, add(zt, mul(slope, sub(q, v)))), Assign(v, q)]
    return tuple(out)


def tips_on_grid(pt, rt, zt, zp, zr, *, unit: float, lift: float):
    """The PC's model of :func:`tip_statements`: rounded tip positions and their heights (floats)."""
    pr, rr = round_half_away(pt, unit), round_half_away(rt, unit)
    return pr, rr, np.asarray(zt) + lift + zp * (pr - pt) + zr * (rr - rt)


def tip_lift(kmax: np.ndarray, slopes_sq: np.ndarray, offset: float, unit: Fraction) -> Fraction:
    """Half a unit plus the bound of the tangent plane's error over the rounding, as an exact constant.

    ``kmax`` is the surface's larger principal curvature at the raster
    positions (positive where it is concave, seen from the tool) and
    ``slopes_sq`` is ``Zp**2 + Zr**2`` there.  The tip's path bends up by at
    most ``k / (1 - offset k)`` along the surface, so by at most that times
    ``w**3`` per horizontal unit squared, ``w = sqrt(1 + Zp**2 + Zr**2)``;
    over the rounding's horizontal move of at most ``unit / sqrt(2)`` the
    plane's error is below half that times ``unit**2 / 2``.
    """
    k = np.maximum(np.asarray(kmax, dtype=float), 0.0)
    bend = k / np.maximum(1.0 - offset * k, 1e-12) * (1.0 + np.asarray(slopes_sq)) ** 1.5
    c2 = 0.5 * float(bend.max(initial=0.0)) * float(unit) ** 2 / 2.0
    step = unit / 1000  # the bound rounded up to a thousandth of a unit
    return unit / 2 + step * math.ceil(c2 / float(step))
