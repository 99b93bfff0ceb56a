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
from fractions import Fraction

import numpy as np

from ..errors import ProgramError
from ..lagrange import LagrangeSurface
from ..machine import MachineSettings, RasterSpec, Tool, choice
from .form import FORMS, RowForm, point_statements, row_form, row_statements
from .model import Assign, Clamp, Loop, Move, add, const, decimal_context, mul, run, sub, var
from .plan import MacroRaster, exact, macro_raster

__all__ = ["MACRO_DIALECTS", "PRECISIONS", "DEFAULT_PRECISION", "DEFAULT_FORM", "MacroPlan", "MacroProgram",
           "macro_plan", "macro_program", "predicted_error"]

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
        The normalized Horner form the statements evaluate.
    start : tuple of Fraction
        The first point (X, Y, Z), exact, for the rapid approach and the plunge.
    """

    body: tuple
    raster: MacroRaster
    form: RowForm
    start: tuple[Fraction, Fraction, Fraction]
    tool: Tool | None = None


def _exact_z(form: RowForm, p: Fraction, r: Fraction) -> Fraction:
    u, v = (p - form.pc) * form.pk, (r - form.rc) * form.rk
    acc = Fraction(0)
    for row in reversed(form.coefficients):
        inner = Fraction(0)
        for c in reversed(row):
            inner = inner * v + c
        acc = acc * u + inner
    return acc + form.z0


def macro_plan(surface: LagrangeSurface, settings: MachineSettings, raster: RasterSpec,
               tool: Tool | None = None, form: str = "horner") -> MacroPlan:
    """The loop plan for ``surface``: counted rows and points and the statements of the height (``form``)."""
    plan = macro_raster(surface, settings, raster)
    form = row_form(surface, settings, plan.direction, form)
    rows, pts = plan.rows, plan.points
    j, d, i, k, t = var("j"), var("d"), var("i"), var("k"), var("t")
    r, p, z = var("r"), var("p"), var("z")
    point_body = [
        Assign(t, sub(const(pts.count), mul(const(2), i))),
        Assign(k, add(i, mul(d, t))),
        Assign(p, add(const(pts.start), mul(k, const(pts.step)))),
        Clamp(p, const(pts.end)),
        *point_statements(form, p, z),
        Move(p, r, z) if plan.direction == "x" else Move(r, p, z),
    ]
    row_body = [
        Assign(r, add(const(rows.start), mul(j, const(rows.step)))),
        Clamp(r, const(rows.end)),
        *row_statements(form, r),
        Loop(i, pts.count, tuple(point_body)),
        Assign(d, sub(const(1), d)),
    ]
    body = (Assign(d, const(0)), Loop(j, rows.count, tuple(row_body)))
    z0 = _exact_z(form, pts.start, rows.start)
    start = (pts.start, rows.start, z0) if plan.direction == "x" else (rows.start, pts.start, z0)
    return MacroPlan(body=body, raster=plan, form=form, start=start, tool=tool)


def _sample(axis, limit: int) -> list[Fraction]:
    ks = sorted(set(np.linspace(0, axis.count, min(axis.count + 1, limit)).round().astype(int).tolist()))
    return [min(axis.start + k * axis.step, axis.end) for k in ks]


def predicted_error(plan: MacroPlan, precision: int, rows: int = 25, points: int = 41) -> float:
    """Largest difference between the control's arithmetic and exact evaluation over a sample of the raster.

    The row and point statements of ``plan`` are run in decimal arithmetic
    with ``precision`` significant digits, rounding after every operation, at
    up to ``rows`` x ``points`` raster positions (always including the edges),
    and compared with exact rational evaluation of the same form.  Returns the
    largest absolute difference in program units.
    """
    ctx = decimal_context(precision)
    form = plan.form
    row_code = row_statements(form, var("r"))
    point_code = point_statements(form, var("p"), var("z"))
    worst = Fraction(0)
    for r in _sample(plan.raster.rows, rows):
        env = run(row_code, {"r": _dec(r, ctx)}, ctx)
        for p in _sample(plan.raster.points, points):
            env["p"] = _dec(p, ctx)
            run(point_code, env, ctx)
            worst = max(worst, abs(Fraction(env["z"]) - _exact_z(form, Fraction(env["p"]), Fraction(env["r"]))))
    return float(worst)


def _dec(v: Fraction, ctx):
    from decimal import Decimal

    return ctx.divide(Decimal(v.numerator), Decimal(v.denominator))


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
    if tool is not None and tool.shape == "ball" and tool.diameter_mm > 0:
        from .ballend import ballend_plan

        plan = ballend_plan(surface, settings, raster, tool, form)
    else:
        plan = macro_plan(surface, settings, raster, tool, form)
    err = predicted_error(plan, precision) / settings.unit_factor
    if err > tolerance_mm:
        raise ProgramError(
            f"{surface.grid.source}: a {surface.grid.shape[0]}x{surface.grid.shape[1]} surface evaluated with "
            f"{precision} significant digits in the {form} form is predicted to be off by {err:.3g} mm, more than the tolerance "
            f"{tolerance_mm:g} mm; use a control with 15-digit arithmetic (--precision 15), fewer control points, "
            f"or the point-list toolpath")
    module = importlib.import_module(f"{__package__}.{dialect}")
    text = module.render(plan, settings, precision=precision, variable_base=variable_base)
    return MacroProgram(text=text, dialect=dialect, precision=precision, predicted_error=err, plan=plan)
