"""The executor: links loops and branches, then runs the blocks one by one on a :class:`Control`."""

from __future__ import annotations

from dataclasses import replace
from decimal import Decimal, InvalidOperation

from ..errors import ProgramError
from ..gcode.limits import VARIABLE_RANGES
from ..values import choice
from .alarms import BlockAlarm, ControlAlarm
from .blocks import (Assign, AssignNamed, Block, End, Goto, IfGoto, IfGotoLabel, IfThen, Label, Nop, OElse, OElseIf,
                     OEndIf, OEndWhile, OIf, OWhile, Stop, While, Words)
from .control import Control
from .reader import SIM_DIALECTS, detect_dialect, read_blocks
from .result import Simulation
from .runaway import MAX_BLOCKS, MAX_IDLE_BLOCKS, Runaway, endless_jumps

__all__ = ["simulate", "MAX_DO"]

MAX_DO = 3  # Fanuc: DO1..DO3


def simulate(text: str, dialect: str | None = None, precision: int = 8, *,
             variable_ranges=None, max_blocks: int = MAX_BLOCKS, max_idle_blocks: int = MAX_IDLE_BLOCKS) -> Simulation:
    """Execute ``text`` as the control would, with ``precision`` significant digits.

    Parameters
    ----------
    text : str
        The program.
    dialect : str, optional
        ``fanuc``, ``linuxcnc`` or ``heidenhain``; guessed from the text if not given.
    precision : int
        Significant digits of every stored value and every operation's result (8 or 15).
    variable_ranges : tuple of (int, int), optional
        Variable numbers the program may use; by default the dialect's (Fanuc
        #1-#33, #100-#199, #500-#999; LinuxCNC #1-#5602; Heidenhain Q0-Q99).
    max_blocks : int
        Blocks executed before the run is stopped as a runaway loop; the
        moves take at most :data:`~lagsym.simulate.result.BYTES_PER_MOVE` bytes
        each, one move a block at most.
    max_idle_blocks : int
        Blocks executed without a move before the run is stopped as a runaway
        loop.  A run that comes back to a block with every variable and the
        position unchanged is stopped at once (see :mod:`~lagsym.simulate.runaway`).

    Raises
    ------
    ControlAlarm
        Where the control would raise an alarm.
    InputError
        For a dialect that is not one of ``SIM_DIALECTS``.

    Examples
    --------
    >>> program = "#100=0.\\nWHILE [#100 LE 2.] DO1\\nG1 X#100 Y0. Z[#100*#100] F100.\\n#100=[#100+1.]\\nEND1\\nM30"
    >>> sim = simulate(program)
    >>> [(m.x, m.z) for m in sim.moves]
    [(0.0, 0.0), (1.0, 1.0), (2.0, 4.0)]
    """
    dialect = choice(dialect or detect_dialect(text), SIM_DIALECTS, "dialect")
    if int(precision) < 1 or int(precision) > 34:
        raise ProgramError(f"precision {precision} must be 1 to 34 significant digits")
    blocks = _match_loops(read_blocks(text, dialect))
    labels = _labels(blocks)
    m = Control(dialect, int(precision), variable_ranges or VARIABLE_RANGES[dialect])
    handlers = [_RUN[type(b)] for b in blocks]
    runaway = Runaway(max_blocks, max_idle_blocks, endless_jumps(blocks, labels, dialect, int(precision)), blocks)
    pc, executed = 0, 0
    while pc < len(blocks):
        b = blocks[pc]
        executed += 1
        try:
            nxt = handlers[pc](m, blocks, pc, b, labels)
        except BlockAlarm as e:
            raise ControlAlarm(e.alarm, e.message, b.line, b.text) from None
        except (InvalidOperation, OverflowError, ArithmeticError) as e:
            raise ControlAlarm("111", f"calculated data out of range ({type(e).__name__})", b.line, b.text) from None
        if nxt is None:
            break
        if nxt <= pc:  # a run that never ends jumps back again and again: the guard looks only here
            runaway.check(m, executed, nxt, b)
        pc = nxt
    return Simulation(dialect=dialect, precision=int(precision), moves=m.moves, blocks=executed)


# --------------------------------------------------------------------------- linking


def _match_loops(blocks: list[Block]) -> list[Block]:
    """Pair every loop start with its end and every if branch with the next one (the control's alarms if not).

    Returns the blocks with the partner indices (``end``/``start``,
    ``next``/``endif``) filled in.
    """
    links: dict[int, dict[str, int]] = {}
    stack: list[int] = []
    chains: list[list[int]] = []  # the branches of each open if, innermost last
    for i, b in enumerate(blocks):
        top = blocks[stack[-1]] if stack else None
        if isinstance(b, While):
            if not 1 <= b.loop <= MAX_DO:
                raise ControlAlarm("126", f"DO{b.loop}: loop numbers are 1 to {MAX_DO}", b.line, b.text)
            if len(stack) >= MAX_DO:
                raise ControlAlarm("126", f"more than {MAX_DO} nested DO loops", b.line, b.text)
            if any(blocks[j].loop == b.loop for j in stack):
                raise ControlAlarm("126", f"DO{b.loop} inside a loop with the same number", b.line, b.text)
            stack.append(i)
        elif isinstance(b, End):
            if not isinstance(top, While) or top.loop != b.loop:
                raise ControlAlarm("124", f"END{b.loop} without its DO{b.loop}", b.line, b.text)
            j = stack.pop()
            links[j], links[i] = {"end": i}, {"start": j}
        elif isinstance(b, OWhile):
            stack.append(i)
        elif isinstance(b, OIf):
            stack.append(i)
            chains.append([i])
        elif isinstance(b, OEndWhile):
            if not isinstance(top, OWhile) or top.oword != b.oword:
                raise ControlAlarm("o-word", f"o{b.oword} endwhile without its o{b.oword} while", b.line, b.text)
            j = stack.pop()
            links[j], links[i] = {"end": i}, {"start": j}
        elif isinstance(b, (OElseIf, OElse, OEndIf)):
            if not isinstance(top, (OIf, OElseIf, OElse)) or top.oword != b.oword:
                raise ControlAlarm("o-word", f"o{b.oword} {b.KEYWORD} without its o{b.oword} if", b.line, b.text)
            j = stack.pop()
            if not isinstance(top, OElse):
                links.setdefault(j, {})["next"] = i
            if isinstance(b, OEndIf):
                for k in chains.pop():
                    links.setdefault(k, {})["endif"] = i
            else:
                stack.append(i)
                chains[-1].append(i)
    if stack:
        b = blocks[stack[-1]]
        if isinstance(b, While):
            raise ControlAlarm("124", f"DO{b.loop} without its END{b.loop}", b.line, b.text)
        raise ControlAlarm("o-word", f"o{b.oword} {b.KEYWORD} is never closed", b.line, b.text)
    return [replace(b, **links[i]) if i in links else b for i, b in enumerate(blocks)]


def _labels(blocks: list[Block]) -> dict[int, int]:
    """Jump targets: Heidenhain ``LBL n`` (the last one wins) and Fanuc ``N`` numbers (the first one wins)."""
    labels: dict[int, int] = {}
    for i, b in enumerate(blocks):
        if isinstance(b, Label):
            labels[b.number] = i
        elif b.sequence is not None:
            labels.setdefault(b.sequence, i)
    return labels


# --------------------------------------------------------------------------- running
# Each handler runs block ``b`` at index ``pc`` and returns the index of the next block, or None to stop.


def _jump(labels, n: int) -> int:
    if n not in labels:
        raise BlockAlarm("128", f"sequence number or label {n} not found")
    return labels[n]


def _assign(m: Control, blocks, pc: int, b: Assign, labels) -> int:
    m.set(b.target(m), b.value(m))
    return pc + 1


def _assign_named(m: Control, blocks, pc: int, b: AssignNamed, labels) -> int:
    m.names[b.name] = m.ctx.plus(b.value(m))
    return pc + 1


def _while(m: Control, blocks, pc: int, b: While | OWhile, labels) -> int:
    if b.cond is not None and not b.cond(m):
        return b.end + 1
    return pc + 1


def _end(m: Control, blocks, pc: int, b: End | OEndWhile, labels) -> int:
    return b.start


def _if(m: Control, blocks, pc: int, b: OIf, labels) -> int:
    j, branch = pc, b
    while not branch.cond(m):  # try the if, then each elseif, in turn
        j = branch.next
        branch = blocks[j]
        if not isinstance(branch, OElseIf):
            break  # the else (its body runs) or the endif
    return j + 1


def _skip_to_endif(m: Control, blocks, pc: int, b: OElseIf | OElse, labels) -> int:
    return b.endif + 1  # reached from a branch that ran: skip the rest


def _next(m: Control, blocks, pc: int, b: Block, labels) -> int:
    return pc + 1


def _stop(m: Control, blocks, pc: int, b: Stop, labels) -> None:
    return None


def _if_then(m: Control, blocks, pc: int, b: IfThen, labels) -> int | None:
    if b.cond(m):
        return _RUN[type(b.then)](m, blocks, pc, b.then, labels)
    return pc + 1


def _goto(m: Control, blocks, pc: int, b: Goto, labels) -> int:
    return _jump(labels, m.index(b.number(m)))


def _if_goto(m: Control, blocks, pc: int, b: IfGoto, labels) -> int:
    if b.cond(m):
        return _jump(labels, m.index(b.number(m)))
    return pc + 1


def _if_goto_label(m: Control, blocks, pc: int, b: IfGotoLabel, labels) -> int:
    if b.cond(m):
        return _jump(labels, b.label)
    return pc + 1


def _words(m: Control, blocks, pc: int, b: Words, labels) -> int | None:
    values: dict[str, Decimal] = {}
    gs: list[Decimal] = []
    ms: list[Decimal] = []
    for letter, f in b.words:
        v = f(m)
        if letter == "G":
            gs.append(v)
        elif letter == "M":
            ms.append(v)
        else:
            values[letter] = v
    for g in gs:
        if g in (0, 1, 2, 3):
            m.motion = f"G{int(g)}"
        elif g == 90:
            m.absolute = True
        elif g == 91:
            m.absolute = False
    if "F" in values:
        m.feed = values["F"]
    if m.motion in ("G2", "G3") and any(a in values for a in "XYZ"):
        raise BlockAlarm("arc", "arcs are outside what the simulator runs")
    m.move(b.line, values)
    if any(v in (2, 30, 99) for v in ms):
        return None  # end of program
    return pc + 1


_RUN = {
    Assign: _assign, AssignNamed: _assign_named, Words: _words,
    While: _while, End: _end, IfThen: _if_then, Goto: _goto, IfGoto: _if_goto,
    Label: _next, IfGotoLabel: _if_goto_label, Stop: _stop, Nop: _next,
    OWhile: _while, OEndWhile: _end, OIf: _if, OElseIf: _skip_to_endif, OElse: _skip_to_endif, OEndIf: _next,
}
