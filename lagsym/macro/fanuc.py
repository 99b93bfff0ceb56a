"""Fanuc Custom Macro B (also Haas): ``#`` variables, ``WHILE [..] DOm .. ENDm``, ``[ ]`` brackets.

Limits kept (see docs/macros.md): common variables ``#100-#199`` or
``#500-#999``; at most 3 nested ``DO`` levels (the program uses 2); at most 5
nested brackets (expressions here use at most 2); a decimal point on every
constant, at most 8 significant digits on 8-digit controls, no exponent;
``O`` number 1-9999; ``%`` framing.
"""

from __future__ import annotations

from ..errors import ProgramError
from ..gcode import limits
from ..gcode.numbers import fixed
from ._render import expression, literal, number_variables
from .model import Assign, Clamp, Loop, Move

__all__ = ["render", "VARIABLE_RANGES", "DEFAULT_BASE", "MAX_BLOCK"]

VARIABLE_RANGES = limits.MACRO_VARIABLES["fanuc"]
DEFAULT_BASE = 100
MAX_BLOCK = limits.MAX_BLOCK["fanuc"]


def _comment(text: str) -> str:
    return "(" + text.upper().replace("(", "").replace(")", "") + ")"


def render(loops, settings, precision: int = 8, variable_base: int | None = None) -> str:
    """The Fanuc macro program for ``loops`` (a :class:`~lagsym.macro.loops.MacroLoops`) as text with the settings' line endings."""
    base = DEFAULT_BASE if variable_base is None else int(variable_base)
    number = number_variables(loops.body, base, VARIABLE_RANGES)

    def name(v):
        return f"#{number[v.name]}"

    def expr(e):
        return expression(e, name, precision)

    dp = settings.digits
    out = ["%", f"O{settings.program_number:04d} {_comment('lagsym surface macro')}"]
    out.append(_comment(f"surface {loops.form.shape[0]}x{loops.form.shape[1]} normalized {loops.form.kind}, "
                        f"{precision} digit arithmetic"))
    out.append(_comment(f"{loops.raster.size} points, rows along {loops.raster.direction}"))
    out.append(f"G{'21' if settings.units == 'mm' else '20'} G17 G40 G49 G80 G90")
    out.append(settings.work_offset)
    out.append(f"T{settings.tool_number} M6")
    out.append(f"G43 H{settings.tool_number} G0 Z{fixed(settings.safe_z_mm * settings.unit_factor, dp)}")
    if settings.spindle_rpm:
        out.append(f"S{int(round(settings.spindle_rpm))} M3")
    x0, y0, z0 = loops.start
    out.append(f"G0 X{fixed(x0, dp)} Y{fixed(y0, dp)}")
    out.append(f"G1 Z{fixed(z0, dp)} F{fixed(settings.plunge_feed_mm_min * settings.unit_factor, 1, trim=True)}")
    out.append(f"F{fixed(settings.feed_mm_min * settings.unit_factor, 1, trim=True)}")

    def emit(stmts, depth):
        for s in stmts:
            if isinstance(s, Assign):
                out.append(f"{name(s.target)}={expr(s.expr)}")
            elif isinstance(s, Clamp):
                lim = literal(s.limit.value, precision)
                out.append(f"IF [{name(s.target)} GT {lim}] THEN {name(s.target)}={lim}")
            elif isinstance(s, Loop):
                if depth >= 3:
                    raise ProgramError("a Fanuc macro nests at most 3 WHILE loops")
                c = name(s.counter)
                out.append(f"{c}=0.")
                out.append(f"WHILE [{c} LE {literal(s.last, precision)}] DO{depth + 1}")
                emit(s.body, depth + 1)
                out.append(f"{c}=[{c}+1.]")
                out.append(f"END{depth + 1}")
            elif isinstance(s, Move):
                out.append(f"G1 X{name(s.x)} Y{name(s.y)} Z{name(s.z)}")

    emit(loops.body, 0)
    out.append(f"G0 Z{fixed(settings.safe_z_mm * settings.unit_factor, dp)}")
    out += ["M5", "M30", "%"]
    for line in out:
        if len(line) > MAX_BLOCK:
            raise ProgramError(f"block {line[:30]!r}... has {len(line)} characters, more than {MAX_BLOCK}")
    return settings.eol.join(out) + settings.eol
