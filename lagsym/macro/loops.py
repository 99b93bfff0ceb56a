"""The loops every dialect renders: counted rows and points around the statements of the height.

.. code-block:: text

    j = 0; d = 0
    while j <= NR:                       rows, counted
        r = R0 + j*DR; clamp r to R1
        v, g0 .. g(n-1) from r           once per row
        i = 0
        while i <= NP:                   points, counted
            k = i + d*(NP - 2*i)         zig-zag: reversed rows visit the same positions
            p = P0 + k*DP; clamp p to P1
            u, z from p and g            once per point
            G1 to (p, r, z)
            i = i + 1
        d = 1 - d
        j = j + 1

so positions are always ``start + count * step`` and never drift.  For a
ball-end cutter the point statements go on to the slopes and the tool tip
(:mod:`lagsym.macro.ballend`), and the move goes to the tip.  Where the
macro language has ``ROUND``, the positions moved to are rounded to the
program's last decimal before their height is computed, and the height is
raised by half a unit (:mod:`lagsym.macro.rounding`).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from ..lagrange import LagrangeSurface, horner2
from ..machine import MachineSettings, RasterSpec, Tool
from .ballend import TIP_OUTPUTS, ball_offsets, ball_tips, checked_tip_lift, contact_form, is_ball, offset_points, \
    offset_statements, refuse_flat_end
from .form import RowForm, point_statements, row_form, row_statements
from .model import Assign, Clamp, Loop, Move, add, const, mul, sub, var
from .raster import MacroRaster, macro_raster
from .rounding import resolution, round_statement, slope_lift, tip_statements

__all__ = ["MacroLoops", "macro_loops", "zigzag_loops", "exact_height"]


@dataclass(frozen=True)
class MacroLoops:
    """What every dialect renders: the statements, the raster, the form and the first point.

    Attributes
    ----------
    body : tuple
        The loop statements (see the module docstring).
    raster : MacroRaster
        The counted raster, in program units.
    form : RowForm
        The normalized form the statements evaluate.
    start : tuple
        The first programmed point (X, Y, Z), for the rapid approach and the plunge.
    row_code, point_code : tuple
        The straight-line statements run once per row (from ``r``) and once per
        point (from ``p``); :func:`~lagsym.macro.accuracy.predicted_error` runs them on the PC.
    finish_code : tuple
        Run after ``point_code``: the tip rounded to the program's resolution
        and the height raised by half a unit (see :mod:`lagsym.macro.rounding`).
    outputs : tuple of str
        The variables moved to, in the order (P, R, Z): along the row, across, height.
    ball_radius, ball_offset : float
        For a ball-end cutter, its radius and the distance of its centre from the
        surface (radius plus stock), in program units; 0 for a point on the surface.
    resolution, tip_lift : Fraction
        The unit positions are rounded to on the control (0: not rounded), and
        what a rounded tip's height is raised by.
    title : str
        The program's name in its first comment.
    slope_lift : Fraction
        Where the control cannot round (Heidenhain), what every height is
        raised by instead (:func:`~lagsym.macro.rounding.slope_lift`); 0 elsewhere.
    """

    body: tuple
    raster: MacroRaster
    form: RowForm
    start: tuple
    row_code: tuple = ()
    point_code: tuple = ()
    finish_code: tuple = ()
    outputs: tuple[str, str, str] = ("p", "r", "z")
    ball_radius: float = 0.0
    ball_offset: float = 0.0
    resolution: Fraction = Fraction(0)
    tip_lift: Fraction = Fraction(0)
    title: str = "LAGSYM SURFACE MACRO"
    slope_lift: Fraction = Fraction(0)

    def reference(self, p: Fraction, r: Fraction) -> tuple:
        """The point (P, R, Z) the program should reach at raster position (p, r), computed on the PC.

        Exact rationals for a point on the surface; for a ball-end cutter, floats
        from the stable evaluation of the exact derivatives.
        """
        if not self.ball_radius:
            return p, r, exact_height(self.form, p, r)
        pt, rt, zt = offset_points(self.form, self.ball_radius, self.ball_offset,
                                   np.array([float(p)]), np.array([float(r)]))
        return float(pt[0]), float(rt[0]), float(zt[0])


def exact_height(form: RowForm, p: Fraction, r: Fraction) -> Fraction:
    """The height of ``form`` at raster position (p, r), exact."""
    return horner2(form.coefficients, (p - form.pc) * form.pk, (r - form.rc) * form.rk) + form.z0


def zigzag_loops(raster: MacroRaster, row_code, point_code, outputs=("p", "r", "z"), finish_code=()) -> tuple:
    """The counted zig-zag loops around the per-row and per-point statements (see the module docstring)."""
    rows, pts = raster.rows, raster.points
    j, d, i, k, t = var("j"), var("d"), var("i"), var("k"), var("t")
    r, p = var("r"), var("p")
    mp, mr, mz = (var(n) for n in outputs)
    point_body = [
        Assign(t, sub(const(pts.count), mul(const(2), i))),
        Assign(k, add(i, mul(d, t))),
        Assign(p, add(const(pts.start), mul(k, const(pts.step)))),
        Clamp(p, const(pts.end)),
        *point_code,
        *finish_code,
        Move(mp, mr, mz) if raster.direction == "x" else Move(mr, mp, mz),
    ]
    row_body = [
        Assign(r, add(const(rows.start), mul(j, const(rows.step)))),
        Clamp(r, const(rows.end)),
        *row_code,
        Loop(i, pts.count, tuple(point_body)),
        Assign(d, sub(const(1), d)),
    ]
    return (Assign(d, const(0)), Loop(j, rows.count, tuple(row_body)))


def _in_xyz(raster: MacroRaster, p, r, z) -> tuple:
    return (p, r, z) if raster.direction == "x" else (r, p, z)


def macro_loops(surface: LagrangeSurface, settings: MachineSettings, raster: RasterSpec,
                tool: Tool | None = None, form: str = "horner") -> MacroLoops:
    """The loops for ``surface``: counted rows and points and the statements of the height (``form``).

    A ball-end ``tool`` with a diameter gets the normal offset of :mod:`lagsym.macro.ballend`;
    a zero diameter programs the surface itself.  A flat end with a diameter is
    refused (:func:`~lagsym.macro.ballend.refuse_flat_end`).
    """
    refuse_flat_end(tool)
    counted = macro_raster(surface, settings, raster)
    if is_ball(tool):
        return _ball_loops(surface, settings, counted, tool, form)
    rf = row_form(surface, settings, counted.direction, form)
    unit = resolution(settings)
    rounding = (round_statement(var("r"), unit),) if unit else ()
    row_code = rounding + tuple(row_statements(rf, var("r")))
    point_code = ((round_statement(var("p"), unit),) if unit else ()) + tuple(point_statements(rf, var("p"), var("z")))
    lift = unit / 2 if unit else slope_lift(surface, settings)
    finish = (Assign(var("z"), add(var("z"), const(lift))),) if lift else ()
    p0, r0 = counted.points.start, counted.rows.start
    return MacroLoops(body=zigzag_loops(counted, row_code, point_code, finish_code=finish), raster=counted, form=rf,
                      start=_in_xyz(counted, p0, r0, exact_height(rf, p0, r0) + lift),
                      row_code=row_code, point_code=point_code, finish_code=finish, resolution=unit,
                      slope_lift=Fraction(0) if unit else lift)


def _ball_loops(surface: LagrangeSurface, settings: MachineSettings, counted: MacroRaster, tool: Tool,
                form: str) -> MacroLoops:
    """The loops for a ball-end cutter: height, exact slopes and the normal offset on the control."""
    rf = contact_form(surface, settings, counted.direction, form)
    radius, offset = ball_offsets(settings, tool)
    unit = resolution(settings)
    lift = checked_tip_lift(rf, counted, offset, unit, surface.grid.source, settings.unit_factor, stock=offset - radius)
    row_code = tuple(row_statements(rf, var("r"), slopes=True))
    point_code = tuple(point_statements(rf, var("p"), var("z"), slopes=True)) + offset_statements(radius, offset)
    raise_z = Fraction(0) if unit else slope_lift(surface, settings)
    finish = tip_statements(unit, lift) if unit else (
        (Assign(var("zt"), add(var("zt"), const(raise_z))),) if raise_z else ())
    p0, r0, z0 = ball_tips(rf, radius, offset, np.array([float(counted.points.start)]),
                           np.array([float(counted.rows.start)]), resolution=unit, lift=lift)
    z0 = z0 + float(raise_z)
    return MacroLoops(body=zigzag_loops(counted, row_code, point_code, TIP_OUTPUTS, finish), raster=counted, form=rf,
                      start=_in_xyz(counted, float(p0[0]), float(r0[0]), float(z0[0])),
                      row_code=row_code, point_code=point_code, finish_code=finish, outputs=TIP_OUTPUTS,
                      ball_radius=radius, ball_offset=offset, resolution=unit, tip_lift=lift, slope_lift=raise_z)
