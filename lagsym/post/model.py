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

import re
from dataclasses import dataclass

import numpy as np

from ..errors import ProgramError
from ..machine import MachineSettings
from .moves import format_moves
from ..gcode.numbers import fixed

__all__ = ["PointProgram", "point_program", "iso_comment", "body", "units_word"]


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
    """

    points_mm: np.ndarray
    settings: MachineSettings
    title: str = ""
    tool_comment: str = ""

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
    tool = f"T{settings.tool_number} {t.shape.upper()} END D{fixed(t.diameter_mm, 3, trim=True)} MM"
    return PointProgram(points_mm=toolpath.points_mm, settings=settings, title=title, tool_comment=tool)


_NOT_ISO = re.compile(r"[^A-Z0-9 .,:=+\-/*#_]")


def iso_comment(text: str) -> str:
    """Comment text a control accepts: upper-case ISO characters, no parentheses.

    Examples
    --------
    >>> iso_comment("Paper example 4 (5x5) – Ø6 ball")
    'PAPER EXAMPLE 4 5X5 - 6 BALL'
    """
    t = text.upper().replace("\u2013", "-").replace("\u2014", "-")
    t = _NOT_ISO.sub(" ", t)
    return re.sub(r"\s+", " ", t).strip()


def body(program: PointProgram, tool_length: bool = True) -> list[str]:
    """The moves every dialect shares: over the first point, down to it, along the points, up to safe Z."""
    s = program.settings
    p = program.points_mm
    safe = s.safe_z_mm
    if safe <= float(p[:, 2].max()):
        raise ProgramError(f"safe Z {safe:g} mm is not above the highest cutter location {float(p[:, 2].max()):.3f} mm")
    out = [f"G00 X{program.num(p[0, 0])} Y{program.num(p[0, 1])}"]
    out.append(f"G43 H{s.tool_number} Z{program.num(safe)}" if tool_length else f"G00 Z{program.num(safe)}")
    out.extend(format_moves(p[:1], s, previous=(p[0, 0], p[0, 1], safe), first_feed=s.plunge_feed_mm_min))
    rest = format_moves(p[1:], s, previous=p[0], first_feed=s.feed_mm_min, motion="") if len(p) > 1 else []
    if rest:
        rest[0] = rest[0].lstrip()
    out.extend(rest)
    out.append(f"G00 Z{program.num(safe)}")
    return out


def units_word(settings: MachineSettings) -> str:
    """G21 for millimetres, G20 for inches."""
    return "G21" if settings.units == "mm" else "G20"
