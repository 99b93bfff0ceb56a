"""The parametric roughing macro: the control loops over levels, rows and points and computes each tip height.

.. code-block:: text

    w = 0; d = 0
    n = 0 .. NL                          levels, counted
        lv = TOP - (n + 1) * SD; if lv < LOW: lv = LOW
        j = 0 .. NR                      rows, counted; every other level in reverse
            jj = j + w * (NR - 2 j);  r = R0 + jj * DR, clamped to the block
            rc = r clamped to the box;  the row's statements of F from rc;  tj = its tile row
            i = 0 .. NP                  points: outside, the box edge, ..., the box edge, outside
                kk = i + d * (NP - 2 i);  p = A0 + (kk - 1) * DP, clamped to A1
                p = E0 at kk = 0, E1 at kk = NP (beside the block);  pc = p clamped to the box
                z = F(pc, rc) + stock, zp, zr = the slopes there;  ti = its tile
                z = z + R * SQRT[zp**2 + zr**2] + A[ti, tj];  if z > B[ti, tj]: z = B[ti, tj]
                if z < lv: z = lv
                if i > 0 and z < zq - |p - pq| T: z = zq - |p - pq| T      T: the ramp angle's tangent
                G1 to (p, r, z);  zq = z;  pq = p
            d = 1 - d
        w = 1 - w

so the tool runs the point-list roughing's zig-zag (:mod:`lagsym.toolpath.rough`):
every row starts and ends beside the block by the tool radius plus the
clearance, so every level is entered from the air, and the links between
rows and levels run there; inside a row no descent is steeper than the
tool's ramp angle (:mod:`.roughpath`; none held for a plunge, 90 degrees).
The tables ``A`` and ``B`` (set at the start, read with ``#[..]``; one tile
and no table for a dialect without them) and the proof are in
:mod:`.clearance`:
no position and no move goes below the exact drop-cutter height plus the
stock.  The program's size depends on the surface's degree, not on the block.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from decimal import Decimal
from fractions import Fraction

import numpy as np

from .._arrays import freeze_fields
from ..controls import control, names
from ..errors import ToolpathError
from ..evaluate import surface_evaluator
from ..machine import MachineSettings, Tool, program_units_per_mm
from ..surfaces.piecewise import PiecewiseSurface
from ..toolpath.rough import RoughSpec, Stock, check_points, check_rough_request, ramp_note
from ..values import choice
from .clearance import Clearance, clearance_tables
from .form import FORMS, RowForm, point_statements, row_form, row_statements
from .loops import MacroLoops
from .model import Assign, Choose, Clamp, Item, Loop, Move, SetItem, Var, add, const, decimal_context, mul, run, sqrt, sub, var
from .raster import Axis, MacroRaster
from .roughpath import b_mm, model, path, ramp_tangent, xy
from .roughvars import check_rough_variables

__all__ = ["RoughMacro", "rough_macro", "rough_macro_blocks", "rough_macro_program", "MACRO_MILLING"]

MACRO_MILLING = ("zigzag",)
JOB_MACROS = names(point_lists=True, macros=True)
"""The controls a job's roughing macro is written for: a macro language inside a point-list program."""
_GRID = Fraction(1, 10_000)  # the loops' constants (positions, steps, levels) on a 0.0001 grid of program units


@dataclass(frozen=True)
class RoughMacro:
    """A roughing macro: its loops, the clearance, its levels and the path the control will run (PC model).

    Attributes
    ----------
    loops : MacroLoops
        What a dialect renders (:data:`~lagsym.macro.program.RENDERERS`).
    clearance : Clearance
        The tables ``A`` and ``B`` and their terms (mm).
    levels_mm : ndarray
        The Z levels, from the top down (machine mm).
    points_mm : ndarray, shape (N, 3)
        The tip positions the control computes, in floats (machine mm): for
        the cycle time and the checks; the program holds none of them.
    precision : int
        The control's significant digits the arithmetic allowance is for.
    """

    loops: MacroLoops
    clearance: Clearance
    levels_mm: np.ndarray
    points_mm: np.ndarray
    precision: int
    tool: Tool
    stock: Stock
    spec: RoughSpec

    def __post_init__(self):
        freeze_fields(self, ("levels_mm", "points_mm"))

    def __len__(self) -> int:
        return len(self.points_mm)


def _up(v: Fraction) -> Fraction:
    return math.ceil(v / _GRID) * _GRID


def _down(v: Fraction) -> Fraction:
    return math.floor(v / _GRID) * _GRID


def _counted(lo: Fraction, hi: Fraction, step: Fraction) -> tuple[int, Fraction]:
    """``count, spacing``: ``lo + count * spacing >= hi`` with a spacing on the grid and no larger than ``step``."""
    count = max(math.ceil((hi - lo) / step), 1)
    while True:
        spacing = _up((hi - lo) / count)
        if spacing <= step or spacing == _GRID:
            return count, spacing
        count += 1


@dataclass(frozen=True)
class _Layout:
    """The counted loops' constants, in program units (exact)."""

    a0: Fraction   # box edges along the rows
    a1: Fraction
    b0: Fraction   # box edges across
    b1: Fraction
    e0: Fraction   # row ends beside the block
    e1: Fraction
    c0: Fraction   # first and last row
    c1: Fraction
    dp: Fraction
    np_: int       # last point index (N + 2)
    dr: Fraction
    nr: int
    p_edges: tuple = ()  # the tiles' inner edges along and across, half-way between two grid positions
    r_edges: tuple = ()


def _edges(lo: Fraction, hi: Fraction, tiles: int) -> tuple:
    """``tiles - 1`` inner edges evenly between ``lo`` and ``hi``, each half-way between two grid positions
    (so no sample is ever on one: every control's comparison with it is exact)."""
    return tuple((math.floor((lo + i * (hi - lo) / tiles) / _GRID) + Fraction(1, 2)) * _GRID for i in range(1, tiles))


def _layout(rf: RowForm, stock: Stock, tool: Tool, spec: RoughSpec, per_mm: Fraction, tiles: int) -> _Layout:
    def box(c, k):
        return c - 1 / k, c + 1 / k

    a0, a1 = box(rf.pc, rf.pk)
    b0, b1 = box(rf.rc, rf.rk)
    mm = lambda v: Fraction(v) * per_mm  # noqa: E731
    along = (stock.x0, stock.x1) if spec.direction == "x" else (stock.y0, stock.y1)
    across = (stock.y0, stock.y1) if spec.direction == "x" else (stock.x0, stock.x1)
    out = mm(tool.radius_mm) + mm(spec.clearance_mm)
    n, dp = _counted(a0, a1, mm(spec.step_mm))
    c0, c1 = _down(mm(across[0])), _up(mm(across[1]))
    nr, dr = _counted(c0, c1, mm(spec.stepover_mm))
    return _Layout(a0, a1, b0, b1, _down(mm(along[0]) - out), _up(mm(along[1]) + out), c0, c1, dp, n + 2, dr, nr,
                   _edges(a0, a1, tiles), _edges(b0, b1, tiles))


def _tile(index: Var, position: Var, edges) -> tuple:
    """``index`` = how many of the tile ``edges`` lie below ``position``."""
    return (Assign(index, const(0)),) + tuple(Choose(index, position, "GT", const(e), const(k))
                                               for k, e in enumerate(edges, 1))


def _statements(rf: RowForm, lay: _Layout, radius: Fraction, tables, *, top: Fraction, sd: Fraction,
                low: Fraction, levels: int, direction: str,
                tan_a: Fraction | None = None) -> tuple[tuple, tuple, tuple]:
    """The loops, and the row and point statements of ``F + stock + R |grad F|`` (for the arithmetic check).

    ``tables`` is ``(A, B)`` as constants (one tile) or ``(base, tiles)``: the
    tables' first variable number and tiles a side.  ``tan_a`` holds every
    descent inside a row to that slope (:mod:`.roughpath`); None lets the tip
    fall as the surface does.
    """
    n, j, jj, i, kk, t = var("n"), var("j"), var("jj"), var("i"), var("kk"), var("t")
    w, d, lv, r, rc, p, pc, z, q = var("w"), var("d"), var("lv"), var("r"), var("rc"), var("p"), var("pc"), \
        var("z"), var("q")
    zp, zr, ti, tj, ia, ib = var("zp"), var("zr"), var("ti"), var("tj"), var("ia"), var("ib")
    zq, pq = var("zq"), var("pq")  # the row's last tip and position, for the ramp
    ramp, keep, start = (), (), ()
    if tan_a is not None:  # q = zq - |p - pq| tan, low at a row's first point (beside the block, not held)
        ramp = (Assign(q, mul(sub(p, pq), sub(const(1), mul(const(2), d)))),
                Assign(q, sub(zq, mul(q, const(tan_a)))),
                Choose(q, i, "LT", const(Fraction(1, 2)), const(low)),
                Choose(z, z, "LT", q, q))
        keep, start = (Assign(zq, z), Assign(pq, p)), (Assign(zq, const(low)), Assign(pq, const(lay.e0)))
    row_code = tuple(row_statements(rf, rc, slopes=True))
    point_code = tuple(point_statements(rf, pc, z, slopes=True)) + (
        Assign(q, sqrt(add(mul(zp, zp), mul(zr, zr)))),
        Assign(z, add(z, mul(q, const(radius)))))
    if isinstance(tables[0], Fraction):
        row_tile, cap = (), (Assign(z, add(z, const(tables[0]))), Choose(z, z, "GT", const(tables[1]),
                                                                         const(tables[1])))
    else:
        base, tiles = tables  # A[ip, ir] is variable base + ir * tiles + ip, B[ip, ir] tiles**2 further on
        row_tile = _tile(tj, rc, lay.r_edges) + (Assign(tj, add(mul(tj, const(tiles)), const(base))),)
        cap = _tile(ti, pc, lay.p_edges) + (
            Assign(ia, add(tj, ti)), Assign(ib, add(ia, const(tiles * tiles))),
            Assign(z, add(z, Item(ia))), Choose(z, z, "GT", Item(ib), Item(ib)))
    point_body = (
        Assign(t, sub(const(lay.np_), mul(const(2), i))),
        Assign(kk, add(i, mul(d, t))),
        Assign(p, add(const(lay.a0), mul(sub(kk, const(1)), const(lay.dp)))),
        Clamp(p, const(lay.a1)),
        Choose(p, kk, "LT", const(Fraction(1, 2)), const(lay.e0)),
        Choose(p, kk, "GT", const(lay.np_ - Fraction(1, 2)), const(lay.e1)),
        Assign(pc, p),
        Choose(pc, pc, "LT", const(lay.a0), const(lay.a0)),
        Clamp(pc, const(lay.a1)),
        *point_code,
        *cap,
        Choose(z, z, "LT", lv, lv),
        *ramp,
        Move(p, r, z) if direction == "x" else Move(r, p, z),
        *keep,
    )
    row_body = (
        Assign(t, sub(const(lay.nr), mul(const(2), j))),
        Assign(jj, add(j, mul(w, t))),
        Assign(r, add(const(lay.c0), mul(jj, const(lay.dr)))),
        Clamp(r, const(lay.c1)),
        Assign(rc, r),
        Choose(rc, rc, "LT", const(lay.b0), const(lay.b0)),
        Clamp(rc, const(lay.b1)),
        *row_code,
        *row_tile,
        Loop(i, lay.np_, point_body),
        Assign(d, sub(const(1), d)),
    )
    level_body = (
        Assign(lv, sub(const(top), mul(add(n, const(1)), const(sd)))),
        Choose(lv, lv, "LT", const(low), const(low)),
        Loop(j, lay.nr, row_body),
        Assign(w, sub(const(1), w)),
    )
    body = (Assign(w, const(0)), Assign(d, const(0)), *start, Loop(n, levels - 1, level_body))
    return body, row_code, point_code


def _near(v_mm: float, per_mm: Fraction) -> Fraction:
    """A length given in mm, in program units, on the loops' grid (a decimal as written, not its binary float)."""
    return round(Fraction(repr(float(v_mm))) * per_mm / _GRID) * _GRID


def _arithmetic_mm(rf, lay: _Layout, radius: Fraction, ev, place, settings: MachineSettings, *, per_mm: Fraction,
                   precision: int) -> float:
    """Twice the largest difference of the control's ``b`` from the PC's, over 9 x 41 box positions, plus 3 units."""
    _, row_code, point_code = _statements(rf, lay, radius, (Fraction(0), Fraction(0)), top=Fraction(0),
                                          sd=Fraction(1), low=Fraction(0), levels=1, direction="x")
    ctx = decimal_context(precision)
    worst, size = 0.0, 0.0
    for rv in np.linspace(float(lay.b0), float(lay.b1), 9):
        env = run(row_code, {"rc": ctx.create_decimal(repr(float(rv)))}, ctx)
        ps = np.linspace(float(lay.a0), float(lay.a1), 41)
        got = []
        for pv in ps:
            env["pc"] = ctx.create_decimal(repr(float(pv)))
            got.append(float(run(point_code, env, ctx)["z"]))
        x, y = xy(rf.direction, ps / float(per_mm), np.full(len(ps), rv / float(per_mm)))
        want = b_mm(ev, place, float(radius / per_mm), settings.stock_to_leave_mm, x, y)
        worst = max(worst, float(np.abs(np.array(got) / float(per_mm) - want).max()))
        size = max(size, float(np.abs(want).max()))
    ulp = float(Decimal(1).scaleb(Decimal(repr(size * float(per_mm))).adjusted() + 1 - precision)) / float(per_mm)
    return 2.0 * worst + 3.0 * ulp


def piecewise_macro_refusal(surface: PiecewiseSurface, what: str) -> str:
    """Why ``what`` (a macro) is not written for a piecewise surface, in one line."""
    a, b = surface.shape
    return (f"{what} evaluates one polynomial on the control, and {surface.source} is {a} x {b} = {a * b} "
            f"bicubic pieces: rough it as a point list (leave out the macro)")


def rough_macro(surface, tool: Tool, stock: Stock, spec: RoughSpec, settings: MachineSettings, *,
                precision: int, form: str | None = None, evaluator=None, max_points: int | None = None) -> RoughMacro:
    """Plan the parametric roughing of ``stock`` for ``settings.dialect`` at the control's ``precision``.

    ``settings.stock_to_leave_mm`` is replaced by ``spec``'s.  Only a zig-zag
    (``spec.milling``) is written as a macro; a one-way raster retracts over
    the block between rows, which the point-list roughing does.  ``max_points``
    refuses a run of more moves than that before anything is planned.

    Examples
    --------
    >>> from lagsym.grid import grid_from_points
    >>> from lagsym.lagrange import lagrange_surface
    >>> s = lagrange_surface(grid_from_points([(0, 0, 1), (0, 4, 1), (4, 0, 1), (4, 4, 1)]))
    >>> rm = rough_macro(s, Tool("flat", 2.0), Stock(0, 4, 0, 4, 4.0), RoughSpec(1.5, 1.5, 1.0, 0.5),
    ...                  MachineSettings(dialect="linuxcnc"), precision=15)
    >>> [round(float(z), 4) for z in rm.levels_mm], bool(rm.points_mm[:, 2].min() >= 1.5)
    ([2.5, 1.5006], True)
    """
    if isinstance(surface, PiecewiseSurface):
        raise ToolpathError(piecewise_macro_refusal(surface, "a roughing macro"))
    if spec.pattern != "raster":
        raise ToolpathError(f"pattern {spec.pattern!r}: a roughing macro runs raster rows")
    if spec.milling not in MACRO_MILLING:
        raise ToolpathError(f"milling {spec.milling!r}: a roughing macro cuts zig-zag only (a one-way raster "
                            "retracts over the block between rows); leave out the macro for climb or conventional")
    form = form or ("lagrange" if precision <= 8 else "horner")
    choice(form, FORMS, "form")
    settings = dataclasses.replace(settings, stock_to_leave_mm=spec.stock_to_leave_mm)
    ev = evaluator or surface_evaluator(surface)
    place = settings.placement
    check_rough_request(tool, stock, spec, ev, place, max_points=max_points, option="--max-points")
    per_mm = program_units_per_mm(settings.units)
    rf = row_form(surface, settings, spec.direction, form)
    language = settings.control.macro
    tiles = language.table_tiles if language is not None and language.table_base is not None else 1
    lay = _layout(rf, stock, tool, spec, per_mm, tiles)
    radius = _near(tool.radius_mm, per_mm)
    arith = _arithmetic_mm(rf, lay, radius, ev, place, settings, per_mm=per_mm, precision=precision)
    edges = [np.array([float(v / per_mm) for v in (lo, *inner, hi)])
             for lo, inner, hi in ((lay.a0, lay.p_edges, lay.a1), (lay.b0, lay.r_edges, lay.b1))]
    ex, ey = edges if spec.direction == "x" else edges[::-1]
    clear = clearance_tables(ev, place, tool, float(lay.dp / per_mm), settings.stock_to_leave_mm, edges_x=ex,
                             edges_y=ey, unit_mm=10.0 ** -settings.digits / float(per_mm), arithmetic_mm=arith,
                             direction=spec.direction)
    a = [[_up(Fraction(repr(float(v))) * per_mm) for v in row] for row in clear.a_mm]
    b = [[_up(Fraction(repr(float(v))) * per_mm) for v in row] for row in clear.b_mm]
    rows, pts, tip = model(ev, place, lay, float(radius / per_mm), settings.stock_to_leave_mm, a=a, b=b,
                           per_mm=per_mm, direction=spec.direction)
    top, sd = _near(stock.top_mm, per_mm), _near(spec.stepdown_mm, per_mm)
    low = _down(Fraction(repr(float(tip.min()))) * per_mm)
    count = max(math.ceil((top - low) / sd), 1)
    check_points(stock, tool, spec, count, max_points, "--max-points")
    levels = np.maximum(float(top) - float(sd) * np.arange(1, count + 1), float(low)) / float(per_mm)
    if spec.reach_mm is not None and stock.top_mm - levels[-1] > spec.reach_mm:
        raise ToolpathError(f"the tool cannot reach: the cut goes {stock.top_mm - levels[-1]:.3f} mm below the "
                            f"stock top, the tool reaches {spec.reach_mm:g} mm below its holder")
    if tiles == 1:
        tables, setup = (a[0][0], b[0][0]), ()
    else:
        base = language.table_base
        tables = (base, tiles)
        setup = tuple(SetItem(base + k * tiles * tiles + ir * tiles + ip, const(t[ip][ir]))
                      for k, t in enumerate((a, b)) for ir in range(tiles) for ip in range(tiles))
    tan_a = ramp_tangent(tool)
    body, row_code, point_code = _statements(rf, lay, radius, tables, top=top, sd=sd, low=low, levels=count,
                                             direction=spec.direction, tan_a=tan_a)
    tips = path(rows, pts, tip, levels, spec.direction, tan_a)
    _check_safe_z(float(tips[:, 2].max()), settings)
    start = tuple(Fraction(repr(float(v))) * per_mm for v in tips[0])
    raster = MacroRaster(spec.direction, rows=Axis("Y" if spec.direction == "x" else "X", lay.c0, lay.c1, lay.dr,
                                                   lay.nr),
                         points=Axis("X" if spec.direction == "x" else "Y", lay.a0, lay.a1, lay.dp, lay.np_))
    loops = MacroLoops(body=setup + body, raster=raster, form=rf, start=start, row_code=row_code,
                       point_code=point_code, title="LAGSYM ROUGHING MACRO")
    return RoughMacro(loops, clear, levels, tips, precision, tool, stock, spec)


def _check_safe_z(highest_mm: float, settings: MachineSettings) -> None:
    """Refuse a safe Z below the feed height over the highest tip the loops move to.

    The clearance can lift the tip above the block on a steep flank; the
    retract at the end and every approach go straight down or up there.
    """
    need = highest_mm + settings.feed_height_mm
    if settings.safe_z_mm < need - 1e-9:
        raise ToolpathError(f"safe Z {settings.safe_z_mm:g} mm is less than the feed height "
                            f"{settings.feed_height_mm:g} mm above the highest tip of the roughing macro "
                            f"{highest_mm:.3f} mm (its clearance lifts the tool above the surface on steep flanks): "
                            f"raise --safe-z to at least {need:.3f} mm")


def rough_macro_blocks(rm: RoughMacro, settings: MachineSettings, variable_base: int | None = None,
                       variables: str = "full") -> list[str]:
    """The blocks from over the first point at safe Z: down to it, then the loops (Fanuc or LinuxCNC).

    For a program that writes its own header, tool change and end (a job's);
    :func:`rough_macro_program` writes a whole one, in any macro dialect.
    The variables must fit the control's ``variables`` profile
    (:func:`check_rough_variables`).
    """
    from . import fanuc, linuxcnc
    from ..gcode.numbers import fixed

    c = control(settings.dialect, "dialect of a roughing macro in a job", JOB_MACROS)
    check_rough_variables(rm, c.name, variables, variable_base)
    uf, dp = settings.unit_factor, settings.digits
    z0 = float(rm.loops.start[2])
    out = []
    if z0 + settings.feed_height_mm * uf < settings.safe_z_mm * uf:
        out.append(f"G00 Z{fixed(z0 + settings.feed_height_mm * uf, dp)}")
    out.append(f"G01 Z{fixed(z0, dp)} F{fixed(settings.plunge_feed_mm_min * uf, 1, trim=True)}")
    out.append(f"F{fixed(settings.feed_mm_min * uf, 1, trim=True)}")
    if c.macro.name == "linuxcnc":
        return out + linuxcnc.body_lines(rm.loops, rm.precision)
    return out + fanuc.body_lines(rm.loops, rm.precision, variable_base, variables, control=c)


def rough_macro_program(rm: RoughMacro, settings: MachineSettings, variable_base: int | None = None,
                        variables: str = "full") -> str:
    """The whole program for ``rm``: header (the ramp angle among its notes), tool, approach, the loops, the end
    (Fanuc, LinuxCNC or Heidenhain)."""
    from .program import RENDERERS

    c = control(settings.dialect, "macro dialect", names(macros=True))
    check_rough_variables(rm, c.name, variables, variable_base)
    settings = dataclasses.replace(settings, notes=(*settings.notes, ramp_note(rm.tool)))
    return RENDERERS[c.macro.name](rm.loops, settings, precision=rm.precision, variable_base=variable_base,
                              variables=variables)
