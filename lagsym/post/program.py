"""Point-list program text: one block writer per dialect, looked up in :data:`WRITERS`.

The program model and the blocks every dialect shares live in
:mod:`lagsym.post.model`, the moves in :mod:`lagsym.post.moves`; each dialect
module (:mod:`lagsym.post.fanuc`, :mod:`lagsym.post.linuxcnc`,
:mod:`lagsym.post.grbl`) turns a :class:`PointProgram` into its blocks.
"""

from __future__ import annotations

from typing import Callable

from ..errors import ProgramError
from ..machine import DIALECTS
from ..values import choice
from . import fanuc, grbl, linuxcnc
from .model import PointProgram, iso_comment, point_program
from .moves import format_moves

__all__ = ["PointProgram", "point_program", "write_program", "format_moves", "iso_comment", "WRITERS", "writer"]

WRITERS: dict[str, Callable[[PointProgram], list[str]]] = {
    "fanuc": fanuc.blocks,
    "linuxcnc": linuxcnc.blocks,
    "grbl": grbl.blocks,
}


def writer(dialect: str) -> Callable[[PointProgram], list[str]]:
    """The block writer for ``dialect``; the message lists the dialects that have one."""
    choice(dialect, DIALECTS, "dialect")
    if dialect not in WRITERS:
        raise ProgramError(f"dialect {dialect!r} has no point-list writer; use one of {', '.join(sorted(WRITERS))}")
    return WRITERS[dialect]


def write_program(program: PointProgram) -> str:
    """The program text, lines joined by the settings' line ending, ending with one.

    Examples
    --------
    >>> import numpy as np
    >>> from lagsym.machine import MachineSettings
    >>> p = PointProgram(np.array([[0.0, 0.0, 1.0], [2.0, 0.0, 1.0]]), MachineSettings(dialect="linuxcnc"))
    >>> print(write_program(p), end="")
    (SURFACE IN MM 1 MM PER UNIT PROGRAM IN MM)
    G21 G17 G40 G49 G80 G90 G94
    T1 M06
    G54
    S3000 M03
    G00 G43 H1 Z50.000
    G00 X0.000 Y0.000
    Z3.000
    G01 Z1.000 F200.0
    X2.000 F600.0
    G00 Z50.000
    M05
    M02
    """
    lines = writer(program.settings.dialect)(program)
    eol = program.settings.eol
    return eol.join(lines) + eol
