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

import re
from decimal import ROUND_HALF_UP, Decimal

from .alarms import BlockAlarm
from .blocks import (Assign, AssignNamed, End, Goto, IfGoto, IfGotoLabel, IfThen, OElse, OElseIf, OEndWhile,
                     OIf, OWhile, Stop, While, Words)
from .expressions import closure

__all__ = ["compile_program", "alarm_block", "SOURCE_NAME"]

SOURCE_NAME = "<lagsym-macro>"
_CONTROL = (While, OWhile, End, OEndWhile, OIf, OElseIf, OElse, Goto, IfGoto, IfGotoLabel, Stop)
_ROUNDED = {"add", "sub", "mul", "div", "neg", "num", "var", "named", "cmp", "logic"}  # results as stored
_OPS = {"add": "+", "sub": "-", "mul": "*"}
_CMP = {"EQ": "==", "NE": "!=", "GT": ">", "GE": ">=", "LT": "<", "LE": "<="}
_LOGIC = {"AND": "&", "OR": "|", "XOR": "^"}
_STOPS = (2, 30, 99)  # M02, M30, M99 end the program
_NAME = re.compile(r"\b[A-Za-z_]\w*\b")


def _leaders(blocks, labels) -> list[int]:
    """The indices a run can reach other than from the block before: where segments start."""
    n = len(blocks)
    starts = {0, *labels.values()}
    for i, b in enumerate(blocks):
        if isinstance(b, _CONTROL) or (isinstance(b, Words) and any(k == "M" for k, _ in b.words)):
            starts.add(i + 1)
        for name in ("end", "next", "endif"):
            if getattr(b, name, -1) >= 0:
                starts.add(getattr(b, name) + 1)
        if getattr(b, "start", -1) >= 0:
            starts.add(b.start)
    return sorted(s for s in starts if s < n)


def _modal_g(m, g) -> None:
    if g in (0, 1, 2, 3):
        m.motion = f"G{int(g)}"
    elif g == 90:
        m.absolute = True
    elif g == 91:
        m.absolute = False


def _arc() -> None:
    raise BlockAlarm("arc", "arcs are outside what the simulator runs")


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
            "RHU": ROUND_HALF_UP, "GMODAL": _modal_g, "ARC": _arc, "STOPS": _STOPS, "A_LINE": line,
            "A_RAPID": rapid, "A_X": x, "A_Y": y, "A_Z": z, "A_F": feed}


class _Segment:
    """The code of one segment as it is written: lines tagged with their block, locals known so far."""

    def __init__(self, gen, cached: bool):
        self.gen, self.cached = gen, cached
        self.lines: list[tuple[str, int]] = []
        self.pre: list[str] = []  # loads the statement being written needs first
        self.known: set[int] = set()  # numbered variables held in locals
        self.written: set[int] = set()  # ... and set unconditionally (written back at the end)
        self.named: dict[str, str] = {}  # named parameters known to be set, and their locals
        self.named_written: dict[str, str] = {}
        self.block = -1
        self.indent = 1
        self.temps = 0

    def emit(self, text: str) -> None:
        for p in self.pre:
            self.lines.append(("    " * self.indent + p, self.block))
        self.pre.clear()
        self.lines.append(("    " * self.indent + text, self.block))

    def temp(self) -> str:
        self.temps += 1
        return f"_t{self.temps}"

    def write_back(self) -> None:
        for n in sorted(self.written):
            self.emit(f"V[{n}] = v{n}")
        for name, local in self.named_written.items():
            self.emit(f"NM[{name!r}] = {local}")

    # ------------------------------------------------------------------ expressions

    def value(self, node, truth: bool = False) -> str:
        """Python code for the value of ``node`` (for its truth only, when ``truth``)."""
        kind = node[0]
        folded = self.gen.fold(node)
        if folded is not None:
            return folded
        if kind == "num":
            return f"CONST({node[1]!r})"  # a constant the control refuses: its alarm when the block runs
        if kind == "var":
            return self.read(node[1])
        if kind == "named":
            return self.read_named(node[1])
        if kind in _OPS:
            return f"({self.value(node[1])} {_OPS[kind]} {self.value(node[2])})"
        if kind == "neg":
            return f"(-{self.value(node[1])})"
        if kind == "div":
            k = self.gen.constant(node[2])
            if k is not None and k != 0:  # m.divide's test for zero done once
                return f"({self.value(node[1])} / {self.value(node[2])})"
            return f"DIV({self.value(node[1])}, {self.value(node[2])})"
        if kind == "mod":
            return f"MOD({self.value(node[2])}, {self.value(node[1])})"
        if kind == "pow":
            return f"POW({self.value(node[1])}, {self.value(node[2])})"
        if kind == "atan2":
            return f"ATAN2({self.value(node[1])}, {self.value(node[2])})"
        if kind == "func":
            if node[1] == "ROUND":
                return f"{self.value(node[2])}.to_integral_value(RHU)"
            return f"FUNC({node[1]!r}, {self.value(node[2])})"
        if kind == "cmp":
            test = f"{self.value(node[2])} {_CMP[node[1]]} {self.value(node[3])}"
        elif kind == "logic":
            test = f"bool({self.value(node[2])}) {_LOGIC[node[1]]} bool({self.value(node[3])})"
        else:
            raise AssertionError(f"no code for {kind}")
        return f"({test})" if truth else f"(ONE if ({test}) else ZERO)"

    def index(self, ref) -> str:
        """Python code for the variable number of a reference node."""
        if ref[0] == "lit":
            return str(ref[1])
        inner = self.value(ref[1]) if ref[0] == "idx" else f"GET({self.index(ref[1])})"
        return f"int({inner}.to_integral_value(RHU))"

    def read(self, ref) -> str:
        if ref[0] != "lit":
            return f"GET({self.index(ref)})"
        n = ref[1]
        if n == 0 and self.gen.m.dialect == "fanuc":
            return "Z"  # #0 is always vacant; vacant reads as 0
        if not self.gen.in_range(n):
            return f"GET({n})"  # the control's alarm when the block runs
        if not self.cached:
            return f"V.get({n}, Z)"
        if n not in self.known:
            self.pre.append(f"v{n} = V.get({n}, Z)")
            self.known.add(n)
        return f"v{n}"

    def read_named(self, name: str) -> str:
        local = self.named.get(name)
        if local is not None:
            return local
        local = self.gen.named_local(name)
        self.named[name] = local
        return f"({local} := GETN({name!r}))"  # read in its place: an unset name is an alarm of this block

    def stored(self, node) -> str:
        """Code for ``node`` rounded as a stored value (``ctx.plus``), without the call where it changes nothing."""
        folded = self.gen.constant(node)
        if folded is not None:
            return self.gen.intern(self.gen.m.ctx.plus(folded))
        code = self.value(node)
        if node[0] in ("var", "named"):
            return code  # stored values are rounded already
        if node[0] in _ROUNDED:  # a rounded nonzero result is its own plus; a zero may be -0
            t = self.temp()
            self.emit(f"{t} = {code}")
            return f"({t} if {t} else P({t}))"
        return f"P({code})"

    # ------------------------------------------------------------------ statements

    def assign(self, b: Assign, conditional: bool = False) -> None:
        """``#n = expr``: the value first, then the variable's check, as :meth:`Control.set` does."""
        ref = b.target.node
        if ref[0] != "lit":
            r, t = self.temp(), self.temp()
            self.emit(f"{r} = {self.index(ref)}")
            self.emit(f"{t} = {self.value(b.value.node)}")
            self.emit(f"V[CHECK({r})] = P({t})")
            return
        n = ref[1]
        if not self.gen.in_range(n) or (n == 0 and self.gen.m.dialect == "fanuc"):
            self.emit(f"{self.temp()} = {self.value(b.value.node)}")
            self.emit(f"CHECK({n})")
            return
        code = self.stored(b.value.node)
        if not self.cached:
            self.emit(f"V[{n}] = {code}")
        elif conditional:
            self.emit(f"v{n} = V[{n}] = {code}")  # the dict too: taken or not, the local holds the value
        else:
            self.emit(f"v{n} = {code}")
            self.known.add(n)
            self.written.add(n)

    def assign_named(self, b: AssignNamed) -> None:
        code = self.stored(b.value.node)
        local = self.gen.named_local(b.name)
        self.emit(f"{local} = {code}")
        self.named[b.name] = self.named_written[b.name] = local

    def if_then(self, b: IfThen) -> None:
        cond = self.value(b.cond.node, truth=True)
        if self.cached:  # the locals the branch reads or sets exist whether it is taken or not
            for ref in _static_refs((b.then.value.node, ("var", b.then.target.node))):
                if self.gen.in_range(ref[1]):
                    self.read(ref)
        named = dict(self.named)
        self.emit(f"if {cond}:")
        self.indent += 1
        self.assign(b.then, conditional=True)
        self.indent -= 1
        self.named = named  # a name first read inside the branch is read again after it

    def words(self, i: int, b: Words) -> bool:
        """Address words; returns whether the block has ``M`` words (then it ends the segment)."""
        temps = []
        for letter, e in b.words:
            t = self.temp()
            self.emit(f"{t} = {self.value(e.node)}")
            temps.append((letter, t, e.node))
        last = {letter: t for letter, t, _ in temps}
        for letter, t, node in temps:
            if letter == "G":
                g = self.gen.constant(node)
                if g is None:
                    self.emit(f"GMODAL(m, {t})")
                elif g in (0, 1, 2, 3):
                    self.emit(f"m.motion = 'G{int(g)}'")
                elif g in (90, 91):
                    self.emit(f"m.absolute = {g == 90}")
        if "F" in last:
            self.emit(f"m.feed = {last['F']}")
        axes = [(k, last[a]) for k, a in enumerate("XYZ") if a in last]
        if axes:
            self.emit("if m.motion in ('G2', 'G3'): ARC()")
            self.emit("if m.absolute: " + "; ".join(f"POS[{k}] = {t}" for k, t in axes))
            self.emit("else: " + "; ".join(f"POS[{k}] = POS[{k}] + {t}" for k, t in axes))
            self.emit(f"A_LINE({b.line}); A_RAPID(m.motion == 'G0'); A_X(float(POS[0])); A_Y(float(POS[1])); "
                      "A_Z(float(POS[2])); A_F(float(m.feed))")
        ms = [t for letter, t, _ in temps if letter == "M"]
        if ms:
            self.write_back()
            self.emit(f"return None if ({' or '.join(f'{t} in STOPS' for t in ms)}) else {i + 1}")
        return bool(ms)


def _static_refs(nodes):
    """The ``("lit", n)`` references read in the trees ``nodes``."""
    for node in nodes:
        if not isinstance(node, tuple):
            continue
        if node[0] == "var" and node[1][0] == "lit":
            yield node[1]
        else:
            yield from _static_refs(node[1:])


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
        if _reads_variables(node) or node[0] in ("lit", "idx", "ind"):
            return None
        try:
            return closure(node)(self.m)
        except (BlockAlarm, ArithmeticError, ValueError):
            return None

    def fold(self, node):
        value = self.constant(node)
        return None if value is None else self.intern(value)

    def segment(self, start: int, stop: int) -> tuple[list[tuple[str, int]], int]:
        """The lines of the function for blocks ``start`` to ``stop - 1`` and the index of its last block."""
        cached = not any(_dynamic(b) for b in self.blocks[start:stop])
        seg = _Segment(self, cached)
        for i in range(start, stop):
            b = self.blocks[i]
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

    def flow(self, seg: _Segment, i: int, b) -> None:
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
    if not isinstance(node, tuple):
        return False
    return node[0] in ("var", "named") or any(_reads_variables(c) for c in node[1:])


def _dynamic(b) -> bool:
    """Whether a block reads or sets a variable whose number is computed (``#[#1+1]``, ``##2``)."""
    def computed(node) -> bool:
        if not isinstance(node, tuple):
            return False
        return node[0] in ("idx", "ind") or any(computed(c) for c in node[1:])

    a = b.then if isinstance(b, IfThen) else b
    exprs = [getattr(a, name, None) for name in ("target", "value", "cond", "number")]
    exprs += [getattr(b, "cond", None)] + [e for _, e in getattr(b, "words", ())]
    return any(computed(getattr(e, "node", None)) for e in exprs)


def compile_program(m, blocks, labels) -> tuple[list, list[int]]:
    """The segments of a program, and the block of each line of their code (for :func:`alarm_block`).

    The first list has, at each block where a segment starts, ``(function,
    blocks in it, index of its last block)``, and None elsewhere.  ``m`` is
    the :class:`~lagsym.simulate.control.Control` the functions run on: they
    read and set its variables, modes and moves.
    """
    prog = _Program(m, blocks, labels)
    starts = _leaders(blocks, labels)
    source, where, spans = [], [-1], []  # where[line number] is the block of that line
    for start, stop in zip(starts, starts[1:] + [len(blocks)]):
        lines, last = prog.segment(start, stop)
        spans.append((start, last))
        used = sorted({w for text, _ in lines for w in _NAME.findall(text)} & prog.env.keys())
        source.append(f"def s{start}({', '.join(f'{w}={w}' for w in used)}):")  # locals, the fastest to read
        where.append(-1)
        for text, blk in lines:
            source.append(text)
            where.append(blk)
    code = compile("\n".join(source) + "\n", SOURCE_NAME, "exec")
    namespace = dict(prog.env)
    exec(code, namespace)  # the code is generated here from the parsed blocks, nothing else
    table: list = [None] * len(blocks)
    for start, last in spans:
        table[start] = (namespace[f"s{start}"], last - start + 1, last)
    return table, where


def alarm_block(error: BaseException, where: list[int]) -> int | None:
    """The index of the block whose generated code raised ``error``, or None if none of it did."""
    found, tb = None, error.__traceback__
    while tb is not None:
        if tb.tb_frame.f_code.co_filename == SOURCE_NAME:
            found = where[tb.tb_lineno]
        tb = tb.tb_next
    return found
