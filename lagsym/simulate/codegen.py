"""The code of one segment: Python statements for the blocks of a straight run, each line tagged with its block.

:class:`Segment` writes what :mod:`~lagsym.simulate.compiler` puts in one
function: expressions as Python expressions on :class:`~decimal.Decimal`
values (the executor runs them under the control's context), numbered
variables in locals ``v<n>`` read once and written back at the end, named
parameters in locals, constants as names bound to their values read once,
modes and moves on the control.  Each operation is the one the expression's
closure does through the control's methods, in the same order.
"""

from __future__ import annotations

from .blocks import Assign, AssignNamed, IfThen, Words

__all__ = ["Segment", "STOPS"]

_ROUNDED = {"add", "sub", "mul", "div", "neg", "num", "var", "named", "cmp", "logic"}  # results as stored
_OPS = {"add": "+", "sub": "-", "mul": "*"}
_CMP = {"EQ": "==", "NE": "!=", "GT": ">", "GE": ">=", "LT": "<", "LE": "<="}
_LOGIC = {"AND": "&", "OR": "|", "XOR": "^"}
STOPS = (2, 30)  # M02, M30 end the program (M99 and the calls are refused: lagsym.gcode.program.unrun_code)


class Segment:
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
        self.pending: list[tuple] = []  # blocks of constant words not written yet: one call for them all

    def emit(self, text: str) -> None:
        for p in self.pre:
            self.lines.append(("    " * self.indent + p, self.block))
        self.pre.clear()
        self.lines.append(("    " * self.indent + text, self.block))

    def temp(self) -> str:
        self.temps += 1
        return f"_t{self.temps}"

    def constant_words(self, i: int, b: Words) -> bool:
        """Take a block whose words are all constants into the pending run; whether it was one."""
        pairs = tuple((letter, self.gen.constant(e.node)) for letter, e in b.words)
        if any(v is None for _, v in pairs):
            return False
        if not self.pending:
            self.block = i
        self.pending.append((b, pairs))
        return True

    def flush(self) -> None:
        if self.pending:
            name = f"w{self.block}"
            self.gen.env[name] = tuple(self.pending)
            self.pending = []
            self.emit(f"WORDS(m, {name})")

    def write_back(self) -> None:
        self.flush()
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
        if n == 0 and self.gen.m.language.vacant_zero:
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
        """``#n = expr``: the value first, then the variable's check, as :meth:`ControlState.set` does."""
        ref = b.target.node
        if ref[0] != "lit":
            r, t = self.temp(), self.temp()
            self.emit(f"{r} = {self.index(ref)}")
            self.emit(f"{t} = {self.value(b.value.node)}")
            self.emit(f"V[CHECK({r})] = P({t})")
            return
        n = ref[1]
        if not self.gen.in_range(n) or (n == 0 and self.gen.m.language.vacant_zero):
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
                if g is None or g not in (0, 1, 2, 3, 90, 91):
                    self.emit(f"GMODAL(m, {t})")  # the modes, and the alarm of a code the simulator does not run
                elif g in (0, 1, 2, 3):
                    self.emit(f"m.motion = 'G{int(g)}'")
                elif g in (90, 91):
                    self.emit(f"m.absolute = {g == 90}")
        ms = [t for letter, t, _ in temps if letter == "M"]
        for t in ms:
            self.emit(f"MCHECK({t})")  # before the move: a block that calls does not move on its own
        if "F" in last:
            self.emit(f"m.feed = {last['F']}")
        axes = [(k, last[a]) for k, a in enumerate("XYZ") if a in last]
        if axes:
            self.emit("if m.motion not in ('G0', 'G1'): ARC(m)")
            self.emit("if m.motion == 'G1' and not m.feed > 0: NOFEED(m)")
            self.emit("if m.absolute: " + "; ".join(f"POS[{k}] = {t}" for k, t in axes))
            self.emit("else: " + "; ".join(f"POS[{k}] = POS[{k}] + {t}" for k, t in axes))
            self.emit(f"A_LINE({b.line}); A_RAPID(m.motion == 'G0'); A_X(float(POS[0])); A_Y(float(POS[1])); "
                      "A_Z(float(POS[2])); A_F(float(m.feed))")
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
