"""What the dialect renderers share: variable numbering, constants and fully bracketed expressions."""

from __future__ import annotations

from fractions import Fraction

from ..errors import ProgramError
from ..gcode.numbers import fixed
from .model import Const, Op, Sqrt, Var, variables, written

__all__ = ["number_variables", "expression", "literal"]


def number_variables(body, base: int, ranges: tuple[tuple[int, int], ...], letter: str = "#") -> dict[str, int]:
    """Give every variable of ``body`` a number from ``base`` up; it must stay in one of ``ranges``."""
    names = variables(body)
    last = base + len(names) - 1
    if not any(lo <= base and last <= hi for lo, hi in ranges):
        allowed = ", ".join(f"{letter}{lo}-{letter}{hi}" for lo, hi in ranges)
        raise ProgramError(f"variables {letter}{base}-{letter}{last} ({len(names)} needed) are outside the "
                           f"ranges the control allows ({allowed}); choose another variable base")
    return {name: base + n for n, name in enumerate(names)}


def literal(value: Fraction, precision: int) -> str:
    """A constant with at most ``precision`` digits (see :func:`.model.written`), decimal point, no exponent."""
    d = written(Fraction(value), precision)
    return fixed(d, max(-d.as_tuple().exponent, 0), trim=True)


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
