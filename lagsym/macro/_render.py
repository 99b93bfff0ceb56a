"""What the dialect renderers share: variable numbering, constants and fully bracketed expressions."""

from __future__ import annotations

from fractions import Fraction

from ..errors import ProgramError
from ..gcode.limits import check_axis, check_blocks, check_settings
from ..gcode.numbers import fixed
from ..gcode.text import COOLANT_ON, iso_comment, surface_comment
from ..machine import MachineSettings
from .model import Const, Item, Op, Round, Sqrt, Var, variables, written

__all__ = ["number_variables", "expression", "literal", "iso_start", "iso_end", "header_comments", "check_text"]


def header_comments(loops, settings: MachineSettings, precision: int) -> list[str]:
    """What the program is, in ISO comment text: the form, the raster, the surface's units."""
    f, r = loops.form, loops.raster
    return [iso_comment(f"surface {f.shape[0]}x{f.shape[1]} normalized {f.kind} {precision} digit arithmetic"),
            iso_comment(f"{r.size} points rows along {r.direction}"), surface_comment(settings),
            *(iso_comment(n) for n in settings.notes)]


def _z(settings: MachineSettings, value_mm: float) -> str:
    return fixed(value_mm * settings.unit_factor, settings.digits)


def iso_start(loops, settings: MachineSettings, dialect_words: tuple[str, str]) -> list[str]:
    """Tool, work offset, spindle, clearance plane, coolant, over the first point, rapid to a feed height, plunge.

    ``dialect_words`` are the tool change and spindle-on words (``M6``, ``M3``).
    The rapid down stops a feed height above the first point, a tool position
    clear of the part (see :func:`lagsym.post.model.body`).
    """
    check_settings(settings)
    dp, uf = settings.digits, settings.unit_factor
    change, spindle = dialect_words
    out = [settings.work_offset, f"T{settings.tool_number} {change}"]
    if settings.spindle_rpm:
        out.append(f"S{int(round(settings.spindle_rpm))} {spindle}")
    out.append(f"G43 H{settings.length_offset_number} G0 Z{_z(settings, settings.safe_z_mm)}")
    out += [COOLANT_ON[settings.coolant]] if settings.coolant != "off" else []
    x0, y0, z0 = loops.start
    check_axis([x0, y0, z0, settings.safe_z_mm * uf], settings, "the first point")
    out.append(f"G0 X{fixed(x0, dp)} Y{fixed(y0, dp)}")
    approach = float(z0) + settings.feed_height_mm * uf
    if approach < settings.safe_z_mm * uf:
        out.append(f"Z{fixed(approach, dp)}")
    out.append(f"G1 Z{fixed(z0, dp)} F{fixed(settings.plunge_feed_mm_min * uf, 1, trim=True)}")
    out.append(f"F{fixed(settings.feed_mm_min * uf, 1, trim=True)}")
    return out


def iso_end(settings: MachineSettings, stop: str) -> list[str]:
    """Up to the clearance plane, coolant off, spindle off, and the program end word ``stop``."""
    return [f"G0 Z{_z(settings, settings.safe_z_mm)}", *([] if settings.coolant == "off" else ["M09"]), "M5", stop]


def check_text(lines, settings: MachineSettings) -> None:
    """Refuse a block longer than the dialect's control reads (see :mod:`lagsym.gcode.limits`)."""
    check_blocks(lines, settings.control)


def number_variables(body, base: int, ranges: tuple[tuple[int, int], ...], letter: str = "#") -> dict[str, int]:
    """Give every variable of ``body`` a number from ``base`` up; it must stay in one of ``ranges``."""
    names = variables(body)
    last = base + len(names) - 1
    if not any(lo <= base and last <= hi for lo, hi in ranges):
        allowed = ", ".join(f"{letter}{lo}-{letter}{hi}" for lo, hi in ranges)
        raise ProgramError(f"variables {letter}{base}-{letter}{last} ({len(names)} needed) are outside the "
                           f"ranges the control allows ({allowed}); choose another variable base")
    return {name: base + n for n, name in enumerate(names)}


def literal(value: Fraction, precision: int, leading_zero: bool = False) -> str:
    """A constant with at most ``precision`` digits, decimal point, no exponent.

    The digits are those of :func:`.model.written`; a lone leading zero is left
    out (``.66666667``), as a Fanuc counts it among the 8 digits it reads
    (``leading_zero`` keeps it, for the TNC's own notation).

    Examples
    --------
    >>> literal(Fraction(2, 3), 8), literal(Fraction(-1, 3000), 8), literal(Fraction(2, 3), 8, leading_zero=True)
    ('.66666667', '-.00033333', '0.66666667')
    """
    d = written(Fraction(value), precision)
    text = fixed(d, max(-d.as_tuple().exponent, 0), trim=True)
    if not leading_zero and text.lstrip("-").startswith("0.") and text.lstrip("-") != "0.":
        text = text.replace("0.", ".", 1)
    return text


def expression(e, name, precision: int) -> str:
    """``e`` with every binary operation in ``[ ]``; ``name(var)`` writes a variable.

    Adding a negative constant is written as a subtraction, so ``+-`` never appears.
    """
    if isinstance(e, Var):
        return name(e)
    if isinstance(e, Const):
        return literal(e.value, precision)
    if isinstance(e, Sqrt):
        return f"SQRT[{_inner(e.a, name, precision)}]"
    if isinstance(e, Round):
        return f"ROUND[{_inner(e.a, name, precision)}]"
    if isinstance(e, Item):
        return f"#[{name(e.index)}]"
    return f"[{_chain(e, name, precision)}]"


def _inner(e, name, precision: int) -> str:
    # Inside a function's own brackets an operation needs no second pair.
    return _chain(e, name, precision) if isinstance(e, Op) else expression(e, name, precision)


def _chain(e, name, precision: int) -> str:
    # A left operand with the same precedence is written without its own brackets:
    # [a*b*c] and [a+b-c] are evaluated left to right, as the Op tree says.
    op, b = e.op, e.b
    if isinstance(b, Const) and b.value < 0 and op in "+-":
        op, b = ("-" if op == "+" else "+"), Const(-b.value)
    a = e.a
    same = isinstance(a, Op) and ((a.op in "+-" and op in "+-") or (a.op in "*/" and op in "*"))
    left = _chain(a, name, precision) if same else expression(a, name, precision)
    return f"{left}{op}{expression(b, name, precision)}"
