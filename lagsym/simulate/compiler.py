"""The compiler: each straight run of blocks becomes one Python function, so a block is read once and runs as code.

A *segment* is a run of blocks that always execute one after the other:
it starts at a block some jump can reach (a loop's head or exit, a label,
an ``N`` number, the block after a branch) and ends at the next such block
or at a block that decides where to go (a loop's head or end, an
``IF .. GOTO``, ``M30``).  Its function does the arithmetic of all its blocks
with the :mod:`decimal` operators -- the executor runs them under the
control's context, so ``a * b`` is exactly ``ctx.multiply(a, b)``, rounded to
the control's digits -- keeps the variables it uses in Python locals and
writes back those it set, appends its moves to the columns of
:class:`~lagsym.simulate.result.SimMoves`, and returns the index of the next
block (None to end).

What the closures of :mod:`~lagsym.simulate.expressions` do through the
control's methods, the code does the same way, in the same order: every
result and every stored value rounded as before, a constant read as the
control reads it (folded once when it raises no alarm, read when the block
runs when it does), a variable out of range, a division by zero or a jump
to a missing label raising the same alarm when its block runs.  An alarm's
block is found from the line of the generated code that raised it
(:func:`alarm_block`).
"""

from __future__ import annotations

import ast
import re
from decimal import ROUND_HALF_UP, Decimal

from ..gcode.program import unrun_code
from .alarms import BlockAlarm, alarm_at, feed_zero
from .blocks import (Assign, AssignNamed, End, Goto, IfGoto, IfGotoLabel, IfThen, OElse, OElseIf, OEndWhile,
                     OIf, OWhile, Output, Stop, While, Words, probe_code)
from .codegen import STOPS, Segment
from .expressions import closure

__all__ = ["compile_program", "alarm_block", "SOURCE_NAME"]

SOURCE_NAME = "<lagsym-macro>"
_CONTROL = (While, OWhile, End, OEndWhile, OIf, OElseIf, OElse, Goto, IfGoto, IfGotoLabel, Stop)
MAX_SEGMENT = 100  # blocks in one function at most
_BATCH_LINES = 5000  # lines of generated code compiled at a time
_NAME = re.compile(r"\b[A-Za-z_]\w*\b")


def _leaders(blocks, labels) -> list[int]:
    """The indices a run can reach other than from the block before: where segments start."""
    n = len(blocks)
    starts = {0, *labels.values()}
    for i, b in enumerate(blocks):
        if isinstance(b, _CONTROL):
            starts.add(i + 1)
            starts.update(getattr(b, name) + 1 for name in ("end", "next", "endif") if getattr(b, name, -1) >= 0)
            if getattr(b, "start", -1) >= 0:
                starts.add(b.start)
        elif isinstance(b, Words) and any(k == "M" for k, _ in b.words):
            starts.add(i + 1)
        elif isinstance(b, Output) or probe_code(b) is not None:
            starts.add(i + 1)  # it reads and sets variables and state outside the segment's locals
    starts = sorted(s for s in starts if s < n)
    cut = []  # long straight runs (a point list) in pieces: the compiler's time and memory stay linear
    for a, b in zip(starts, starts[1:] + [n]):
        cut += range(a, b, MAX_SEGMENT)
    return cut


def _modal_g(m, g) -> None:
    if m.probing is not None and f"G{_code(g)}" == m.probing.move:
        m.probe_pending = round(float(g), 1)  # this block's move probes
        if m.probing.checks_contact:
            m.motion = m.probing.move  # G38.2 is a motion mode on LinuxCNC; G31 is one-shot on a Fanuc
        return
    why = unrun_code("G", g)
    if why is not None:
        raise BlockAlarm("not-run", f"G{_code(g)} {why}, which the simulator does not run")
    if g in (0, 1, 2, 3):
        m.motion = f"G{int(g)}"
    elif g == 90:
        m.absolute = True
    elif g == 91:
        m.absolute = False


def _m_check(value) -> None:
    """Refuse an ``M`` code that may call, return or move (:func:`lagsym.gcode.program.unrun_code`)."""
    why = unrun_code("M", value)
    if why is not None:
        raise BlockAlarm("not-run", f"M{_code(value)} {why}, which the simulator does not run")


def _code(value) -> str:
    """A G or M number as a control shows it: ``98``, ``66.1``."""
    v = round(float(value), 1)
    return f"{v:g}" if v != int(v) else f"{int(v)}"


def _constant_words(m, run) -> None:
    """Blocks whose words are all constants, ``(block, ((letter, value), ..))`` each: modes and moves in turn.

    What the generated code of such a block would do, without code of its own
    (a point list compiles in no time); an alarm names its block here.
    """
    for b, pairs in run:
        values = {}
        try:
            for letter, v in pairs:
                if letter == "G":
                    _modal_g(m, v)
                elif letter == "M":
                    _m_check(v)
                else:
                    values[letter] = v
            if "F" in values:
                m.feed = values["F"]
            if m.motion not in ("G0", "G1") and m.probe_pending is None and any(a in values for a in "XYZ"):
                _arc(m)
            m.move(b.line, values)
        except (BlockAlarm, ArithmeticError) as e:
            raise alarm_at(e, b) from None


def _run_words(m, b) -> None:
    """A block of words run through the control's own methods (a probing move: its state lives on the control)."""
    try:
        pairs = tuple((letter, e(m)) for letter, e in b.words)
    except (BlockAlarm, ArithmeticError) as e:
        raise alarm_at(e, b) from None
    _constant_words(m, ((b, pairs),))


def _send(m, b) -> None:
    try:
        m.send(b.action, b.items)
    except (BlockAlarm, ArithmeticError) as e:
        raise alarm_at(e, b) from None


def _no_feed(m) -> None:
    raise feed_zero(m.feed)


def _arc(m) -> None:
    """Refuse a move in a motion mode the simulator does not run: an arc, or a probing mode carried on."""
    if m.motion in ("G2", "G3"):
        raise BlockAlarm("arc", "arcs are outside what the simulator runs")
    raise BlockAlarm("not-run", f"a move in {m.motion} mode without its {m.motion} word: the simulator runs a "
                                f"probing move only in the block that gives it")


def _environment(m, labels) -> dict:
    """The names the generated code uses, bound once for the run."""
    ctx = m.ctx

    def jump(n: int) -> int:
        if n not in labels:
            raise BlockAlarm("128", f"sequence number or label {n} not found")
        return labels[n]

    def mod(b, a):  # ``a MOD b`` with ``b`` evaluated first, as the closure does
        return ctx.remainder(a, b) if b else m.divide(a, b)

    line, rapid, x, y, z, feed = m.moves.appenders()
    return {"m": m, "V": m.vars, "NM": m.names, "POS": m.pos, "Z": Decimal(0), "ONE": Decimal(1),
            "ZERO": Decimal(0), "P": ctx.plus, "POW": ctx.power, "DIV": m.divide, "MOD": mod, "FUNC": m.func,
            "ATAN2": m.atan2, "GET": m.get, "GETN": m.named, "CHECK": m.check, "CONST": m.const, "JUMP": jump,
            "RHU": ROUND_HALF_UP, "GMODAL": _modal_g, "MCHECK": _m_check, "ARC": _arc, "NOFEED": _no_feed,
            "RUNWORDS": _run_words, "SEND": _send, "WORDS": _constant_words, "STOPS": STOPS,
            "A_LINE": line, "A_RAPID": rapid, "A_X": x, "A_Y": y, "A_Z": z, "A_F": feed}


class _Program:
    """The constants, names and source lines of all segments of one program on one control."""

    def __init__(self, m, blocks, labels):
        self.m, self.blocks, self.labels = m, blocks, labels
        self.env = _environment(m, labels)
        self.consts: dict[tuple, str] = {}
        self.names: dict[str, str] = {}

    def in_range(self, n: int) -> bool:
        return any(lo <= n <= hi for lo, hi in self.m.ranges)

    def named_local(self, name: str) -> str:
        return self.names.setdefault(name, f"n{len(self.names)}")

    def intern(self, value: Decimal) -> str:
        key = (str(value), value.as_tuple())
        if key not in self.consts:
            self.consts[key] = f"k{len(self.consts)}"
            self.env[self.consts[key]] = value
        return self.consts[key]

    def constant(self, node):
        """The value of a tree that reads no variable, or None if it reads one or raises (it raises when run)."""
        kind = node[0]
        if kind == "dec":
            return Decimal(node[1])
        if kind in ("var", "named", "lit", "idx", "ind") or (kind != "num" and _reads_variables(node)):
            return None
        try:
            return self.m.const(node[1]) if kind == "num" else closure(node)(self.m)
        except (BlockAlarm, ArithmeticError, ValueError):
            return None

    def fold(self, node):
        value = self.constant(node)
        return None if value is None else self.intern(value)

    def segment(self, start: int, stop: int) -> tuple[list[tuple[str, int]], int]:
        """The lines of the function for blocks ``start`` to ``stop - 1`` and the index of its last block."""
        cached = not any(_dynamic(b) for b in self.blocks[start:stop])
        seg = Segment(self, cached)
        for i in range(start, stop):
            b = self.blocks[i]
            if isinstance(b, Output) or probe_code(b) is not None:
                seg.write_back()
                seg.block = i
                name = f"b{i}"
                self.env[name] = b
                seg.emit(f"{'SEND' if isinstance(b, Output) else 'RUNWORDS'}(m, {name})")
                seg.emit(f"return {i + 1}")
                return seg.lines, i
            if isinstance(b, Words) and seg.constant_words(i, b):
                ms = [v for letter, v in seg.pending[-1][1] if letter == "M"]
                if ms:
                    seg.write_back()
                    seg.emit("return None" if any(v in STOPS for v in ms) else f"return {i + 1}")
                    return seg.lines, i
                continue
            seg.flush()
            seg.block = i
            if isinstance(b, _CONTROL):
                seg.write_back()
                self.flow(seg, i, b)
                return seg.lines, i
            if isinstance(b, Assign):
                seg.assign(b)
            elif isinstance(b, AssignNamed):
                seg.assign_named(b)
            elif isinstance(b, IfThen):
                seg.if_then(b)
            elif isinstance(b, Words) and seg.words(i, b):
                return seg.lines, i
        seg.write_back()
        seg.emit(f"return {stop}")
        return seg.lines, stop - 1

    def flow(self, seg: Segment, i: int, b) -> None:
        """The code of a block that decides where the run goes."""
        if isinstance(b, (While, OWhile)):
            if b.cond is not None:
                seg.emit(f"if not {seg.value(b.cond.node, truth=True)}: return {b.end + 1}")
            seg.emit(f"return {i + 1}")
        elif isinstance(b, (End, OEndWhile)):
            seg.emit(f"return {b.start}")
        elif isinstance(b, OIf):
            j, branch = i, b
            while True:  # the if, then each elseif in turn; the else (its body runs) or the endif
                seg.emit(f"if {seg.value(branch.cond.node, truth=True)}: return {j + 1}")
                j = branch.next
                branch = self.blocks[j]
                if not isinstance(branch, OElseIf):
                    break
            seg.emit(f"return {j + 1}")
        elif isinstance(b, (OElseIf, OElse)):
            seg.emit(f"return {b.endif + 1}")  # reached from a branch that ran: skip the rest
        elif isinstance(b, (Goto, IfGoto)):
            number = f"int({seg.value(b.number.node)}.to_integral_value(RHU))"
            if isinstance(b, Goto):
                seg.emit(f"return JUMP({number})")
            else:
                seg.emit(f"if {seg.value(b.cond.node, truth=True)}: return JUMP({number})")
                seg.emit(f"return {i + 1}")
        elif isinstance(b, IfGotoLabel):
            seg.emit(f"if {seg.value(b.cond.node, truth=True)}: return JUMP({b.label})")
            seg.emit(f"return {i + 1}")
        else:  # Stop
            seg.emit("return None")


def _reads_variables(node) -> bool:
    if not isinstance(node, tuple) or node[0] in ("num", "dec", "lit"):
        return False
    return node[0] in ("var", "named") or any(_reads_variables(c) for c in node[1:])


def _dynamic(b) -> bool:
    """Whether a block reads or sets a variable whose number is computed (``#[#1+1]``, ``##2``)."""
    def computed(node) -> bool:
        if not isinstance(node, tuple) or node[0] in ("num", "dec", "lit"):
            return False
        return node[0] in ("idx", "ind") or any(computed(c) for c in node[1:])

    if "#" not in b.text:
        return False  # no variable at all (a point list's block, Heidenhain's Q numbers)
    a = b.then if isinstance(b, IfThen) else b
    exprs = [getattr(a, name, None) for name in ("target", "value", "cond", "number")]
    exprs += [getattr(b, "cond", None)] + [e for _, e in getattr(b, "words", ())]
    return any(computed(getattr(e, "node", None)) for e in exprs)


def compile_program(m, blocks, labels) -> tuple[list, list[int]]:
    """The segments of a program, and the block of each line of their code (for :func:`alarm_block`).

    The first list has, at each block where a segment starts, ``(function,
    blocks in it, index of its last block)``, and None elsewhere.  ``m`` is
    the :class:`~lagsym.simulate.control.ControlState` the functions run on: they
    read and set its variables, modes and moves.
    """
    prog = _Program(m, blocks, labels)
    starts = _leaders(blocks, labels)
    source, where, spans = [], [-1], []  # where[line number] is the block of that line
    namespace: dict = {}
    for start, stop in zip(starts, starts[1:] + [len(blocks)]):
        lines, last = prog.segment(start, stop)
        spans.append((start, last))
        used = sorted({w for text, _ in lines for w in _NAME.findall(text)} & prog.env.keys())
        source.append(f"def s{start}({', '.join(f'{w}={w}' for w in used)}):")  # locals, the fastest to read
        where.append(-1)
        for text, blk in lines:
            source.append(text)
            where.append(blk)
        if len(source) >= _BATCH_LINES:
            _run(source, len(where) - 1 - len(source), prog.env, namespace)
            source = []
    _run(source, len(where) - 1 - len(source), prog.env, namespace)
    table: list = [None] * len(blocks)
    for start, last in spans:
        table[start] = (namespace[f"s{start}"], last - start + 1, last)
    return table, where


def _run(source: list[str], before: int, env: dict, namespace: dict) -> None:
    """Compile and run the functions of ``source``, numbered as lines ``before + 1`` on of the program's code.

    The code is compiled a few thousand lines at a time: Python's compiler
    takes some hundred times the text's size while it works, and a program
    of long expressions makes tens of megabytes of code.
    """
    if not source:
        return
    tree = ast.parse("\n".join(source) + "\n", SOURCE_NAME, "exec")
    ast.increment_lineno(tree, before)
    namespace.update(env)
    exec(compile(tree, SOURCE_NAME, "exec"), namespace)  # the code is generated here from the parsed blocks


def alarm_block(error: BaseException, where: list[int]) -> int | None:
    """The index of the block whose generated code raised ``error``, or None if none of it did."""
    found, tb = None, error.__traceback__
    while tb is not None:
        if tb.tb_frame.f_code.co_filename == SOURCE_NAME:
            found = where[tb.tb_lineno]
        tb = tb.tb_next
    return found
