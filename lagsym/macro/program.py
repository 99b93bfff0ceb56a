"""Macro programs: the loop plan shared by every dialect, the arithmetic check, and the finished program.

:func:`macro_program` is the one entry point: surface, machine settings,
raster and tool in; a :class:`MacroProgram` (text plus what was predicted
about it) out.  The loop plan is

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

so positions are always ``start + count * step`` and never drift.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from decimal import Decimal
from fractions import Fraction

import numpy as np

from ..errors import ProgramError, ToolpathError
from ..lagrange import LagrangeSurface, horner2
from ..machine import MachineSettings, RasterSpec, Tool
from ..values import choice
from .form import FORMS, RowForm, point_statements, row_form, row_statements
from .model import Assign, Clamp, Loop, Move, add, const, decimal_context, mul, run, sub, var
from .plan import MacroRaster, macro_raster, points_at, sample_positions

__all__ = ["MACRO_DIALECTS", "PRECISIONS", "DEFAULT_PRECISION", "DEFAULT_FORM", "MacroPlan", "MacroProgram",
           "macro_plan", "macro_program", "predicted_error", "exact_height", "loop_plan"]

MACRO_DIALECTS = ("fanuc", "linuxcnc", "heidenhain")
PRECISIONS = (8, 15)
DEFAULT_PRECISION = {"fanuc": 8, "linuxcnc": 15, "heidenhain": 8}
DEFAULT_FORM = {8: "lagrange", 15: "horner"}


@dataclass(frozen=True)
class MacroPlan:
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
        point (from ``p``); :func:`predicted_error` runs them on the PC.
    outputs : tuple of str
        The variables moved to, in the order (P, R, Z): along the row, across, height.
    ball_radius, ball_offset : float
        For a ball-end cutter, its radius and the distance of its centre from the
        surface (radius plus stock), in program units; 0 for a point on the surface.
    """

    body: tuple
    raster: MacroRaster
    form: RowForm
    start: tuple
    row_code: tuple = ()
    point_code: tuple = ()
    outputs: tuple[str, str, str] = ("p", "r", "z")
    ball_radius: float = 0.0
    ball_offset: float = 0.0

    def reference(self, p: Fraction, r: Fraction) -> tuple:
        """The point (P, R, Z) the program should reach at raster position (p, r), computed on the PC.

        Exact rationals for a point on the surface; for a ball-end cutter, floats
        from the stable evaluation of the exact derivatives.
        """
        if not self.ball_radius:
            return p, r, exact_height(self.form, p, r)
        from .ballend import offset_points

        pt, rt, zt = offset_points(self.form, self.ball_radius, self.ball_offset,
                                   np.array([float(p)]), np.array([float(r)]))
        return float(pt[0]), float(rt[0]), float(zt[0])


def exact_height(form: RowForm, p: Fraction, r: Fraction) -> Fraction:
    """The height of ``form`` at raster position (p, r), exact."""
    return horner2(form.coefficients, (p - form.pc) * form.pk, (r - form.rc) * form.rk) + form.z0


def loop_plan(plan: MacroRaster, form: RowForm, row_code, point_code, outputs=("p", "r", "z")) -> tuple:
    """The counted zig-zag loops around the per-row and per-point statements (see the module docstring)."""
    rows, pts = plan.rows, plan.points
    j, d, i, k, t = var("j"), var("d"), var("i"), var("k"), var("t")
    r, p = var("r"), var("p")
    mp, mr, mz = (var(n) for n in outputs)
    point_body = [
        Assign(t, sub(const(pts.count), mul(const(2), i))),
        Assign(k, add(i, mul(d, t))),
        Assign(p, add(const(pts.start), mul(k, const(pts.step)))),
        Clamp(p, const(pts.end)),
        *point_code,
        Move(mp, mr, mz) if plan.direction == "x" else Move(mr, mp, mz),
    ]
    row_body = [
        Assign(r, add(const(rows.start), mul(j, const(rows.step)))),
        Clamp(r, const(rows.end)),
        *row_code,
        Loop(i, pts.count, tuple(point_body)),
        Assign(d, sub(const(1), d)),
    ]
    return (Assign(d, const(0)), Loop(j, rows.count, tuple(row_body)))


def macro_plan(surface: LagrangeSurface, settings: MachineSettings, raster: RasterSpec,
               tool: Tool | None = None, form: str = "horner") -> MacroPlan:
    """The loop plan for ``surface``: counted rows and points and the statements of the height (``form``).

    A ball-end ``tool`` with a diameter gets the normal offset of :mod:`lagsym.macro.ballend`.
    """
    if tool is not None and tool.shape == "ball" and tool.diameter_mm > 0:
        from .ballend import ballend_plan

        return ballend_plan(surface, settings, raster, tool, form)
    plan = macro_raster(surface, settings, raster)
    rf = row_form(surface, settings, plan.direction, form)
    row_code = tuple(row_statements(rf, var("r")))
    point_code = tuple(point_statements(rf, var("p"), var("z")))
    z0 = exact_height(rf, plan.points.start, plan.rows.start)
    p0, r0 = plan.points.start, plan.rows.start
    start = (p0, r0, z0) if plan.direction == "x" else (r0, p0, z0)
    return MacroPlan(body=loop_plan(plan, rf, row_code, point_code), raster=plan, form=rf, start=start,
                     row_code=row_code, point_code=point_code)


def _spread(lo: int, hi: int, limit: int) -> list[int]:
    """Up to ``limit`` indices from ``lo`` to ``hi`` inclusive, evenly spread, ends included."""
    return sorted(set(np.linspace(lo, hi, min(hi - lo + 1, limit)).round().astype(int).tolist()))


def _errors(plan: MacroPlan, ctx, row_ks, point_ks) -> dict[tuple[int, int], Fraction]:
    """Error at each raster index pair (row, point): the control's arithmetic against the reference."""
    rows, pts = plan.raster.rows, plan.raster.points
    out = {}
    for kr in row_ks:
        env = run(plan.row_code, {"r": _decimal(min(rows.start + kr * rows.step, rows.end), ctx)}, ctx)
        for kp in point_ks:
            env["p"] = _decimal(min(pts.start + kp * pts.step, pts.end), ctx)
            run(plan.point_code, env, ctx)
            ref = plan.reference(Fraction(env["p"]), Fraction(env["r"]))
            out[kr, kp] = max(abs(Fraction(env[name]) - Fraction(want)) for name, want in zip(plan.outputs, ref))
    return out


def predicted_error(plan: MacroPlan, precision: int, rows: int = 25, points: int = 41) -> float:
    """Largest difference between the control's arithmetic and the PC's over the raster, by sampling.

    The row and point statements of ``plan`` are run in decimal arithmetic
    with ``precision`` significant digits, rounding after every operation, at
    up to ``rows`` x ``points`` raster positions (always including the edges),
    and compared with :meth:`MacroPlan.reference`.  The error varies quickly
    between the nodes, so the neighbourhoods of the four worst samples are then
    searched at the raster's own spacing.  Returns the largest coordinate
    difference found, in program units.
    """
    ctx = decimal_context(precision)
    nr, np_ = plan.raster.rows.count, plan.raster.points.count
    row_ks, point_ks = _spread(0, nr, rows), _spread(0, np_, points)
    found = _errors(plan, ctx, row_ks, point_ks)
    dr, dp = max(nr // max(rows - 1, 1), 1), max(np_ // max(points - 1, 1), 1)
    for kr, kp in sorted(found, key=found.get, reverse=True)[:4]:
        near = _errors(plan, ctx, _spread(max(kr - dr, 0), min(kr + dr, nr), 9),
                       _spread(max(kp - dp, 0), min(kp + dp, np_), 13))
        found.update(near)
    return float(max(found.values()))


def _decimal(v: Fraction, ctx) -> Decimal:
    return ctx.divide(Decimal(v.numerator), Decimal(v.denominator))


def _check_clearance(surface, settings, raster, tool, plan: MacroPlan) -> None:
    """The rapid moves at the safe height must clear the highest point the tool tip reaches.

    Checked over the raster positions (up to 401 x 401 of them, evenly spread),
    with 1 % of the height range as margin for what lies between them.
    """
    uf = settings.unit_factor
    z = points_at(surface, settings, tool, *sample_positions(plan.raster))[:, 2]
    top = (float(z.max()) + 0.01 * float(np.ptp(z))) / uf
    if settings.safe_z_mm <= top:
        raise ToolpathError(f"safe Z {settings.safe_z_mm:g} mm is not above the highest point of the path, "
                            f"{float(z.max()) / uf:.3f} mm: the rapid moves would hit the part; raise --safe-z")


@dataclass(frozen=True)
class MacroProgram:
    """A finished macro program.

    Attributes
    ----------
    text : str
        The program, with the machine's line endings.
    dialect : str
        ``fanuc``, ``linuxcnc`` or ``heidenhain``.
    precision : int
        Significant digits of the control's arithmetic the program was checked for.
    predicted_error : float
        Largest arithmetic error predicted at that precision, in program units.
    plan : MacroPlan
        The loops and form the text renders.
    """

    text: str
    dialect: str
    precision: int
    predicted_error: float
    plan: MacroPlan = field(repr=False)

    @property
    def size(self) -> int:
        """Size in bytes (characters; programs are ASCII)."""
        return len(self.text.encode("ascii"))


def macro_program(surface: LagrangeSurface, settings: MachineSettings, raster: RasterSpec,
                  tool: Tool | None = None, *, precision: int | None = None, tolerance_mm: float = 0.001,
                  variable_base: int | None = None, form: str | None = None) -> MacroProgram:
    """A parametric program that evaluates ``surface`` on the control while it cuts the raster.

    Parameters
    ----------
    surface : LagrangeSurface
        The exact surface.
    settings : MachineSettings
        Dialect (``fanuc``, ``linuxcnc`` or ``heidenhain``), scale, origin, feeds, program number.
    raster : RasterSpec
        Direction, side step and forward step (both fixed).
    tool : Tool, optional
        The cutter; a ball-end cutter with a diameter is offset along the surface normal.
    precision : int, optional
        Significant digits of the control's arithmetic, 8 or 15; by default 8 for
        Fanuc and Heidenhain, 15 for LinuxCNC.
    tolerance_mm : float
        Largest arithmetic error accepted; a program predicted to exceed it is refused.
    variable_base : int, optional
        First variable number (Fanuc ``#100`` or ``#500``, Heidenhain ``Q1``).
    form : str, optional
        ``"horner"`` (shortest) or ``"lagrange"`` (tensor-product basis, the most
        accurate); by default Lagrange for 8 digits and Horner for 15.

    Raises
    ------
    ProgramError
        If the predicted error exceeds ``tolerance_mm`` or the variables do not fit.
    """
    dialect = choice(settings.dialect, MACRO_DIALECTS, "macro dialect")
    precision = DEFAULT_PRECISION[dialect] if precision is None else int(precision)
    if precision not in PRECISIONS:
        raise ProgramError(f"precision {precision} is not one of {', '.join(map(str, PRECISIONS))} significant digits")
    form = DEFAULT_FORM[precision] if form is None else choice(form, FORMS, "form")
    plan = macro_plan(surface, settings, raster, tool, form)
    _check_clearance(surface, settings, raster, tool, plan)
    err = predicted_error(plan, precision) / settings.unit_factor
    if err > tolerance_mm:
        raise ProgramError(
            f"{surface.grid.source}: a {surface.grid.shape[0]}x{surface.grid.shape[1]} surface evaluated with "
            f"{precision} significant digits in the {form} form is predicted to be off by {err:.3g} mm, "
            f"more than the tolerance {tolerance_mm:g} mm; use a control with 15-digit arithmetic "
            f"(--precision 15){', the lagrange form' if form == 'horner' else ''}, fewer control points, "
            f"or the point-list toolpath")
    module = importlib.import_module(f"{__package__}.{dialect}")
    text = module.render(plan, settings, precision=precision, variable_base=variable_base)
    return MacroProgram(text=text, dialect=dialect, precision=precision, predicted_error=err, plan=plan)
