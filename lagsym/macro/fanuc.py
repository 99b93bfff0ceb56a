"""Fanuc Custom Macro B (Fanuc, and Haas, whose macros are Fanuc's): ``#`` variables, ``WHILE [..] DOm .. ENDm``.

Limits kept (see docs/macros.md and :mod:`lagsym.controls`): the control's
common variables (a Fanuc's ``#100-#199`` or ``#500-#999``, ``#100-#149`` and
``#500-#531`` on the ``small`` profile; a Haas's general-purpose ranges); at
most 3 nested ``DO`` levels (the program uses 2); at most 5 nested brackets
(expressions here use at most 2); a decimal point on every constant, at most 8
significant digits on 8-digit controls, no exponent; the control's ``O``
number and ``%`` framing.
"""

from __future__ import annotations

from ..controls import Control
from ..errors import ProgramError
from ..gcode.limits import variable_ranges
from ._render import check_text, expression, header_comments, iso_end, iso_start, literal, number_variables
from .model import Assign, Choose, Clamp, Loop, Move, SetItem

__all__ = ["render", "body_lines", "DEFAULT_BASE"]

DEFAULT_BASE = 100


def body_lines(loops, precision: int = 8, variable_base: int | None = None, variables: str = "full", *,
               control: str | Control = "fanuc") -> list[str]:
    """The blocks of the loops alone (no header, approach or end), for a program that frames them itself.

    The variables are numbered from ``variable_base`` within the ranges of
    ``control``'s macro option ``variables``.
    """
    base = DEFAULT_BASE if variable_base is None else int(variable_base)
    number = number_variables(loops.body, base, variable_ranges(control, variables))

    def name(v):
        return f"#{number[v.name]}"

    def expr(e):
        return expression(e, name, precision)

    out: list[str] = []

    def emit(stmts, depth):
        for s in stmts:
            if isinstance(s, Assign):
                out.append(f"{name(s.target)}={expr(s.expr)}")
            elif isinstance(s, Clamp):
                lim = literal(s.limit.value, precision)
                out.append(f"IF [{name(s.target)} GT {lim}] THEN {name(s.target)}={lim}")
            elif isinstance(s, SetItem):
                out.append(f"#{s.number}={literal(s.value.value, precision)}")
            elif isinstance(s, Choose):
                out.append(f"IF [{name(s.test)} {s.op} {expr(s.limit)}] THEN {name(s.target)}={expr(s.value)}")
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
    return out


def render(loops, settings, precision: int = 8, variable_base: int | None = None, variables: str = "full") -> str:
    """The Fanuc macro program for ``loops`` (a :class:`~lagsym.macro.loops.MacroLoops`) as text with the settings' line endings."""
    out = ["%", settings.control.framing.program_word.format(settings.program_number) + f" ({loops.title})"]
    out += [f"({c})" for c in header_comments(loops, settings, precision)]
    out.append(f"G{'21' if settings.units == 'mm' else '20'} G17 G40 G49 G80 G90")
    out += iso_start(loops, settings, ("M6", "M3"))
    out += body_lines(loops, precision, variable_base, variables, control=settings.control)
    out += iso_end(settings, "M30") + ["%"]
    check_text(out, settings)
    return settings.eol.join(out) + settings.eol
