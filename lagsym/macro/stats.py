"""How big a macro program is next to the point list it replaces, and how long each takes down a serial line.

The point-list size is an estimate, not a rendered program: one block
``G1 X... Y... Z...`` per raster point with the machine's decimals and line
ending, the coordinates written as :func:`lagsym.gcode.numbers.fixed` writes
them, plus the same preamble and postamble as the macro.  A real point-list
post may add block numbers or drop unchanged words; the estimate is within a
few per cent of a plain one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..gcode.program import macro_uses
from ..machine import bits_per_char
from . import heidenhain

__all__ = ["ProgramStats", "point_list_size", "transfer_seconds", "program_stats", "frame_bytes", "BITS_PER_CHAR_7E2"]

BITS_PER_CHAR_7E2 = bits_per_char(7, "even", 2)  # start bit, 7 data bits, even parity, 2 stop bits


def transfer_seconds(size_bytes: int, baud: int = 9600, bits_per_char: int = BITS_PER_CHAR_7E2) -> float:
    """Seconds to send ``size_bytes`` characters at ``baud`` (7E2: 11 bits a character).

    Examples
    --------
    >>> round(transfer_seconds(9600), 1)
    11.0
    """
    return size_bytes * bits_per_char / baud


def _width(values: np.ndarray, decimals: int) -> int:
    # Characters of fixed(v, decimals) summed over values, without formatting each one.
    a = np.round(np.abs(values), decimals)
    ints = np.floor(a)
    digits = np.where(ints >= 1, np.floor(np.log10(np.maximum(ints, 1))) + 1, 1)
    neg = (np.round(values, decimals) < 0) & (a > 0)
    return int(np.sum(digits + 1 + decimals + neg))


def point_list_size(points: np.ndarray, decimals: int = 3, eol: str = "\n", overhead: int = 0) -> int:
    """Bytes of a plain point list: ``G1 X.. Y.. Z..`` and a line ending per point, plus ``overhead``.

    Examples
    --------
    >>> point_list_size(np.array([[1.0, 2.0, -0.5]]), 3)
    25
    """
    pts = np.asarray(points, dtype=float)
    n = len(pts)
    return (n * (len("G1 X Y Z") + len(eol)) + sum(_width(pts[:, c], decimals) for c in range(3)) + overhead)


@dataclass(frozen=True)
class ProgramStats:
    """Sizes (bytes) and 9600-baud 7E2 transfer times (seconds) of a macro and its point list."""

    points: int
    macro_bytes: int
    point_list_bytes: int
    macro_seconds: float
    point_list_seconds: float

    def text(self) -> str:
        """The comparison as a few lines of text."""
        ratio = self.point_list_bytes / self.macro_bytes
        return (f"raster points:      {self.points}\n"
                f"macro program:      {self.macro_bytes} bytes, {self.macro_seconds:.1f} s at 9600 baud 7E2\n"
                f"point-list program: {self.point_list_bytes} bytes, "
                f"{_duration(self.point_list_seconds)} at 9600 baud 7E2 (estimate)\n"
                f"the point list is {ratio:.1f} times larger")


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.1f} s"
    return f"{seconds / 60:.1f} min" if seconds < 7200 else f"{seconds / 3600:.2f} h"


def _gcode_statement(line: str) -> bool:
    return bool(macro_uses(line))


_STATEMENTS = {"fanuc": _gcode_statement, "linuxcnc": _gcode_statement, "heidenhain": heidenhain.is_statement}
"""How each macro language's statements are told from the program's framing: G-code through the one reader
of blocks (:func:`~lagsym.gcode.program.macro_uses`), Heidenhain's conversational ``FN`` and ``LBL`` lines by
its own module."""


def frame_bytes(text: str, eol: str, language: str = "fanuc") -> int:
    """Bytes of a program outside its macro part: the lines before the first and after the last macro statement.

    ``language`` is the macro language the program is written in (a key of the control's ``macro``).
    """
    statement = _STATEMENTS[language]
    lines = text.split(eol)
    marks = [n for n, line in enumerate(lines) if statement(line)]
    if not marks:
        return len(text)
    keep = lines[:marks[0]] + lines[marks[-1] + 1:]
    return sum(len(line) + len(eol) for line in keep if line)


def program_stats(program, points: np.ndarray, settings, count: int | None = None) -> ProgramStats:
    """Compare ``program`` (a MacroProgram) with the point list over ``points`` (the planned (N, 3) points).

    The point list keeps the macro's preamble and postamble (:func:`frame_bytes`)
    and has one block per point (:func:`point_list_size`).  With ``count``,
    ``points`` is a sample of a raster of ``count`` points and the blocks are
    scaled from the sample's mean.
    """
    frame = frame_bytes(program.text, settings.eol, settings.control.macro.name)
    blocks = point_list_size(points, settings.digits, settings.eol)
    n = len(points) if count is None else int(count)
    if count is not None:
        blocks = round(blocks * n / len(points))
    plist = frame + blocks
    return ProgramStats(points=n, macro_bytes=program.size, point_list_bytes=plist,
                        macro_seconds=transfer_seconds(program.size), point_list_seconds=transfer_seconds(plist))
