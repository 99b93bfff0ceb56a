"""Point-list program text: one writer for every control, driven by the control's framing.

The program model and the moves every control shares live in
:mod:`lagsym.post.model` and :mod:`lagsym.post.moves`; what differs (``%``
framing, the ``O`` number, the safe-start words, the tool change, length
offsets, the end word, comment length) is read from the program's
:class:`~lagsym.controls.Control` (:attr:`~lagsym.machine.MachineSettings.control`).
"""

from __future__ import annotations

from ..controls import names
from ..errors import ProgramError
from .model import (PointProgram, body, check_blocks, check_settings, iso_comment, point_program, surface_comment,
                    units_word)
from .moves import format_moves

__all__ = ["PointProgram", "point_program", "write_program", "format_moves", "iso_comment", "blocks"]


def blocks(program: PointProgram) -> list[str]:
    """The blocks of a point-list program, framed as its control reads them.

    ``%`` and the ``O`` number with the title where the control takes them
    (else the title as a comment), the cutter and the surface's placement as
    comments, units and safe-start words, tool change (none where the control
    has no changer), work offset, spindle, the moves of :func:`~.model.body`,
    spindle off and the end word.
    """
    s = program.settings
    c = s.control
    if not c.point_lists:
        raise ProgramError(f"dialect {c.name!r} has no point-list writer; use one of "
                           f"{', '.join(names(point_lists=True))}")
    f = c.framing
    check_settings(s)
    out = ["%"] if f.percent else []
    title, tool = iso_comment(program.title), iso_comment(program.tool_comment)
    if f.program_word:
        out.append(f.program_word.format(int(s.program_number)) + (f" ({title})" if title else ""))
        out += [f"({tool})"] if tool else []
    else:
        out += [f.comment(t) for t in (title, tool) if t]
    out.append(f.comment(surface_comment(s)))
    out += [f.comment(iso_comment(n)) for n in s.notes]
    out.append(f"{units_word(s)} {f.safe_start}")
    if f.tool_change:
        out.append(f"T{s.tool_number} {f.tool_change}")
    out += [s.work_offset, f"S{int(round(s.spindle_rpm))} M03"]
    out += body(program, tool_length=c.length_offsets > 0)
    out += ["M05", f.end] + (["%"] if f.percent else [])
    check_blocks(out, c)
    return out


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
    lines = blocks(program)
    eol = program.settings.eol
    return eol.join(lines) + eol
