"""Heidenhain conversational Q-parameter programs (TNC controls of Bridgeport Interact mills).

Every operation is one ``FN`` block: ``FN 0`` assigns, ``FN 1``-``FN 4`` add,
subtract, multiply and divide, ``FN 12: IF .. LT .. GOTO LBL n`` jumps.  A
loop is a label, its body, an increment and a conditional jump back, so it
runs at least once (every loop of a surface program does).  Blocks are numbered from
0; positions and constants carry a sign, as the TNC writes them.
"""

from __future__ import annotations

import re

from ..errors import ProgramError
from ..gcode.limits import check_axis, check_blocks, check_settings, variable_ranges
from ..gcode.numbers import fixed
from ._render import header_comments, literal, number_variables
from .model import Assign, Choose, Clamp, Const, Loop, Move, Op, Sqrt, Var
from .model import variables as variables_of

__all__ = ["render", "DEFAULT_BASE", "MAX_LABEL"]

DEFAULT_BASE = 1
MAX_LABEL = 254
_FN = {"+": 1, "-": 2, "*": 3, "/": 4}
SCRATCH = 6  # scratch Q parameters for the parts of an expression


_STATEMENT = re.compile(r"^\s*\d*\s*(?:FN\s*\d+\s*:|LBL\s)")


def is_statement(line: str) -> bool:
    """Whether a line of a conversational program is a Q-parameter statement (``FN ..:``) or a label (``LBL``).

    Examples
    --------
    >>> is_statement("12 LBL 1"), is_statement("13 FN 3: Q33 = +Q2 * +0.5"), is_statement("6 L Z+400.000 R0 FMAX M3")
    (True, True, False)
    """
    return bool(_STATEMENT.match(line))


def _reads(e, v: Var) -> bool:
    if isinstance(e, Var):
        return e == v
    if isinstance(e, Sqrt):
        return _reads(e.a, v)
    return isinstance(e, Op) and (_reads(e.a, v) or _reads(e.b, v))


def _signed(text: str) -> str:
    text = text[:-1] if text.endswith(".") else text
    return text if text.startswith("-") else "+" + text


class _Blocks:
    """The FN blocks of the loops: Q numbers, labels and the block list they are appended to."""

    def __init__(self, number: dict[str, int], precision: int, feed: str, out: list[str]):
        self.number, self.precision, self.feed, self.out = number, precision, feed, out
        self.labels = iter(range(1, MAX_LABEL + 1))

    def q(self, v: Var) -> str:
        return f"Q{self.number[v.name]}"

    def operand(self, e) -> str:
        if isinstance(e, Var):
            return "+" + self.q(e)
        return _signed(literal(e.value, self.precision, leading_zero=True))

    def assign(self, target: Var, e, depth: int = 0) -> None:
        # One FN block per operation.  The left operand is built in the target itself
        # (unless the right operand reads the target), the right one in a scratch Q.
        q, operand, out = self.q, self.operand, self.out
        if isinstance(e, (Var, Const)):
            out.append(f"FN 0: {q(target)} = {operand(e)}")
            return
        if isinstance(e, Sqrt):
            arg = e.a
            if isinstance(arg, (Op, Sqrt)):
                self.assign(target, arg, depth)
                arg = target
            out.append(f"FN 5: {q(target)} = SQRT {operand(arg)}")
            return
        a, b = e.a, e.b
        if isinstance(a, (Op, Sqrt)):
            dest = Var(f"h{depth}") if _reads(b, target) else target
            self.assign(dest, a, depth + 1)
            a = dest
        if isinstance(b, (Op, Sqrt)):
            tmp = Var(f"h{depth + 1}")
            self.assign(tmp, b, depth + 2)
            b = tmp
        out.append(f"FN {_FN[e.op]}: {q(target)} = {operand(a)} {e.op} {operand(b)}")

    def label(self) -> int:
        try:
            return next(self.labels)
        except StopIteration:
            raise ProgramError(f"the program needs more than {MAX_LABEL} labels") from None

    def emit(self, stmts) -> None:
        q, out = self.q, self.out
        for s in stmts:
            if isinstance(s, Assign):
                self.assign(s.target, s.expr)
            elif isinstance(s, Clamp):
                n = self.label()
                lim = self.operand(s.limit)
                out.extend([f"FN 12: IF +{q(s.target)} LT {lim} GOTO LBL {n}",
                            f"FN 0: {q(s.target)} = {lim}", f"LBL {n}"])
            elif isinstance(s, Choose):
                # Skip the assignment unless test OP limit: jump on the opposite relation and on equality.
                n = self.label()
                t, lim = "+" + q(s.test), self.operand(s.limit)
                other = "FN 12: IF {} LT {}" if s.op == "GT" else "FN 11: IF {} GT {}"
                out.extend([other.format(t, lim) + f" GOTO LBL {n}", f"FN 9: IF {t} EQU {lim} GOTO LBL {n}"])
                self.assign(s.target, s.value)
                out.append(f"LBL {n}")
            elif isinstance(s, Loop):
                n = self.label()
                c = q(s.counter)
                out.extend([f"FN 0: {c} = +0", f"LBL {n}"])
                self.emit(s.body)
                out.extend([f"FN 1: {c} = +{c} + +1", f"FN 12: IF +{c} LT +{s.last + 1} GOTO LBL {n}"])
            elif isinstance(s, Move):
                out.append(f"L X+{q(s.x)} Y+{q(s.y)} Z+{q(s.z)} R0 {self.feed}")


def render(loops, settings, precision: int = 8, variable_base: int | None = None, variables: str = "full") -> str:
    """The Heidenhain program for ``loops``: ``FN`` arithmetic on Q parameters, labels and jumps.

    The datum is the control's active preset (a TNC has no G-code work
    offset); ``M30`` at the end also stops the spindle and the coolant.
    """
    check_settings(settings)
    base = DEFAULT_BASE if variable_base is None else int(variable_base)
    names = variables_of(loops.body) + [f"h{n}" for n in range(SCRATCH)]
    number = number_variables([Assign(Var(n), Const(0)) for n in names], base,
                              variable_ranges(settings.control, variables), letter="Q")
    dp, uf = settings.digits, settings.unit_factor
    unit = "MM" if settings.units == "mm" else "INCH"

    def pos(v) -> str:
        return _signed(fixed(v, dp))

    safe = pos(settings.safe_z_mm * uf)
    out: list[str] = [f"BEGIN PGM {settings.program_number} {unit}", f"; {loops.title}"]
    out += [f"; {c}" for c in header_comments(loops, settings, precision)]
    out += [f"TOOL CALL {settings.tool_number} Z S{int(round(settings.spindle_rpm))}",
            f"L Z{safe} R0 FMAX M3"]
    x0, y0, z0 = loops.start
    check_axis([x0, y0, z0, settings.safe_z_mm * uf], settings, "the first point")
    cool = {"off": "", "flood": " M8", "mist": " M7"}[settings.coolant]
    out.append(f"L X{pos(x0)} Y{pos(y0)} R0 FMAX{cool}")
    approach = float(z0) + settings.feed_height_mm * uf
    if approach < settings.safe_z_mm * uf:
        out.append(f"L Z{pos(approach)} R0 FMAX")
    out.append(f"L Z{pos(z0)} R0 F{int(round(settings.plunge_feed_mm_min * uf))}")
    feed = f"F{int(round(settings.feed_mm_min * uf))}"
    _Blocks(number, precision, feed, out).emit(loops.body)
    if settings.coolant != "off":
        out.append(f"L Z{safe} R0 FMAX M9")
    out.append(f"L Z{safe} R0 FMAX M30")
    out.append(f"END PGM {settings.program_number} {unit}")
    lines = [f"{n} {line}" for n, line in enumerate(out)]
    check_blocks(lines, settings.control)
    return settings.eol.join(lines) + settings.eol
