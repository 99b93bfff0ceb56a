"""LinuxCNC programs: no ``%`` framing and no ``O`` number (an O word is a subroutine label there)."""

from __future__ import annotations

from .model import PointProgram, body, iso_comment, units_word

__all__ = ["blocks"]


def blocks(program: PointProgram) -> list[str]:
    """The blocks of a LinuxCNC point-list program, ending with ``M02``."""
    s = program.settings
    out = [f"({iso_comment(c)})" for c in (program.title, program.tool_comment) if iso_comment(c)]
    out += [f"{units_word(s)} G17 G40 G49 G80 G90 G94", s.work_offset, f"T{s.tool_number} M06",
            f"S{int(round(s.spindle_rpm))} M03"]
    out += body(program)
    out += ["M05", "M02"]
    return out
