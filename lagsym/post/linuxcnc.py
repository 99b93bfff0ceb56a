"""LinuxCNC programs: no ``%`` framing and no ``O`` number (an O word is a subroutine label there)."""

from __future__ import annotations

from .model import PointProgram, body, check_blocks, check_settings, iso_comment, surface_comment, units_word

__all__ = ["blocks"]


def blocks(program: PointProgram) -> list[str]:
    """The blocks of a LinuxCNC point-list program, ending with ``M02``."""
    s = program.settings
    check_settings(s)
    out = [f"({iso_comment(c)})" for c in (program.title, program.tool_comment) if iso_comment(c)]
    out.append(f"({surface_comment(s)})")
    out += [f"{units_word(s)} G17 G40 G49 G80 G90 G94", f"T{s.tool_number} M06", s.work_offset,
            f"S{int(round(s.spindle_rpm))} M03"]
    out += body(program)
    out += ["M05", "M02"]
    check_blocks(out, s.dialect)
    return out
