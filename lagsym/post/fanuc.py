"""Fanuc-style ISO programs, also read by Haas and by Bridgeport controls that take ISO code.

``%`` framing, an ``O`` number with the title as a comment, and a safe-start
block; programs end with ``M30``.
"""

from __future__ import annotations

from .model import PointProgram, body, check_blocks, check_settings, iso_comment, surface_comment, units_word

__all__ = ["blocks"]


def blocks(program: PointProgram) -> list[str]:
    """The blocks of a Fanuc point-list program."""
    s = program.settings
    check_settings(s)
    title = iso_comment(program.title)
    out = ["%", f"O{int(s.program_number):04d}" + (f" ({title})" if title else "")]
    if program.tool_comment:
        out.append(f"({iso_comment(program.tool_comment)})")
    out.append(f"({surface_comment(s)})")
    out += [f"{units_word(s)} G17 G40 G49 G80 G90 G94", f"T{s.tool_number} M06", s.work_offset,
            f"S{int(round(s.spindle_rpm))} M03"]
    out += body(program)
    out += ["M05", "M30", "%"]
    check_blocks(out, s.dialect)
    return out
