"""Macro programs: the one entry point, from surface and machine to checked program text.

:func:`macro_program` takes surface, machine settings, raster and tool; it
builds the loops (:mod:`.loops`), checks the rapid moves' clearance and the
control's arithmetic (:mod:`.accuracy`), and renders the text with the
dialect's writer from :data:`RENDERERS`.  The result is a
:class:`MacroProgram`: text plus what was predicted about it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from ..controls import CONTROLS, control, names
from ..errors import ProgramError, ToolpathError
from ..lagrange import LagrangeSurface
from ..machine import MachineSettings, RasterSpec, Tool
from ..values import choice
from . import fanuc, heidenhain, linuxcnc
from ..gcode.limits import check_axis
from .accuracy import predicted_error
from .form import FORMS
from .loops import MacroLoops, macro_loops
from .points import points_at
from .raster import MacroRaster, macro_raster, sample_positions

__all__ = ["MACRO_DIALECTS", "PRECISIONS", "DEFAULT_PRECISION", "DEFAULT_FORM", "RENDERERS", "MacroProgram",
           "macro_program", "check_macro_points", "MAX_MACRO_POINTS"]

RENDERERS = {"fanuc": fanuc.render, "linuxcnc": linuxcnc.render, "heidenhain": heidenhain.render}
"""The macro writer of each macro language (:attr:`lagsym.controls.MacroLanguage.name`)."""
MACRO_DIALECTS = names(macros=True)
"""The controls with a macro language."""
PRECISIONS = (8, 15)
DEFAULT_PRECISION = MappingProxyType({c.name: c.macro.default_precision for c in CONTROLS.values() if c.macro})
"""Each macro control's default arithmetic precision, from its :class:`~lagsym.controls.MacroLanguage`."""
DEFAULT_FORM = {8: "lagrange", 15: "horner"}
MAX_MACRO_POINTS = 20_000_000
"""Raster points a macro may visit by default: 310 times the README's Example 4 ball macro (64,566), about
270 hours of cutting at 600 mm/min with its 0.2 mm step; a finer raster is refused with its figures."""


def check_macro_points(raster: MacroRaster, settings: MachineSettings, max_points: int | None) -> None:
    """Refuse a raster of more than ``max_points`` points, stating its size, path length and cutting time.

    The control runs every point of the loops, however small the program
    text: a step of 0.001 mm on Example 4 at scale 20 is 80,001 rows of
    80,001 points, 6.4 billion points and 6,400 m of path, some 178 hours at
    600 mm/min.

    Examples
    --------
    >>> from lagsym.macro.raster import Axis
    >>> r = MacroRaster("x", Axis("Y", 0, 80, 1, 80), Axis("X", 0, 80, 1, 80))
    >>> check_macro_points(r, MachineSettings(), 1000)
    Traceback (most recent call last):
    ...
    lagsym.errors.ToolpathError: the macro's raster is 81 rows of 81 points, 6,561 points, more than the limit of 1,000 (side step 1 mm, step 1 mm): 6.56 m of path, about 0.2 hours at the feed 600 mm/min; use a larger --step or --stepover, or raise --max-points
    """
    if max_points is None or raster.size <= max_points:
        return
    per_mm = float(settings.unit_factor)
    rows, points = raster.rows, raster.points
    length_mm = ((rows.count + 1) * float(points.end - points.start) + float(rows.end - rows.start)) / per_mm
    hours = length_mm / settings.feed_mm_min / 60.0
    raise ToolpathError(
        f"the macro's raster is {rows.count + 1:,} rows of {points.count + 1:,} points, {raster.size:,} points, "
        f"more than the limit of {max_points:,} (side step {float(rows.step) / per_mm:g} mm, step "
        f"{float(points.step) / per_mm:g} mm): {length_mm / 1000:,.2f} m of path, about {hours:,.1f} hours at the "
        f"feed {settings.feed_mm_min:g} mm/min; use a larger --step or --stepover, or raise --max-points")


def _check_clearance(surface, settings, tool, loops: MacroLoops) -> None:
    """The rapid moves at the safe height must clear the highest point the tool tip reaches.

    Checked over the raster positions (up to 401 x 401 of them, evenly spread),
    with 1 % of the height range as margin for what lies between them.
    """
    uf = settings.unit_factor
    z = points_at(surface, settings, tool, *sample_positions(loops.raster))[:, 2]
    check_axis(z, settings, "the height of the path")
    top = (float(z.max()) + 0.01 * float(np.ptp(z))) / uf
    if settings.safe_z_mm < top + settings.feed_height_mm:
        raise ToolpathError(f"safe Z {settings.safe_z_mm:g} mm is less than the feed height "
                            f"{settings.feed_height_mm:g} mm above the highest point of the path, "
                            f"{float(z.max()) / uf:.3f} mm (with 1 % of the height range for what lies between "
                            f"the raster points): raise --safe-z to at least {top + settings.feed_height_mm:.3f} mm "
                            f"or lower --feed-height")


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
    predicted_error_mm : float
        Largest arithmetic error predicted at that precision, in millimetres
        (also for an inch program).
    loops : MacroLoops
        The loops and form the text renders.
    """

    text: str
    dialect: str
    precision: int
    predicted_error_mm: float
    loops: MacroLoops = field(repr=False)

    @property
    def size(self) -> int:
        """Size in bytes (characters; programs are ASCII)."""
        return len(self.text.encode("ascii"))


def macro_program(surface: LagrangeSurface, settings: MachineSettings, raster: RasterSpec,
                  tool: Tool | None = None, *, precision: int | None = None, tolerance_mm: float = 0.001,
                  variable_base: int | None = None, form: str | None = None, variables: str = "full",
                  max_points: int | None = MAX_MACRO_POINTS) -> MacroProgram:
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
    variables : str
        ``"full"`` or ``"small"``: the variable ranges of the control's macro
        option (see :data:`lagsym.gcode.limits.LIMITS`); a program that does
        not fit is refused.
    form : str, optional
        ``"horner"`` (shortest) or ``"lagrange"`` (tensor-product basis, the most
        accurate); by default Lagrange for 8 digits and Horner for 15.
    max_points : int, optional
        Refuse a raster of more points than this before anything else is
        done, with its size, path length and cutting time
        (:func:`check_macro_points`; None: no limit).

    Raises
    ------
    InputError
        If the dialect, precision or form is not one of its choices.
    ProgramError
        If the predicted error exceeds ``tolerance_mm``, the variables do not fit, or
        a block, number or step is beyond what the dialect's control reads.
    ToolpathError
        For a flat-end cutter with a diameter (see :func:`lagsym.macro.loops.macro_loops`),
        or a safe Z less than the feed height above the path.
    """
    c = control(settings.dialect, "macro dialect", MACRO_DIALECTS)
    dialect = c.name
    precision = c.macro.default_precision if precision is None else choice(int(precision), PRECISIONS, "precision")
    form = DEFAULT_FORM[precision] if form is None else choice(form, FORMS, "form")
    check_macro_points(macro_raster(surface, settings, raster), settings, max_points)
    loops = macro_loops(surface, settings, raster, tool, form)
    _check_clearance(surface, settings, tool, loops)
    err_mm = predicted_error(loops, precision) / settings.unit_factor
    if err_mm > tolerance_mm:
        raise ProgramError(
            f"{surface.grid.source}: a {surface.grid.shape[0]}x{surface.grid.shape[1]} surface evaluated with "
            f"{precision} significant digits in the {form} form is predicted to be off by {err_mm:.3g} mm, "
            f"more than the tolerance {tolerance_mm:g} mm; use a control with 15-digit arithmetic "
            f"(--precision 15){', the lagrange form' if form == 'horner' else ''}, fewer control points, "
            f"or the point-list toolpath")
    text = RENDERERS[c.macro.name](loops, settings, precision=precision, variable_base=variable_base, variables=variables)
    return MacroProgram(text=text, dialect=dialect, precision=precision, predicted_error_mm=err_mm, loops=loops)
