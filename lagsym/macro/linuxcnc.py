"""LinuxCNC O-word macros: ``o100 while [..] .. o100 endwhile``, named parameters, every operation in ``[ ]``.

LinuxCNC computes in IEEE double precision (15 significant digits); named
parameters ``#<name>`` keep the program readable.
"""

from __future__ import annotations

from ..gcode import limits
from ..gcode.numbers import fixed
from ._render import expression, literal
from .model import Assign, Clamp, Loop, Move

__all__ = ["render", "MAX_BLOCK"]

MAX_BLOCK = limits.MAX_BLOCK["linuxcnc"]


def render(loops, settings, precision: int = 15, variable_base: int | None = None) -> str:
    """The LinuxCNC program for ``loops``; ``variable_base`` is ignored (named parameters)."""
    def name(v):
        return f"#<{v.name}>"

    def expr(e):
        return expression(e, name, precision)

    dp = settings.digits
    out = ["%", f"(lagsym surface macro, program {settings.program_number})",
           f"(surface {loops.form.shape[0]}x{loops.form.shape[1]}, normalized {loops.form.kind} form, "
           f"{precision}-digit arithmetic)",
           f"({loops.raster.size} points, rows along {loops.raster.direction})",
           f"G{'21' if settings.units == 'mm' else '20'} G17 G40 G49 G80 G90 G64 P0.001",
           settings.work_offset,
           f"T{settings.tool_number} M6",
           f"G43 H{settings.tool_number}",
           f"G0 Z{fixed(settings.safe_z_mm * settings.unit_factor, dp)}"]
    if settings.spindle_rpm:
        out.append(f"S{int(round(settings.spindle_rpm))} M3")
    x0, y0, z0 = loops.start
    out.append(f"G0 X{fixed(x0, dp)} Y{fixed(y0, dp)}")
    out.append(f"G1 Z{fixed(z0, dp)} F{fixed(settings.plunge_feed_mm_min * settings.unit_factor, 1, trim=True)}")
    out.append(f"F{fixed(settings.feed_mm_min * settings.unit_factor, 1, trim=True)}")
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
    out.append(f"G0 Z{fixed(settings.safe_z_mm * settings.unit_factor, dp)}")
    out += ["M5", "M2", "%"]
    return settings.eol.join(out) + settings.eol
