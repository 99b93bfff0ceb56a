"""LinuxCNC O-word macros: ``o100 while [..] .. o100 endwhile``, named parameters, every operation in ``[ ]``.

LinuxCNC computes in IEEE double precision (15 significant digits); named
parameters ``#<name>`` keep the program readable.
"""

from __future__ import annotations

from ..errors import ProgramError
from ._render import check_text, expression, header_comments, iso_end, iso_start, literal
from .model import Assign, Choose, Clamp, Loop, Move, SetItem

__all__ = ["render", "body_lines"]


def body_lines(loops, precision: int = 15) -> list[str]:
    """The blocks of the loops alone (no header, approach or end), for a program that frames them itself."""
    def name(v):
        return f"#<{v.name}>"

    def expr(e):
        return expression(e, name, precision)

    out: list[str] = []
    labels = iter(range(100, 10000))

    def emit(stmts, indent):
        pad = "  " * indent
        for s in stmts:
            if isinstance(s, Assign):
                out.append(f"{pad}{name(s.target)} = {expr(s.expr)}")
            elif isinstance(s, Clamp):
                n = next(labels)
                lim = literal(s.limit.value, precision)
                out.extend([f"{pad}o{n} if [{name(s.target)} GT {lim}]",
                            f"{pad}  {name(s.target)} = {lim}", f"{pad}o{n} endif"])
            elif isinstance(s, SetItem):
                out.append(f"{pad}#{s.number} = {literal(s.value.value, precision)}")
            elif isinstance(s, Choose):
                n = next(labels)
                out.extend([f"{pad}o{n} if [{name(s.test)} {s.op} {expr(s.limit)}]",
                            f"{pad}  {name(s.target)} = {expr(s.value)}", f"{pad}o{n} endif"])
            elif isinstance(s, Loop):
                n = next(labels)
                c = name(s.counter)
                out.append(f"{pad}{c} = 0.")
                out.append(f"{pad}o{n} while [{c} LE {literal(s.last, precision)}]")
                emit(s.body, indent + 1)
                out.append(f"{pad}  {c} = [{c} + 1.]")
                out.append(f"{pad}o{n} endwhile")
            elif isinstance(s, Move):
                out.append(f"{pad}G1 X{name(s.x)} Y{name(s.y)} Z{name(s.z)}")

    emit(loops.body, 0)
    return out


def render(loops, settings, precision: int = 15, variable_base: int | None = None, variables: str = "full") -> str:
    """The LinuxCNC program for ``loops``: named parameters, so neither a variable base nor a profile applies."""
    if variable_base is not None or variables != "full":
        raise ProgramError("a LinuxCNC macro uses named parameters: leave out the variable base and profile")
    out = ["%", f"({loops.title} PROGRAM {settings.program_number})"]
    out += [f"({c})" for c in header_comments(loops, settings, precision)]
    out.append(f"G{'21' if settings.units == 'mm' else '20'} G17 G40 G49 G80 G90 G64 P0.001")
    out += iso_start(loops, settings, ("M6", "M3"))
    out += body_lines(loops, precision)
    out += iso_end(settings, "M2") + ["%"]
    check_text(out, settings)
    return settings.eol.join(out) + settings.eol
