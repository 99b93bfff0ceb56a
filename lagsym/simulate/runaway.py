"""The runaway guard: a program that would never end is stopped within seconds, with the limit it hit.

Every run that does not end jumps back (a loop end, a ``GOTO`` or an ``FN 9``
to an earlier label) again and again, so the guard looks only at backward
jumps, and four things stop a run there:

* a loop that can be seen in the text never to end: a ``GOTO`` back, or a
  loop or ``IF``/``FN 9`` jump back on a condition that nothing in the loop
  can change (a constant, as ``WHILE [1 EQ 1]``, or variables no block of the
  loop sets), with no block between the target and the jump that can leave
  (no ``M02``/``M30`` or ``END PGM``, no ``M99`` or call, whose alarm ends the run, no jump or loop exit
  outside it): stopped the second time its jump runs;
* the program comes back to the same block with every variable, the
  position and the modes as they were before: it is deterministic, so it
  would loop forever (found with Brent's doubling, so a cycle of any length
  is seen within about three turns of it);
* ``max_idle_blocks`` blocks executed without a move: lagsym's own macros
  make a move every few hundred blocks at most, and a loop that moves
  nothing for that long is nearly always one whose exit test never becomes
  true;
* ``max_blocks`` blocks executed in all, which with :data:`BYTES_PER_MOVE`
  bounds the memory the moves can take.
"""

from __future__ import annotations

from decimal import Decimal

from ..errors import InputError
from ..gcode.program import END_M, unrun_code
from ..values import whole
from .alarms import BlockAlarm, ControlAlarm
from .blocks import (Assign, AssignNamed, End, Goto, IfGoto, IfGotoLabel, IfThen, OElse, OElseIf, OEndWhile, OIf,
                     OWhile, Stop, While, Words, probe_code)
from .control import ControlState

__all__ = ["Runaway", "endless_jumps", "MAX_BLOCKS", "MAX_IDLE_BLOCKS"]

MAX_BLOCKS = 5_000_000  # 2.0 times the 2.53 million of the README's Example 4 ball macro at 8 digits
MAX_PROGRAM_LINES = 100_000  # lines read and compiled: about 11 KB each while compiled, so about 1.1 GB
EXPRESSIONS_PER_LINE = 1  # bracketed expressions (each '[') the line limit allows, on average a line
MAX_IDLE_BLOCKS = 200_000  # lagsym's macros move every few hundred blocks at most (a 12x12 Heidenhain one: 613)


def check_lines(text: str, max_lines: int | None, source: str = "the program") -> None:
    """Refuse ``text`` of more than ``max_lines`` lines, or of more than :data:`EXPRESSIONS_PER_LINE` times as
    many bracketed expressions (each takes some 0.1 ms to read and compile), before any is read into blocks
    (None: no limit)."""
    if max_lines is None:
        return
    lines = text.count("\n") + 1
    if lines > whole(max_lines, "max_lines", 1, 1 << 62):
        raise InputError(f"{source}: {lines:,} lines, more than the limit of {max_lines:,} (about "
                         f"{lines * 11e3 / 1e9:.2g} GB to read and compile them); raise the limit (--max-lines)")
    # A bracketed expression costs about as much to read and compile as a whole block of a point list does.
    brackets = text.count("[")
    if brackets > EXPRESSIONS_PER_LINE * max_lines:
        raise InputError(f"{source}: {brackets:,} bracketed expressions, more than the limit of "
                         f"{EXPRESSIONS_PER_LINE * max_lines:,} (one for each line --max-lines allows); "
                         f"raise the limit (--max-lines)")


class Runaway:
    """The three checks of one run; :meth:`check` is called at every backward jump."""

    def __init__(self, max_blocks: int = MAX_BLOCKS, max_idle_blocks: int = MAX_IDLE_BLOCKS,
                 endless: dict[int, int] | None = None, blocks=()):
        self.max_blocks, self.max_idle_blocks = int(max_blocks), int(max_idle_blocks)
        self.endless, self.blocks = endless or {}, blocks
        self.moves_seen = 0
        self.idle_from = 0  # the block count at the last backward jump that found a new move
        self.snapshot: tuple | None = None  # (block index, ControlState.state()) at the last doubling
        self.turns, self.power = 0, 1

    def check(self, control, executed: int, target: int, block) -> None:
        """Raise the ``runaway`` alarm at ``block`` (which jumps back to index ``target``) if a check fails."""
        if self.endless.get(id(block)) == target:
            first = self.blocks[target]
            self._stop(f"the loop from line {first.line} to line {block.line} can never end: it goes back "
                       "unconditionally or on a condition nothing in it changes, and no block in it leaves", block,
                       question=False)
        if executed > self.max_blocks:
            self._stop(f"more than {self.max_blocks} blocks executed (the limit; --max-blocks N lifts it)", block)
        moves = len(control.moves)
        if moves != self.moves_seen:
            self.moves_seen, self.idle_from = moves, executed
        elif executed - self.idle_from > self.max_idle_blocks:
            self._stop(f"{executed - self.idle_from} blocks executed without a move, more than the limit of "
                       f"{self.max_idle_blocks} (--max-idle-blocks N lifts it)", block)
        snap = self.snapshot
        if snap is not None and snap[0] == target and control.same_state(snap[1]):
            self._stop(f"after {executed} blocks the program is back at the same block with every variable, "
                       "the position and the modes unchanged: it would loop forever", block, question=False)
        self.turns += 1
        if self.turns == self.power:
            self.snapshot, self.turns, self.power = (target, control.state()), 0, 2 * self.power

    @staticmethod
    def _stop(message: str, block, question: bool = True) -> None:
        raise ControlAlarm("runaway", message + ("; a loop that never ends?" if question else ""), block.line,
                           block.text)


# --------------------------------------------------------------------------- loops seen never to end


class _NotConstant(Exception):
    pass


class _Probe(ControlState):
    """A control with no variables: evaluating an expression on it says whether the expression is a constant."""

    def get(self, n: int) -> Decimal:
        raise _NotConstant

    def named(self, name: str) -> Decimal:
        raise _NotConstant


class _Reader(ControlState):
    """A control whose every variable reads ``value``, noting which are read."""

    def __init__(self, dialect: str, precision: int, value: int):
        super().__init__(dialect, precision, ((0, 0),))
        self.value, self.numbers, self.names_read = Decimal(value), set(), set()

    def get(self, n: int) -> Decimal:
        self.numbers.add(n)
        return self.value

    def named(self, name: str) -> Decimal:
        self.names_read.add(name)
        return self.value


def _reads(probe: _Probe, cond):
    """The variable numbers and names ``cond`` reads, or None where they depend on values (``#[#1]``)."""
    seen = []
    for value in (0, 1, 7):
        r = _Reader(probe.dialect, probe.precision, value)
        try:
            cond(r)
        except (BlockAlarm, ArithmeticError, ValueError):
            return None
        seen.append((r.numbers, r.names_read))
    return seen[0] if all(s == seen[0] for s in seen) else None


def _unchanged(probe: _Probe, cond, blocks, lo: int, hi: int) -> bool:
    """Whether no block from ``lo`` to ``hi`` can change what ``cond`` reads."""
    reads = _reads(probe, cond)
    if reads is None:
        return False
    numbers, names = reads
    for c in blocks[lo:hi + 1]:
        if probe_code(c) is not None:
            return False  # a probing move sets the result variables
        a = c.then if isinstance(c, IfThen) else c
        if isinstance(a, Assign):
            n = _constant(probe, a.target)
            if n is None or n in numbers:
                return False
        elif isinstance(a, AssignNamed) and a.name in names:
            return False
    return True


def _constant(probe: _Probe, expr):
    """The value of ``expr`` if it reads no variable (and raises no alarm), else None."""
    try:
        return expr(probe)
    except (_NotConstant, BlockAlarm, ArithmeticError, ValueError):
        return None


def endless_jumps(blocks, labels: dict[int, int], dialect: str, precision: int) -> dict[int, int]:
    """The backward jumps that, once taken, are taken forever: ``{id(block): target index}``.

    A jump qualifies when nothing from its target to it can end the program
    or leave that range, and it is unconditional (``ENDm`` of a bare ``DOm``,
    ``GOTO`` a constant) or its condition reads only what no block in the
    range sets: once it has gone back, its condition was true (the loop's
    head let the body run, or the ``IF`` jumped) and will be every time.
    """
    probe = _Probe(dialect, precision, ((0, 0),))
    found = {}
    for j, b in enumerate(blocks):
        back = _back(probe, blocks, labels, j, b)
        if back is None:
            continue
        target, cond = back
        if any(_may_leave(probe, blocks, labels, k, target, j) for k in range(target, j)):
            continue
        if cond is None or _unchanged(probe, cond, blocks, target, j):
            found[id(b)] = target
    return found


def _back(probe, blocks, labels, j: int, b) -> tuple[int, object] | None:
    """``(earlier index, its condition or None)`` for a block that jumps back, else None."""
    if isinstance(b, (End, OEndWhile)):
        return b.start, blocks[b.start].cond
    if isinstance(b, (Goto, IfGoto)):
        n = _constant(probe, b.number)
        target = None if n is None else labels.get(probe.index(n))
    elif isinstance(b, IfGotoLabel):
        target = labels.get(b.label)
    else:
        return None
    if target is None or target > j:
        return None
    return target, (b.cond if isinstance(b, (IfGoto, IfGotoLabel)) else None)


def _may_leave(probe, blocks, labels, k: int, lo: int, hi: int) -> bool:
    """Whether block ``k`` may end the run or go outside ``lo..hi`` (the range of the jump at ``hi``)."""
    c = blocks[k]
    inside = range(lo, hi + 1)
    if isinstance(c, Stop):
        return True
    if isinstance(c, Words):
        ms = [_constant(probe, f) for letter, f in c.words if letter == "M"]
        # an end, or a code the simulator refuses (a call, M99): its alarm ends the run too
        return any(v is None or v in END_M or unrun_code("M", v) is not None for v in ms)
    if isinstance(c, (While, OWhile)):  # its exit, unless it is the head of the loop that jumps back from hi
        return c.end + 1 not in inside and not (k == lo and getattr(blocks[hi], "start", None) == lo)
    if isinstance(c, (End, OEndWhile)):
        return c.start not in inside
    if isinstance(c, (OIf, OElseIf, OElse)):
        return any(getattr(c, a, -1) + 1 not in inside for a in ("next", "endif") if getattr(c, a, -1) >= 0)
    if isinstance(c, (Goto, IfGoto)):
        n = _constant(probe, c.number)
        return n is None or labels.get(probe.index(n)) not in inside
    if isinstance(c, IfGotoLabel):
        return labels.get(c.label) not in inside
    return False
