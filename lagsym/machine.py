"""Machine set-up, cutter and raster settings that travel with every toolpath and program call.

These are plain frozen values: nothing in lagsym keeps machine settings in
module state.  Units are in the names (``feed_mm_min``, ``safe_z_mm``); lengths
in surface units (the control points' units) are turned into millimetres by
``scale``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .errors import ToolpathError
from .values import choice, positive

__all__ = ["Tool", "MachineSettings", "RasterSpec", "DIALECTS", "TOOL_SHAPES", "LINE_ENDINGS", "UNITS", "DIRECTIONS"]

DIALECTS = ("fanuc", "linuxcnc", "heidenhain", "grbl")
TOOL_SHAPES = ("ball", "flat")
LINE_ENDINGS = {"lf": "\n", "crlf": "\r\n", "cr": "\r"}
UNITS = ("mm", "inch")
DIRECTIONS = ("x", "y")


@dataclass(frozen=True)
class Tool:
    """A milling cutter: ``shape`` is ``"ball"`` or ``"flat"``, ``diameter_mm`` its diameter (0: a point)."""

    shape: str = "ball"
    diameter_mm: float = 6.0

    def __post_init__(self):
        choice(self.shape, TOOL_SHAPES, "tool shape")
        object.__setattr__(self, "diameter_mm", positive(self.diameter_mm, "tool diameter", allow_zero=True))

    @property
    def radius_mm(self) -> float:
        """Half the diameter."""
        return self.diameter_mm / 2.0


@dataclass(frozen=True)
class MachineSettings:
    """How a program talks to one machine.

    Attributes
    ----------
    dialect : str
        ``fanuc`` (also Haas and ISO-reading Bridgeport controls), ``linuxcnc``,
        ``heidenhain`` or ``grbl``.
    scale : float
        Millimetres per surface unit.
    origin_mm : tuple of float
        Work offset added to every programmed point (X, Y, Z).
    units : str
        ``mm`` (G21) or ``inch`` (G20) in the program; internal values stay in mm.
    """

    dialect: str = "fanuc"
    scale: float = 1.0
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

    def __post_init__(self):
        choice(self.dialect, DIALECTS, "dialect")
        choice(self.units, UNITS, "units")
        choice(self.line_ending, tuple(LINE_ENDINGS), "line ending")
        positive(self.scale, "scale")
        positive(self.feed_mm_min, "feed")
        positive(self.plunge_feed_mm_min, "plunge feed")
        positive(self.spindle_rpm, "spindle speed", allow_zero=True)
        positive(self.stock_to_leave_mm, "stock to leave", allow_zero=True)
        if len(self.origin_mm) != 3:
            raise ToolpathError(f"origin {self.origin_mm!r} must be X,Y,Z")
        object.__setattr__(self, "origin_mm", tuple(float(v) for v in self.origin_mm))
        if not (1 <= int(self.program_number) <= 9999):
            raise ToolpathError(f"program number {self.program_number} must be 1 to 9999")
        if self.decimals is not None and not (0 <= self.decimals <= 6):
            raise ToolpathError(f"decimals {self.decimals} must be 0 to 6")

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
        """Program units per millimetre."""
        return 1.0 if self.units == "mm" else 1.0 / 25.4


@dataclass(frozen=True)
class RasterSpec:
    """A zig-zag raster: rows along ``direction`` spaced by the side step, points spaced by the forward step.

    Give ``stepover_mm`` or ``scallop_mm`` (side step from the cusp height of a
    ball-end cutter), and ``step_mm`` or ``tolerance_mm`` (forward step from the
    chordal error).  All in millimetres on the machine.
    """

    direction: str = "x"
    stepover_mm: float | None = 0.5
    step_mm: float | None = 0.2
    scallop_mm: float | None = None
    tolerance_mm: float | None = None

    def __post_init__(self):
        choice(self.direction, DIRECTIONS, "raster direction")
        if self.stepover_mm is None and self.scallop_mm is None:
            raise ToolpathError("give a side step (--stepover) or a scallop height (--scallop)")
        if self.step_mm is None and self.tolerance_mm is None:
            raise ToolpathError("give a forward step (--step) or a chordal tolerance (--tolerance)")
        for name in ("stepover_mm", "step_mm", "scallop_mm", "tolerance_mm"):
            v = getattr(self, name)
            if v is not None:
                positive(v, name.replace("_mm", "").replace("_", " "))
