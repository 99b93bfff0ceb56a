"""Grbl programs: no tool changer and no tool length offsets, so neither ``M06`` nor ``G43``."""

from __future__ import annotations

from .model import PointProgram, body, check_blocks, check_settings, iso_comment, surface_comment, units_word

__all__ = ["blocks"]


def blocks(program: PointProgram) -> list[str]:
    """The blocks of a Grbl point-list program (every block within Grbl's 80 characters)."""
    s = program.settings
    check_settings(s)
    out = [f"({iso_comment(c)[:70]})" for c in (program.title, program.tool_comment) if iso_comment(c)]
    out.append(f"({surface_comment(s)[:70]})")
    out += [f"{units_word(s)} G17 G90 G94", s.work_offset, f"S{int(round(s.spindle_rpm))} M03"]
    out += body(program, tool_length=False)
    out += ["M05", "M02"]
    check_blocks(out, s.dialect)
    return out
