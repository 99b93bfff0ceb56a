"""The executor: links loops and branches, compiles the blocks and runs them on a :class:`~lagsym.simulate.control.ControlState`."""

from __future__ import annotations

from dataclasses import replace
from decimal import localcontext

from ..controls import control
from ..gcode.program import ascii_program
from ..values import whole
from ..progress import MOST_CALLS, Progress, Tally
from .alarms import BlockAlarm, ControlAlarm, alarm_at
from .blocks import Block, End, Label, OElse, OElseIf, OEndIf, OEndWhile, OIf, OWhile, While
from .compiler import alarm_block, compile_program
from .control import ControlState
from .reader import SIM_DIALECTS, detect_dialect, read_blocks
from .result import Simulation
from .runaway import MAX_BLOCKS, MAX_IDLE_BLOCKS, MAX_PROGRAM_LINES, Runaway, check_lines, endless_jumps

__all__ = ["simulate", "MAX_DO"]

MAX_DO = 3  # Fanuc: DO1..DO3


def simulate(text: str, dialect: str | None = None, precision: int = 8, *,
             variable_ranges=None, max_blocks: int = MAX_BLOCKS, max_idle_blocks: int = MAX_IDLE_BLOCKS,
             progress: Progress | None = None, target=None, max_lines: int | None = MAX_PROGRAM_LINES) -> Simulation:
    """Execute ``text`` as the control would, with ``precision`` significant digits.

    Parameters
    ----------
    text : str
        The program.
    dialect : str, optional
        A control with a macro language (``SIM_DIALECTS``: ``fanuc``, ``haas``,
        ``linuxcnc``, ``heidenhain``); guessed from the text if not given
        (a Fanuc, LinuxCNC or Heidenhain program: a Haas program reads as a Fanuc's).
    precision : int
        Significant digits of every stored value and every operation's result (8 or 15).
    variable_ranges : tuple of (int, int), optional
        Variable numbers the program may use; by default the control's
        (:attr:`lagsym.controls.Control.variables`: Fanuc #1-#33, #100-#199,
        #500-#999; LinuxCNC #1-#5602; Heidenhain Q0-Q99; ...).
    max_blocks : int
        Blocks executed before the run is stopped as a runaway loop; the
        moves take at most :data:`~lagsym.simulate.result.BYTES_PER_MOVE` bytes
        each, one move a block at most.
    max_idle_blocks : int
        Blocks executed without a move before the run is stopped as a runaway
        loop.  A run that comes back to a block with every variable and the
        position unchanged is stopped at once (see :mod:`~lagsym.simulate.runaway`).
    max_lines : int or None
        Refuse a program of more lines than this before any is read
        (``--max-lines``): each is read into typed blocks and compiled, about
        11 KB a line while it runs; None: no limit.
    target : ProbeTarget, optional
        What the probing moves (Fanuc/Haas ``G31``, LinuxCNC ``G38.2``)
        touch (:func:`~lagsym.simulate.probing.probe_target`); without one a
        probing move is an alarm, as every code the simulator does not run.
    progress : Progress, optional
        Told the blocks executed, every ``max_blocks`` / 200 (stage ``executing blocks``; the total
        is known only at the end: :mod:`lagsym.progress`).

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
    ascii_program(text)
    c = control(dialect or detect_dialect(text), "dialect", SIM_DIALECTS)
    if isinstance(precision, float) and precision.is_integer():
        precision = int(precision)
    precision = whole(precision, "precision (significant digits)", 1, 34)
    max_blocks = whole(max_blocks, "max_blocks", 1, 1 << 62)
    max_idle_blocks = whole(max_idle_blocks, "max_idle_blocks", 1, 1 << 62)
    check_lines(text, max_lines)
    blocks = _match_loops(read_blocks(text, c))
    labels = _labels(blocks)
    m = ControlState(c, int(precision), variable_ranges or None)
    m.target = target
    runaway = Runaway(max_blocks, max_idle_blocks, endless_jumps(blocks, labels, c, int(precision)), blocks)
    table, where = compile_program(m, blocks, labels)
    executed = _run(table, where, blocks, m, runaway, Tally(progress, "executing blocks"))
    return Simulation(dialect=c.name, precision=int(precision), moves=m.moves, blocks=executed,
                      output=tuple(m.output), probes=m.probes)


def _run(table, where, blocks, m: ControlState, runaway: Runaway, tally: Tally | None = None) -> int:
    """Run the compiled segments from the first block; the number of blocks executed, counted in ``tally``."""
    tally = tally if tally is not None else Tally(None, "executing blocks")
    pc, executed, n = 0, 0, len(blocks)
    step = max(runaway.max_blocks // MOST_CALLS, 1)
    tell = step if tally.live else 1 << 62
    tally.start()
    try:
        with localcontext(m.ctx):  # the operators of the compiled code round as the control does
            while pc < n:
                run, count, last = table[pc]
                nxt = run()
                executed += count
                if executed >= tell:
                    tally.add(executed - tally.done)
                    tell = executed + step
                if nxt is None:
                    break
                if nxt <= last:  # a run that never ends jumps back again and again: the guard looks only here
                    runaway.check(m, executed, nxt, blocks[last])
                pc = nxt
    except ControlAlarm:
        raise
    except (BlockAlarm, ArithmeticError) as e:
        k = alarm_block(e, where)
        if k is None:
            raise
        raise alarm_at(e, blocks[k]) from None
    tally.add(executed - tally.done)
    tally.finish()
    return executed


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
