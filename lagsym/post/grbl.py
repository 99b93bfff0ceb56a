"""Grbl programs: no tool changer and no tool length offsets, so neither ``M06`` nor ``G43``."""

from __future__ import annotations

from .model import PointProgram, body, iso_comment, units_word

__all__ = ["blocks"]


def blocks(program: PointProgram) -> list[str]:
    """The blocks of a Grbl point-list program (every block well under Grbl's 80 characters)."""
    s = program.settings
    out = [f"({iso_comment(c)[:70]})" for c in (program.title, program.tool_comment) if iso_comment(c)]
    out += [f"{units_word(s)} G17 G90 G94", s.work_offset, f"S{int(round(s.spindle_rpm))} M03"]
    out += body(program, tool_length=False)
    out += ["M05", "M02"]
    return out
