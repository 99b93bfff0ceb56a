"""The shared program model: a point-list program as a header, moves and a footer.

A dialect module (:mod:`lagsym.post.fanuc`, :mod:`lagsym.post.linuxcnc`,
:mod:`lagsym.post.grbl`) decides the framing, header and footer words; the
moves are written here, once, fast: coordinates are rounded to the program's
decimals as integers and only the words that change are written (X, Y, Z and F
are modal on every control lagsym writes for).  Every number has a decimal
point and fixed decimals, never an exponent; Z is rounded up, so rounding
never puts the tool below a cutter location.  Words that are counts, not
lengths (``S``, ``T``, ``H``, ``M``, ``O``), are integers: a Fanuc alarms on a
decimal point there.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import ProgramError
from ..machine import DIALECTS, MachineSettings
from ..values import choice
from .numbers import fixed

__all__ = ["PointProgram", "point_program", "write_program", "format_moves", "iso_comment", "WRITERS", "writer"]


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


def _words(letter: str, ints: np.ndarray, digits: int, changed: np.ndarray) -> list[str]:
    """``letter`` + fixed-point text for each entry, '' where the value did not change."""
    out = [""] * len(ints)
    scale = 10 ** digits
    for i in np.flatnonzero(changed):
        k = int(ints[i])
        sign = "-" if k < 0 else ""
        q, r = divmod(abs(k), scale)
        out[i] = f"{letter}{sign}{q}.{r:0{digits}d}" if digits else f"{letter}{sign}{q}."
    return out


def _quantize(points_mm, settings: MachineSettings) -> np.ndarray:
    """Points in units of the program's last decimal: X and Y to the nearest, Z rounded up.

    Rounding Z up means a written point never lies below its cutter location,
    so the rounding cannot gouge; it raises a point by less than one unit of
    the last decimal.
    """
    v = np.asarray(points_mm, dtype=float) * (settings.unit_factor * 10 ** settings.digits)
    out = np.empty(v.shape, dtype=np.int64)
    out[:, :2] = np.rint(v[:, :2])
    out[:, 2] = np.ceil(v[:, 2] - 1e-6)  # 1e-6 of a unit: a value that is a whole unit up to float error stays
    return out


def format_moves(points_mm: np.ndarray, settings: MachineSettings, previous=None, first_feed: float | None = None,
                 motion: str = "G01") -> list[str]:
    """Blocks of linear feed moves through ``points_mm``, modal words left out.

    Parameters
    ----------
    points_mm : ndarray, shape (N, 3)
    settings : MachineSettings
    previous : sequence of float, optional
        The position (mm) before the first move, to leave out unchanged words.
    first_feed : float, optional
        Feed (mm/min) written on the first block.
    motion : str
        The motion word written on the first block.

    Examples
    --------
    >>> format_moves(np.array([[1.0, 2.0, -0.0008], [1.5, 2.0, 0.0012]]), MachineSettings(), first_feed=600)
    ['G01 X1.000 Y2.000 Z0.000 F600.0', 'X1.500 Z0.002']
    """
    d = settings.digits
    ints = _quantize(points_mm, settings)
    prev = (np.full(3, np.iinfo(np.int64).min) if previous is None
            else _quantize(np.asarray(previous, dtype=float)[None, :], settings)[0])
    before = np.vstack([prev[None, :], ints[:-1]])
    changed = ints != before
    changed[0] = changed[0] | (previous is None)
    cols = [_words(letter, ints[:, k], d, changed[:, k]) for k, letter in enumerate("XYZ")]
    lines = [" ".join(w for w in ws if w) for ws in zip(*cols)]
    if lines:
        head = [motion]
        if lines[0]:
            head.append(lines[0])
        if first_feed is not None:
            head.append("F" + fixed(float(first_feed) * settings.unit_factor, 1 if settings.units == "mm" else 2))
        lines[0] = " ".join(head)
    # A move to the same rounded point is no move: a control may refuse an empty block.
    return [ln for ln in lines if ln]


WRITERS: dict[str, Callable[[PointProgram], list[str]]] = {}


def register(dialect: str):
    """Register a function that turns a :class:`PointProgram` into blocks for ``dialect``."""

    def deco(fn):
        WRITERS[dialect] = fn
        return fn

    return deco


def writer(dialect: str) -> Callable[[PointProgram], list[str]]:
    """The block writer for ``dialect``; the message lists the dialects that have one."""
    from . import fanuc, grbl, linuxcnc  # noqa: F401 - modules register themselves

    choice(dialect, DIALECTS, "dialect")
    if dialect not in WRITERS:
        raise ProgramError(f"dialect {dialect!r} has no point-list writer; use one of {', '.join(sorted(WRITERS))}")
    return WRITERS[dialect]


def point_program(toolpath, settings: MachineSettings, title: str = "") -> PointProgram:
    """The program model of a :class:`~lagsym.toolpath.Toolpath` for one machine."""
    t = toolpath.tool
    tool = f"T{settings.tool_number} {t.shape.upper()} END D{fixed(t.diameter_mm, 3, trim=True)} MM"
    return PointProgram(points_mm=toolpath.points_mm, settings=settings, title=title, tool_comment=tool)


def write_program(program: PointProgram) -> str:
    """The program text, lines joined by the settings' line ending, ending with one.

    Examples
    --------
    >>> p = PointProgram(np.array([[0.0, 0.0, 1.0], [2.0, 0.0, 1.0]]), MachineSettings(dialect="linuxcnc"))
    >>> print(write_program(p), end="")
    G21 G17 G40 G49 G80 G90 G94
    G54
    T1 M06
    S3000 M03
    G00 X0.000 Y0.000
    G43 H1 Z50.000
    G01 Z1.000 F200.0
    X2.000 F600.0
    G00 Z50.000
    M05
    M02
    """
    lines = writer(program.settings.dialect)(program)
    eol = program.settings.eol
    return eol.join(lines) + eol


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
