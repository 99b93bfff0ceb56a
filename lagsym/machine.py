"""Machine set-up, cutter and raster settings that travel with every toolpath and program call.

These are plain frozen values: nothing in lagsym keeps machine settings in
module state.  Units are in the names (``feed_mm_min``, ``safe_z_mm``); lengths
in surface units (the control points' units) are turned into millimetres by
the one :class:`Placement` (``mm_per_unit`` and ``origin_mm``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from fractions import Fraction

import numpy as np

from .controls import Control, control, names, work_offset
# The cutter is a value of its own (lagsym.cutter); its names stay importable from here, where callers know them.
from .cutter import TOOL_SHAPES, Cutter, Tool, cutter_profile
from .errors import InputError, ToolpathError
from .values import as_exact, choice, finite, positive

__all__ = ["Placement", "Cutter", "Tool", "MachineSettings", "ProgramFormat", "CuttingData", "ToolSlot", "RasterSpec", "DIALECTS", "TOOL_SHAPES", "LINE_ENDINGS",
           "PROGRAM_LINE_ENDINGS", "UNITS", "DIRECTIONS", "COOLANTS", "MM_PER", "LENGTH_UNITS", "FEED_UNITS", "split_unit",
           "mm_per_surface_unit",
           "program_units_per_mm", "mm_per_program_unit", "BOUNDARIES", "DEFAULT_TOLERANCE_MM", "MAX_LEFT_MM", "cutter_profile"]

DIALECTS = names()
"""The names of the registered controls (:data:`lagsym.controls.CONTROLS`)."""
LINE_ENDINGS = {"lf": "\n", "crlf": "\r\n", "cr": "\r"}
# A program ends its blocks with LF or CR LF: with CR alone rs274 and ISO tape readers see one block.
PROGRAM_LINE_ENDINGS = ("lf", "crlf")
UNITS = ("mm", "inch")
COOLANTS = ("off", "flood", "mist")  # M08 flood, M07 mist, M09 off at the end
DIRECTIONS = ("x", "y")
BOUNDARIES = ("inside", "centre", "past")
DEFAULT_TOLERANCE_MM = 0.005
"""Chordal tolerance of a finishing pass given a fixed forward step and no tolerance of its own."""
MAX_LEFT_MM = 0.1
"""Material left above the surface from which a finishing program fails verification, by default."""
MM_PER_INCH = Fraction(254, 10)
MM_PER = {"mm": Fraction(1), "inch": MM_PER_INCH}
LENGTH_UNITS = {"mm": Fraction(1), "in": MM_PER_INCH}
"""The units a length may name after its number (``5mm``, ``0.2 in``), and their millimetres."""
FEED_UNITS = {"mm/min": Fraction(1), "in/min": MM_PER_INCH}
"""The units a feed may name after its number (``600mm/min``, ``24 in/min``), and their millimetres."""


def split_unit(text: str, units) -> tuple[str, Fraction | None]:
    """``text`` as its number and the millimetres of the unit it ends in, of ``units`` (None if it names none).

    Examples
    --------
    >>> split_unit(" 0.2 in", LENGTH_UNITS), split_unit("600", FEED_UNITS)
    (('0.2', Fraction(127, 5)), ('600', None))
    """
    s = text.strip()
    for name in sorted(units, key=len, reverse=True):
        if s.endswith(name):
            return s[:-len(name)].strip(), units[name]
    return s, None


def mm_per_surface_unit(surface_units: str | None, scale: float = 1.0) -> float:
    """Millimetres per surface unit: the model ``scale`` times the length of one unit of the surface.

    ``scale`` is dimensionless (2: the part is twice the size the points
    describe); a surface in inches is 25.4 mm per unit at scale 1.  A surface
    whose file names no units is taken to be in millimetres.

    Examples
    --------
    >>> mm_per_surface_unit("inch"), mm_per_surface_unit("mm", 10), mm_per_surface_unit(None, 2.5)
    (25.4, 10.0, 2.5)
    """
    units = "mm" if surface_units is None else choice(surface_units, UNITS, "surface units")
    return float(as_exact(positive(scale, "scale"), "scale") * MM_PER[units])


def bits_per_char(bytesize: int, parity: str, stopbits: float) -> float:
    """Bits on a serial line for one character: start bit, data bits, parity bit (unless ``none``), stop bits.

    The one figure behind every transfer time (DNC transfers and program statistics).

    Examples
    --------
    >>> bits_per_char(7, "even", 2)
    11.0
    """
    return 1 + bytesize + (0 if parity == "none" else 1) + float(stopbits)


def mm_per_program_unit(units: str) -> float:
    """Millimetres per program unit: 1 for ``mm`` (G21), 25.4 for ``inch`` (G20).

    The one conversion every reader of a program uses, beside its exact
    inverse :func:`program_units_per_mm` that the writers use.
    """
    return float(MM_PER[choice(units, UNITS, "units")])


def program_units_per_mm(units: str) -> Fraction:
    """Program units per millimetre: 1 for ``mm``, 1/25.4 for ``inch`` (exact)."""
    return Fraction(1) if choice(units, UNITS, "units") == "mm" else 1 / MM_PER_INCH


@dataclass(frozen=True)
class Placement:
    """Where the surface sits on the machine: the one map between surface units and machine millimetres.

    A surface point ``(x, y, z)`` (in the control points' units) is at
    ``(x * mm_per_unit + X0, y * mm_per_unit + Y0, z * mm_per_unit + Z0)`` on the
    machine, ``(X0, Y0, Z0) = origin_mm``.  Every toolpath, program, simulated
    cut and picture goes through this one map.

    Examples
    --------
    >>> p = Placement(20.0, (100.0, 0.0, -5.0))
    >>> p.to_machine(1.0, 2.0, 3.0)
    (120.0, 40.0, 55.0)
    >>> p.to_surface(120.0, 40.0)
    (1.0, 2.0)
    """

    mm_per_unit: float = 1.0
    origin_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self):
        object.__setattr__(self, "mm_per_unit", positive(self.mm_per_unit, "scale (millimetres per surface unit)"))
        if len(self.origin_mm) != 3:
            raise ToolpathError(f"origin {self.origin_mm!r} must be X,Y,Z")
        object.__setattr__(self, "origin_mm", tuple(finite(v, "origin") for v in self.origin_mm))

    def to_machine(self, x, y, z=None):
        """Surface coordinates to machine millimetres: ``(x_mm, y_mm)``, or ``(x_mm, y_mm, z_mm)`` given ``z``."""
        s, (ox, oy, oz) = self.mm_per_unit, self.origin_mm
        xy = (np.asarray(x) * s + ox, np.asarray(y) * s + oy)
        xy = tuple(v.item() if v.ndim == 0 else v for v in xy)
        if z is None:
            return xy
        zm = np.asarray(z) * s + oz
        return (*xy, zm.item() if zm.ndim == 0 else zm)

    def to_surface(self, x_mm, y_mm, z_mm=None):
        """Machine millimetres to surface coordinates: ``(x, y)``, or ``(x, y, z)`` given ``z_mm``."""
        s, (ox, oy, oz) = self.mm_per_unit, self.origin_mm
        out = [(np.asarray(x_mm) - ox) / s, (np.asarray(y_mm) - oy) / s]
        if z_mm is not None:
            out.append((np.asarray(z_mm) - oz) / s)
        return tuple(v.item() if v.ndim == 0 else v for v in out)

    def height_mm(self, z):
        """A surface height in machine millimetres (the origin's Z added)."""
        return np.asarray(z) * self.mm_per_unit + self.origin_mm[2]

    def box_mm(self, bounds) -> tuple[float, float, float, float]:
        """The surface's box ``(x0, x1, y0, y1)`` on the machine, in millimetres."""
        x0, x1, y0, y1 = (float(v) for v in bounds)
        (a, c), (b, d) = self.to_machine(x0, y0), self.to_machine(x1, y1)
        return (a, b, c, d)

    def exact(self, units: str = "mm") -> tuple[Fraction, tuple[Fraction, Fraction, Fraction]]:
        """Program units per surface unit and the origin in program units, as exact numbers.

        A float is read as the decimal it prints (see :func:`lagsym.values.as_exact`),
        so a macro program's constants are the numbers the user typed.
        """
        k = program_units_per_mm(units)
        scale = as_exact(self.mm_per_unit, "millimetres per surface unit") * k
        origin = tuple(as_exact(v, "origin") * k for v in self.origin_mm)
        return scale, origin


def _whole(value, what: str) -> None:
    if value is not None and (isinstance(value, bool) or not isinstance(value, (int, np.integer))):
        raise InputError(f"{what} {value!r} must be a whole number")


@dataclass(frozen=True)
class ProgramFormat:
    """How a program is written: the control, its units and decimals, line ending, program number, work offset.

    The positions a program can write (its resolution) follow from these
    alone; nothing here says where the surface is or how the tool cuts.

    Examples
    --------
    >>> f = ProgramFormat("haas", units="inch")
    >>> f.digits, f.control.framing.program_word.format(f.program_number), f.resolution_mm
    (4, 'O01000', 0.00254)
    """

    dialect: str = "fanuc"
    units: str = "mm"
    decimals: int | None = None  # None: 3 for mm, 4 for inch
    line_ending: str = "lf"
    program_number: int = 1000
    work_offset: str = "G54"

    def __post_init__(self):
        c = control(self.dialect)
        choice(self.units, UNITS, "units")
        if self.line_ending not in PROGRAM_LINE_ENDINGS:
            raise InputError(f"line ending {self.line_ending!r} is not one of {', '.join(PROGRAM_LINE_ENDINGS)}: "
                             "with CR alone rs274 and ISO readers see the whole program as one block")
        _whole(self.program_number, "program number")
        _whole(self.decimals, "decimals")
        low, high = c.program_numbers
        if not (low <= int(self.program_number) <= high):
            raise ToolpathError(f"program number {self.program_number} must be {low} to {high} for a {c.name} program")
        if self.decimals is not None and not (0 <= self.decimals <= 6):
            raise ToolpathError(f"decimals {self.decimals} must be 0 to 6")
        work_offset(self.work_offset, exact=True)

    @property
    def control(self) -> Control:
        """The control the program is for (:data:`lagsym.controls.CONTROLS`)."""
        return control(self.dialect)

    @property
    def eol(self) -> str:
        """The end-of-block characters."""
        return LINE_ENDINGS[self.line_ending]

    @property
    def digits(self) -> int:
        """Decimals written after the point in coordinates."""
        if self.decimals is not None:
            return self.decimals
        return 3 if self.units == "mm" else 4

    @property
    def unit_factor(self) -> float:
        """Program units per millimetre (:func:`program_units_per_mm`, as a float)."""
        return float(program_units_per_mm(self.units))

    @property
    def resolution_mm(self) -> float:
        """One unit of the last decimal written, in millimetres: the spacing of the positions the program writes."""
        return 10.0 ** -self.digits / self.unit_factor


@dataclass(frozen=True)
class CuttingData:
    """How the tool cuts: feeds, spindle speed, the clearance and feed heights, stock to leave, coolant (all mm)."""

    feed_mm_min: float = 600.0
    plunge_feed_mm_min: float = 200.0
    spindle_rpm: float = 3000.0
    safe_z_mm: float = 50.0
    feed_height_mm: float = 2.0
    stock_to_leave_mm: float = 0.0
    coolant: str = "off"

    def __post_init__(self):
        choice(self.coolant, COOLANTS, "coolant")
        positive(self.feed_mm_min, "feed")
        positive(self.plunge_feed_mm_min, "plunge feed")
        positive(self.spindle_rpm, "spindle speed", allow_zero=True)
        positive(self.stock_to_leave_mm, "stock to leave", allow_zero=True)
        positive(self.feed_height_mm, "feed height")
        finite(self.safe_z_mm, "safe Z")


@dataclass(frozen=True)
class ToolSlot:
    """Where the cutter sits on the machine: its tool number and the length offset ``G43 H`` takes."""

    tool_number: int = 1
    length_offset: int | None = None  # None: the tool number

    def __post_init__(self):
        _whole(self.tool_number, "tool number")
        _whole(self.length_offset, "length offset")
        if self.tool_number < 1:
            raise InputError(f"tool number {self.tool_number} must be 1 or more")
        if self.length_offset is not None and self.length_offset < 1:
            raise InputError(f"length offset H{self.length_offset} must be 1 or more")

    @property
    def length_offset_number(self) -> int:
        """The H number of ``G43``: the length offset, by default the tool number."""
        return self.tool_number if self.length_offset is None else int(self.length_offset)


_CONCERNS = {"program": ProgramFormat, "cutting": CuttingData, "slot": ToolSlot}


@dataclass(frozen=True)
class MachineSettings:
    """Everything a program for one machine needs, as one set of keyword arguments: four values by concern.

    The fields are the command line's options; each is checked once, by the
    value of its concern, and the values travel apart to the code that needs
    only one: :attr:`placement` (surface to machine), :attr:`program`
    (:class:`ProgramFormat`), :attr:`cutting` (:class:`CuttingData`) and
    :attr:`slot` (:class:`ToolSlot`).  :meth:`of` puts four such values together.

    Attributes
    ----------
    dialect : str
        The control's name, one of :data:`lagsym.controls.CONTROLS`: ``fanuc``
        (also ISO-reading Bridgeport controls), ``haas``, ``linuxcnc``,
        ``heidenhain`` or ``grbl``; :attr:`control` is its value.
    mm_per_unit : float
        Millimetres per surface unit (the CLI's ``--scale``).
    origin_mm : tuple of float
        Work offset added to every programmed point (X, Y, Z); with
        ``mm_per_unit`` it is the :attr:`placement`.
    units : str
        ``mm`` (G21) or ``inch`` (G20) in the program; internal values stay in mm.

    Examples
    --------
    >>> s = MachineSettings(dialect="linuxcnc", mm_per_unit=20.0, feed_mm_min=1500.0, tool_number=2)
    >>> s.program.dialect, s.cutting.feed_mm_min, s.slot.length_offset_number, s.placement.mm_per_unit
    ('linuxcnc', 1500.0, 2, 20.0)
    >>> MachineSettings.of(s.placement, s.program, s.cutting, s.slot) == s
    True
    """

    dialect: str = "fanuc"
    mm_per_unit: float = 1.0
    origin_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    units: str = "mm"
    feed_mm_min: float = 600.0
    plunge_feed_mm_min: float = 200.0
    spindle_rpm: float = 3000.0
    safe_z_mm: float = 50.0
    stock_to_leave_mm: float = 0.0
    program_number: int = 1000
    work_offset: str = "G54"
    line_ending: str = "lf"
    decimals: int | None = None  # None: 3 for mm, 4 for inch
    tool_number: int = 1
    length_offset: int | None = None  # None: the tool number
    feed_height_mm: float = 2.0
    coolant: str = "off"
    surface_units: str = "mm"
    notes: tuple[str, ...] = ()  # header comments about the surface, such as an accepted conditioning
    program: ProgramFormat = field(init=False, repr=False, compare=False)
    cutting: CuttingData = field(init=False, repr=False, compare=False)
    slot: ToolSlot = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        for name, kind in _CONCERNS.items():  # each concern checks its own fields, once
            values = {f.name: getattr(self, f.name) for f in fields(kind)}
            object.__setattr__(self, name, kind(**values))
        choice(self.surface_units, UNITS, "surface units")
        place = Placement(self.mm_per_unit, self.origin_mm)  # checks both, once
        object.__setattr__(self, "mm_per_unit", place.mm_per_unit)
        object.__setattr__(self, "origin_mm", place.origin_mm)

    @classmethod
    def of(cls, placement: Placement = Placement(), program: ProgramFormat = ProgramFormat(),
           cutting: CuttingData = CuttingData(), slot: ToolSlot = ToolSlot(), surface_units: str = "mm"):
        """The settings of four values by concern."""
        flat = {f.name: getattr(v, f.name) for v in (program, cutting, slot) for f in fields(v)}
        return cls(mm_per_unit=placement.mm_per_unit, origin_mm=placement.origin_mm, surface_units=surface_units,
                   **flat)

    @property
    def control(self) -> Control:
        """The control the program is for (:data:`lagsym.controls.CONTROLS`)."""
        return self.program.control

    @property
    def length_offset_number(self) -> int:
        """The H number of ``G43``: the length offset, by default the tool number."""
        return self.slot.length_offset_number

    @property
    def placement(self) -> Placement:
        """Where the surface sits on this machine."""
        return Placement(self.mm_per_unit, self.origin_mm)

    @property
    def eol(self) -> str:
        """The end-of-block characters."""
        return self.program.eol

    @property
    def digits(self) -> int:
        """Decimals written after the point in coordinates."""
        return self.program.digits

    @property
    def unit_factor(self) -> float:
        """Program units per millimetre (:func:`program_units_per_mm`, as a float)."""
        return self.program.unit_factor


@dataclass(frozen=True)
class RasterSpec:
    """A zig-zag raster: rows along ``direction`` spaced by the side step, points spaced by the forward step.

    Give ``stepover_mm`` or ``scallop_mm`` (side step from the cusp height of a
    ball-end cutter), and ``step_mm`` or ``tolerance_mm`` (forward step from the
    chordal error).  All in millimetres on the machine.  A step is the longest
    move: points are added where the path bends, so that every move keeps the
    chordal tolerance (:data:`DEFAULT_TOLERANCE_MM` unless one is given).

    ``boundary`` says where the tool may go, as in CAM: ``inside`` keeps the
    whole tool inside the control points' box, ``centre`` keeps the tool axis
    inside it, ``past`` (the default) lets the tool axis go beyond it, as far
    as the tool can still touch the part there (for a ball, the tool radius
    times the sine of the surface's steepest slope angle; for a flat end, the
    tool radius), so that the tool reaches the box edges also where the surface
    is steep there.

    With ``arcs``, runs of moves along a row are replaced by circular moves
    in the row's plane where one fits within the tolerance, never below the
    cutter path (:mod:`lagsym.toolpath.arcs`).
    """

    direction: str = "x"
    stepover_mm: float | None = 0.5
    step_mm: float | None = 0.2
    scallop_mm: float | None = None
    tolerance_mm: float | None = None
    boundary: str = "past"
    arcs: bool = False

    def __post_init__(self):
        choice(self.direction, DIRECTIONS, "raster direction")
        choice(self.boundary, BOUNDARIES, "boundary")
        if self.stepover_mm is None and self.scallop_mm is None:
            raise ToolpathError("give a side step (--stepover) or a scallop height (--scallop)")
        if self.stepover_mm is not None and self.scallop_mm is not None:
            raise ToolpathError(f"give a side step (stepover {self.stepover_mm:g} mm) or a scallop height (scallop "
                                f"{self.scallop_mm:g} mm), not both: the rows are spaced by one of them")
        if self.step_mm is None and self.tolerance_mm is None:
            raise ToolpathError("give a forward step (--step) or a chordal tolerance (--tolerance)")
        for name in ("stepover_mm", "step_mm", "scallop_mm", "tolerance_mm"):
            v = getattr(self, name)
            if v is not None:
                positive(v, name.replace("_mm", "").replace("_", " "))

    @property
    def chordal_tolerance_mm(self) -> float:
        """The chordal tolerance the moves keep: the one given, or :data:`DEFAULT_TOLERANCE_MM`."""
        return DEFAULT_TOLERANCE_MM if self.tolerance_mm is None else float(self.tolerance_mm)
