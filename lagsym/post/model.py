"""The point-list program model: a header, moves and a footer, and the blocks every dialect shares.

A dialect module (:mod:`lagsym.post.fanuc`, :mod:`lagsym.post.linuxcnc`,
:mod:`lagsym.post.grbl`) decides the framing, header and footer words; the
moves are written here, once, by :func:`body` through
:func:`~lagsym.post.moves.format_moves`.  Every number has a decimal point
and fixed decimals, never an exponent.  Words that are counts, not lengths
(``S``, ``T``, ``H``, ``M``, ``O``), are integers: a Fanuc alarms on a
decimal point there.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import ProgramError
from ..gcode.limits import check_axis, check_blocks, check_settings, resolution
from ..gcode.numbers import fixed
from ..gcode.text import COOLANT_ON, iso_comment, surface_comment
from ..machine import MachineSettings
from .arcs import feed_blocks
from .moves import format_moves

__all__ = ["PointProgram", "point_program", "iso_comment", "body", "units_word", "surface_comment", "check_clearance",
           "coolant_on", "coolant_off", "check_blocks", "check_settings"]


@dataclass(frozen=True)
class PointProgram:
    """What every dialect needs to write a point-list program.

    Attributes
    ----------
    points_mm : ndarray, shape (N, 3)
        Tool-tip positions in machine mm, in cutting order; read-only.
    settings : MachineSettings
        Units, feeds, spindle, safe Z, program number, line ending.
    title : str
        A comment naming the part (ISO characters only in the output).
    tool_comment : str
        A comment naming the cutter.
    arcs : Arcs or None
        Runs of the points written as arcs (:mod:`lagsym.post.arcs`).
    """

    points_mm: np.ndarray
    settings: MachineSettings
    title: str = ""
    tool_comment: str = ""
    arcs: object = None

    def __post_init__(self):
        a = np.array(self.points_mm, dtype=float)
        if a.ndim != 2 or a.shape[1] != 3 or len(a) == 0:
            raise ProgramError(f"a point-list program needs an (N, 3) array of points, not shape {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ProgramError("cannot write a program through a point that is not finite")
        a.setflags(write=False)
        object.__setattr__(self, "points_mm", a)

    def num(self, value_mm: float) -> str:
        """A length in program units with the program's decimals."""
        s = self.settings
        return fixed(float(value_mm) * s.unit_factor, s.digits)

    def feed(self, value_mm_min: float) -> str:
        """A feed in program units per minute (one decimal place, enough for any control)."""
        s = self.settings
        return fixed(float(value_mm_min) * s.unit_factor, 1 if s.units == "mm" else 2)


def point_program(toolpath, settings: MachineSettings, title: str = "") -> PointProgram:
    """The program model of a :class:`~lagsym.toolpath.Toolpath` for one machine."""
    t = toolpath.tool
    tool = f"T{settings.tool_number} {t.label}"
    if toolpath.cusp_mm is not None:  # a ball's rows: the worst cusp they are predicted to leave
        tool += f" CUSP AT MOST {toolpath.cusp_mm:.4f} MM NORMAL TO SURFACE"
        if getattr(toolpath, "hollow_share", None):
            tool += " OUTSIDE HOLLOWS TIGHTER THAN THE TOOL"
    if getattr(toolpath, "note", None):  # waterline or steep-and-shallow: the strategy and its threshold
        settings = replace(settings, notes=(*settings.notes, *toolpath.note.split("; ")))
    return PointProgram(points_mm=toolpath.points_mm, settings=settings, title=title, tool_comment=tool,
                        arcs=getattr(toolpath, "arcs", None))


def check_clearance(settings: MachineSettings, top_mm: float) -> None:
    """The clearance plane must be a feed height above the highest cutter location ``top_mm``."""
    need = top_mm + settings.feed_height_mm
    if settings.safe_z_mm < need:
        raise ProgramError(f"safe Z {settings.safe_z_mm:g} mm is less than the feed height "
                           f"{settings.feed_height_mm:g} mm above the highest cutter location {top_mm:.3f} mm: "
                           f"raise --safe-z to at least {need:.3f} mm or lower --feed-height")


def coolant_on(settings: MachineSettings) -> list[str]:
    """``M08`` (flood) or ``M07`` (mist), nothing when the coolant is off."""
    return [COOLANT_ON[settings.coolant]] if settings.coolant != "off" else []


def coolant_off(settings: MachineSettings) -> list[str]:
    """``M09`` when a coolant was turned on."""
    return [] if settings.coolant == "off" else ["M09"]


def body(program: PointProgram, tool_length: bool = True) -> list[str]:
    """The moves every dialect shares, in the order a machinist expects.

    Up to the clearance plane first (with the tool length offset), coolant on,
    over the first point at that height, down at rapid to a feed height above
    it, the last of the way at plunge feed, along the points at the cutting
    feed, and up to the clearance plane; then coolant off.  The rapid down
    cannot touch the part: the first point is a cutter location, so the tool
    is clear of the part anywhere above it.
    """
    s = program.settings
    p = program.points_mm
    check_clearance(s, float(p[:, 2].max()))
    check_axis(np.append(p.ravel(), s.safe_z_mm) * s.unit_factor, s, "the program")
    if s.feed_height_mm * s.unit_factor < resolution(s):
        raise ProgramError(f"feed height {s.feed_height_mm:g} mm is below the program's resolution")
    safe = program.num(s.safe_z_mm)
    out = [f"G00 G43 H{s.length_offset_number} Z{safe}" if tool_length else f"G00 Z{safe}"]
    out += coolant_on(s)
    out.append(f"G00 X{program.num(p[0, 0])} Y{program.num(p[0, 1])}")
    approach = float(p[0, 2]) + s.feed_height_mm
    above = (p[0, 0], p[0, 1], s.safe_z_mm)
    if approach < s.safe_z_mm:
        out.append(f"Z{program.num(approach)}")
        above = (p[0, 0], p[0, 1], approach)
    out.extend(format_moves(p[:1], s, previous=above, first_feed=s.plunge_feed_mm_min))
    if program.arcs is not None and len(program.arcs):
        check_axis(np.asarray(program.arcs.centre_mm).ravel() * s.unit_factor, s, "an arc centre")
    out.extend(feed_blocks(p, program.arcs, s))
    out.append(f"G00 Z{safe}")
    out += coolant_off(s)
    return out


def units_word(settings: MachineSettings) -> str:
    """G21 for millimetres, G20 for inches."""
    return "G21" if settings.units == "mm" else "G20"
