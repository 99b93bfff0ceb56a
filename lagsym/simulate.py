"""A dry run of a macro program on the PC, with the control's arithmetic and the control's alarms.

:func:`simulate` executes the dialects lagsym writes -- Fanuc Custom Macro B,
LinuxCNC O-words, Heidenhain FN/Q parameters -- in decimal arithmetic of a
chosen number of significant digits (8 for a Fanuc 16/18-class control, 15
for IEEE double), rounding after every operation and on reading every
constant.  It returns the moves the control would make, or raises
:class:`ControlAlarm` where the control would stop:

* unbalanced ``WHILE .. DOm`` / ``ENDm`` or ``o.. while`` / ``o.. endwhile``, ``DO`` beyond 3 levels;
* ``[ ]`` nested deeper than 5 (Fanuc alarm 118);
* a constant with more digits than the control reads (Fanuc alarm 003);
* a constant on an axis word without a decimal point (a Fanuc reads ``X12`` as
  0.012 mm; lagsym refuses it rather than guess);
* a variable outside the range the dialect allows;
* a block longer than the control reads; division by zero, the square root of
  a negative number, a jump to a missing sequence number or label, a runaway loop.

The simulator covers what lagsym emits plus the common core of each language
(``IF [..] GOTO n``, ``IF [..] THEN``, ``GOTO``, the functions every Macro B
control has); it is not a full interpreter of any control.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from decimal import ROUND_CEILING, ROUND_DOWN, ROUND_FLOOR, ROUND_HALF_UP, ROUND_UP, Context, Decimal, InvalidOperation

from .errors import ProgramError

__all__ = ["ControlAlarm", "SimMove", "Simulation", "simulate", "detect_dialect", "moves_csv",
           "SIM_DIALECTS", "VARIABLE_RANGES", "MAX_BLOCK"]

SIM_DIALECTS = ("fanuc", "linuxcnc", "heidenhain")
VARIABLE_RANGES = {
    "fanuc": ((1, 33), (100, 199), (500, 999)),
    "linuxcnc": ((1, 5602),),
    "heidenhain": ((0, 99),),
}
MAX_BLOCK = {"fanuc": 128, "linuxcnc": 255, "heidenhain": 128}
MAX_BRACKETS = 5  # Fanuc alarm 118
MAX_DO = 3  # Fanuc: DO1..DO3


class ControlAlarm(ProgramError):
    """The control would stop here: ``alarm`` names the condition, ``line`` the block (1-based)."""

    def __init__(self, alarm: str, message: str, line: int = 0, block: str = ""):
        self.alarm, self.line, self.block = alarm, line, block
        where = f" at line {line}: {block.strip()[:60]!r}" if line else ""
        super().__init__(f"alarm {alarm}: {message}{where}")


@dataclass(frozen=True)
class SimMove:
    """One motion the control would make: ``motion`` is ``G0`` or ``G1``, coordinates in program units."""

    line: int
    motion: str
    x: float
    y: float
    z: float
    feed: float


@dataclass(frozen=True)
class Simulation:
    """The result of a dry run: the moves in order and how many blocks were executed."""

    dialect: str
    precision: int
    moves: tuple[SimMove, ...]
    blocks: int

    def feed_points(self):
        """The end points of the feed (``G1``) moves as an (N, 3) float array."""
        import numpy as np

        return np.array([(m.x, m.y, m.z) for m in self.moves if m.motion == "G1"], dtype=float).reshape(-1, 3)


def detect_dialect(text: str) -> str:
    """Guess the dialect of a program: ``BEGIN PGM`` is Heidenhain, ``o100 while`` LinuxCNC, else Fanuc."""
    if re.search(r"^\s*\d*\s*BEGIN\s+PGM", text, re.M | re.I):
        return "heidenhain"
    if re.search(r"^[ \t]*o[ \t]*[\d<]\S*[ \t]+(while|if|do|sub|repeat)\b", text, re.M | re.I) or "#<" in text:
        return "linuxcnc"
    return "fanuc"


# --------------------------------------------------------------------------- expressions

_TOKEN = re.compile(r"\s*(?:(?P<num>\d+\.?\d*|\.\d+)|(?P<name>#<[^>]*>)|(?P<word>[A-Za-z_]+)"
                    r"|(?P<op>\*\*|[-+*/\[\]#]))")
_FUNCS = {"SQRT", "ABS", "FIX", "FUP", "ROUND", "SIN", "COS", "TAN", "ATAN", "ASIN", "ACOS", "EXP", "LN"}
_CMP = {"EQ", "NE", "GT", "GE", "LT", "LE"}
_LOGIC = {"AND", "OR", "XOR"}


class _Syntax(Exception):
    def __init__(self, alarm: str, message: str):
        self.alarm, self.message = alarm, message


def _tokens(text: str) -> list[tuple[str, str]]:
    out, pos, depth = [], 0, 0
    text = text.rstrip()
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            raise _Syntax("114", f"cannot read {text[pos:pos + 10]!r}")
        kind = m.lastgroup
        val = m.group(kind)
        if kind == "word":
            val = val.upper()
        if val == "[":
            depth += 1
            if depth > MAX_BRACKETS:
                raise _Syntax("118", f"brackets nested deeper than {MAX_BRACKETS}")
        elif val == "]":
            depth -= 1
            if depth < 0:
                raise _Syntax("118", "a ']' without its '['")
        out.append((kind, val))
        pos = m.end()
    if depth:
        raise _Syntax("118", "a '[' without its ']'")
    return out


class _Parser:
    """Recursive descent over tokens; builds closures ``f(machine) -> Decimal``."""

    def __init__(self, toks):
        self.toks, self.i = toks, 0

    def peek(self):
        return self.toks[self.i] if self.i < len(self.toks) else (None, None)

    def take(self, value=None):
        tok = self.peek()
        if tok[0] is None or (value is not None and tok[1] != value):
            raise _Syntax("114", f"expected {value!r}" if value else "unexpected end of block")
        self.i += 1
        return tok

    def expr(self):
        f = self.compare()
        while self.peek()[1] in _LOGIC:
            op = self.take()[1]
            g = self.compare()
            f = _logic(op, f, g)
        return f

    def compare(self):
        f = self.additive()
        while self.peek()[1] in _CMP:
            op = self.take()[1]
            g = self.additive()
            f = _cmp(op, f, g)
        return f

    def additive(self):
        f = self.term()
        while self.peek()[1] in ("+", "-"):
            op = self.take()[1]
            g = self.term()
            f = (lambda a, b: lambda m: m.ctx.add(a(m), b(m)))(f, g) if op == "+" else \
                (lambda a, b: lambda m: m.ctx.subtract(a(m), b(m)))(f, g)
        return f

    def term(self):
        f = self.power()
        while self.peek()[1] in ("*", "/", "MOD"):
            op = self.take()[1]
            g = self.power()
            f = _mul(op, f, g)
        return f

    def power(self):
        f = self.unary()
        if self.peek()[1] == "**":
            self.take()
            g = self.unary()
            return lambda m, a=f, b=g: m.ctx.power(a(m), b(m))
        return f

    def unary(self):
        if self.peek()[1] == "-":
            self.take()
            f = self.unary()
            return lambda m: m.ctx.minus(f(m))
        if self.peek()[1] == "+":
            self.take()
            return self.unary()
        return self.primary()

    def primary(self):
        kind, val = self.take()
        if kind == "num":
            return lambda m, t=val: m.const(t)
        if val == "[":
            f = self.expr()
            self.take("]")
            return f
        if kind == "name":
            return lambda m, n=val[2:-1].strip().lower(): m.named(n)
        if val == "#":
            ref = self.reference()
            return lambda m: m.get(ref(m))
        if kind == "word" and val in _FUNCS:
            self.take("[")
            a = self.expr()
            self.take("]")
            if val == "ATAN" and self.peek()[1] == "/":
                self.take("/")
                self.take("[")
                b = self.expr()
                self.take("]")
                return lambda m: m.atan2(a(m), b(m))
            return lambda m, fn=val: m.func(fn, a(m))
        raise _Syntax("114", f"unexpected {val!r}")

    def reference(self):
        """After ``#``: a number, ``[expr]`` or another ``#``; returns ``f(machine) -> int``."""
        kind, val = self.peek()
        if kind == "num":
            self.take()
            if "." in val:
                raise _Syntax("114", f"variable number #{val} is not an integer")
            return lambda m, n=int(val): n
        if val == "[":
            self.take()
            f = self.expr()
            self.take("]")
            return lambda m: m.index(f(m))
        if val == "#":
            self.take()
            inner = self.reference()
            return lambda m: m.index(m.get(inner(m)))
        raise _Syntax("114", "'#' without a variable number")


def _logic(op, f, g):
    def run(m):
        a, b = bool(f(m)), bool(g(m))
        return Decimal(int(a and b if op == "AND" else a or b if op == "OR" else a != b))

    return run


def _cmp(op, f, g):
    tests = {"EQ": lambda a, b: a == b, "NE": lambda a, b: a != b, "GT": lambda a, b: a > b,
             "GE": lambda a, b: a >= b, "LT": lambda a, b: a < b, "LE": lambda a, b: a <= b}
    t = tests[op]
    return lambda m: Decimal(int(t(f(m), g(m))))


def _mul(op, f, g):
    if op == "*":
        return lambda m: m.ctx.multiply(f(m), g(m))
    if op == "/":
        return lambda m: m.divide(f(m), g(m))
    return lambda m: m.ctx.remainder(f(m), g(m)) if g(m) else m.divide(f(m), g(m))


def _expression(text: str):
    p = _Parser(_tokens(text))
    f = p.expr()
    if p.i != len(p.toks):
        raise _Syntax("114", f"unexpected {p.toks[p.i][1]!r}")
    return f


def _reference(text: str):
    p = _Parser(_tokens(text))
    p.take("#")
    r = p.reference()
    if p.i != len(p.toks):
        raise _Syntax("114", f"unexpected {p.toks[p.i][1]!r}")
    return r


# --------------------------------------------------------------------------- the machine


class _Machine:
    """Variables, modal state and arithmetic of one run."""

    def __init__(self, dialect: str, precision: int, ranges):
        self.dialect, self.precision, self.ranges = dialect, precision, ranges
        self.ctx = Context(prec=precision, Emin=-99, Emax=99)
        self.vars: dict[int, Decimal] = {}
        self.constants: dict[str, Decimal] = {}
        self.names: dict[str, Decimal] = {}
        self.pos = [Decimal(0)] * 3
        self.motion = "G0"
        self.feed = Decimal(0)
        self.absolute = True
        self.moves: list[SimMove] = []

    def const(self, text: str) -> Decimal:
        value = self.constants.get(text)
        if value is None:
            if self.dialect == "fanuc":
                whole, _, frac = text.lstrip("+-").partition(".")
                digits = len(whole.lstrip("0")) + len(frac)
                if digits > self.precision:
                    raise _Syntax("003", f"{text} has {digits} digits, "
                                         f"more than the {self.precision} the control reads")
            value = self.constants[text] = self.ctx.create_decimal(text)
        return value

    def check(self, n: int) -> int:
        if not any(lo <= n <= hi for lo, hi in self.ranges):
            allowed = ", ".join(f"{lo}-{hi}" for lo, hi in self.ranges)
            raise _Syntax("115", f"variable {n} is outside the allowed ranges {allowed}")
        return n

    def index(self, value: Decimal) -> int:
        """A computed variable or sequence number, rounded to the nearest integer as the control does."""
        return int(value.to_integral_value(rounding=ROUND_HALF_UP))

    def get(self, n: int) -> Decimal:
        if n == 0 and self.dialect == "fanuc":
            return Decimal(0)  # #0 is always vacant; vacant reads as 0 in arithmetic
        self.check(n)
        return self.vars.get(n, Decimal(0))

    def set(self, n: int, value: Decimal) -> None:
        self.vars[self.check(n)] = self.ctx.plus(value)

    def named(self, name: str) -> Decimal:
        if name not in self.names:
            raise _Syntax("named", f"named parameter #<{name}> is used before it is set")
        return self.names[name]

    def divide(self, a: Decimal, b: Decimal) -> Decimal:
        if b == 0:
            raise _Syntax("112", "division by zero")
        return self.ctx.divide(a, b)

    def func(self, name: str, a: Decimal) -> Decimal:
        c = self.ctx
        if name == "SQRT":
            if a < 0:
                raise _Syntax("111", f"square root of {a}")
            return c.sqrt(a)
        if name == "ABS":
            return c.abs(a)
        if name == "FIX":  # Fanuc drops the fraction (toward zero); LinuxCNC rounds down
            return a.to_integral_value(rounding=ROUND_DOWN if self.dialect == "fanuc" else ROUND_FLOOR)
        if name == "FUP":  # Fanuc raises the magnitude (away from zero); LinuxCNC rounds up
            return a.to_integral_value(rounding=ROUND_UP if self.dialect == "fanuc" else ROUND_CEILING)
        if name == "ROUND":
            return a.to_integral_value(rounding=ROUND_HALF_UP)
        if name == "EXP":
            return c.exp(a)
        if name == "LN":
            if a <= 0:
                raise _Syntax("111", f"logarithm of {a}")
            return c.ln(a)
        x = float(a)
        try:
            value = {"SIN": lambda: math.sin(math.radians(x)), "COS": lambda: math.cos(math.radians(x)),
                     "TAN": lambda: math.tan(math.radians(x)), "ATAN": lambda: math.degrees(math.atan(x)),
                     "ASIN": lambda: math.degrees(math.asin(x)), "ACOS": lambda: math.degrees(math.acos(x))}[name]()
        except ValueError:
            raise _Syntax("111", f"{name} of {a}") from None
        return c.create_decimal(repr(value))

    def atan2(self, a: Decimal, b: Decimal) -> Decimal:
        return self.ctx.create_decimal(repr(math.degrees(math.atan2(float(a), float(b))) % 360.0))

    def move(self, line: int, words: dict[str, Decimal]) -> None:
        for axis, letter in enumerate("XYZ"):
            if letter in words:
                v = words[letter]
                self.pos[axis] = v if self.absolute else self.ctx.add(self.pos[axis], v)
        if any(k in words for k in "XYZ"):
            self.moves.append(SimMove(line, self.motion, float(self.pos[0]), float(self.pos[1]),
                                      float(self.pos[2]), float(self.feed)))


# --------------------------------------------------------------------------- blocks

@dataclass
class _Block:
    line: int
    text: str
    kind: str
    a: object = None
    b: object = None
    target: int | None = None
    label: int | None = None


_AXIS_DECIMAL = set("XYZABCIJKRUVW")
_FUNC_NAME = re.compile(r"(?i)(SQRT|ABS|FIX|FUP|ROUND|SIN|COS|TAN|ATAN|ASIN|ACOS|EXP|LN)(?=\s*\[)")
_WORD = re.compile(r"([A-Z])\s*")


def _strip_comments(text: str, dialect: str) -> str:
    text = re.sub(r"\([^)]*\)", "", text)
    if dialect == "linuxcnc" and ";" in text:
        text = text.split(";", 1)[0]
    return text.strip()


def _split_words(text: str) -> list[tuple[str, str]]:
    """``G1 X#112 Y[#1+2.] Z-1.5`` -> [('G', '1'), ('X', '#112'), ...], keeping bracketed values whole."""
    out, i, s = [], 0, text
    while i < len(s):
        if s[i].isspace():
            i += 1
            continue
        letter = s[i].upper()
        if not letter.isalpha():
            raise _Syntax("114", f"cannot read {s[i:i + 10]!r}")
        i += 1
        while i < len(s) and s[i].isspace():
            i += 1
        start, depth = i, 0
        while i < len(s):
            ch = s[i]
            fn = _FUNC_NAME.match(s, i) if depth == 0 and s[start:i].strip() in ("", "-", "+") else None
            if fn:  # X SQRT[..]: a function name is part of the value, not the next address
                i = fn.end()
                continue
            if s.startswith("#<", i):
                close = s.find(">", i)
                if close < 0:
                    raise _Syntax("114", "a '#<' without its '>'")
                i = close + 1
                continue
            if ch == "[":
                depth += 1
            elif ch == "]":
                depth -= 1
            elif depth == 0 and (ch.isspace() or ch.isalpha()):
                break
            i += 1
        out.append((letter, s[start:i]))
    return out


def _word_value(letter: str, text: str, dialect: str):
    t = text.strip()
    if not t:
        raise _Syntax("114", f"address {letter} without a value")
    if re.fullmatch(r"[-+]?(\d+\.?\d*|\.\d+)", t):
        if letter in _AXIS_DECIMAL and "." not in t and dialect == "fanuc":
            raise _Syntax("decimal-point",
                          f"{letter}{t} has no decimal point (a Fanuc would read it in least increments)")
        return lambda m, v=t: m.const(v)
    return _expression(t)


def _fanuc_block(line: int, raw: str, text: str) -> _Block:
    m = re.match(r"N\s*(\d+)\s*", text, re.I)
    label = int(m.group(1)) if m else None
    b = _fanuc_statement(line, raw, text[m.end():] if m else text)
    if label is not None:
        b.label = label
    return b


def _fanuc_statement(line: int, raw: str, t: str) -> _Block:
    u = t.upper()
    if not t:
        return _Block(line, raw, "nop")
    m = re.fullmatch(r"WHILE\s*(\[.*\])\s*DO\s*(\d+)", t, re.I)
    if m:
        return _Block(line, raw, "while", _expression(m.group(1)), int(m.group(2)))
    m = re.fullmatch(r"DO\s*(\d+)", t, re.I)
    if m:
        return _Block(line, raw, "while", None, int(m.group(1)))
    m = re.fullmatch(r"END\s*(\d+)", t, re.I)
    if m:
        return _Block(line, raw, "end", None, int(m.group(1)))
    m = re.fullmatch(r"IF\s*(\[.*\])\s*GOTO\s*(.+)", t, re.I)
    if m:
        return _Block(line, raw, "if_goto", _expression(m.group(1)), _expression(m.group(2)))
    m = re.fullmatch(r"IF\s*(\[.*\])\s*THEN\s*(.+)", t, re.I)
    if m:
        inner = _fanuc_statement(line, raw, m.group(2).strip())
        if inner.kind != "assign":
            raise _Syntax("114", "THEN must be followed by an assignment")
        return _Block(line, raw, "if_then", _expression(m.group(1)), inner)
    m = re.fullmatch(r"GOTO\s*(.+)", t, re.I)
    if m:
        return _Block(line, raw, "goto", None, _expression(m.group(1)))
    if t.startswith("#"):
        lhs, eq, rhs = t.partition("=")
        if not eq:
            raise _Syntax("114", "a variable without '='")
        return _Block(line, raw, "assign", _reference(lhs), _expression(rhs))
    if u.startswith("O") and re.fullmatch(r"O\d+\s*", t, re.I):
        n = int(t[1:])
        if not 1 <= n <= 9999:
            raise _Syntax("114", f"program number O{n} is not 1-9999")
        return _Block(line, raw, "nop")
    return _words_block(line, raw, t, "fanuc")


def _words_block(line: int, raw: str, t: str, dialect: str) -> _Block:
    words = []
    for letter, value in _split_words(t):
        words.append((letter, _word_value(letter, value, dialect)))
    return _Block(line, raw, "words", words)


def _linuxcnc_statement(line: int, raw: str, t: str) -> _Block:
    if not t:
        return _Block(line, raw, "nop")
    m = re.fullmatch(r"[oO]\s*(\d+|<[^>]+>)\s*([a-z]+)\s*(.*)", t, re.I)
    if m and m.group(2).lower() not in ("while", "endwhile", "if", "elseif", "else", "endif"):
        raise _Syntax("o-word", f"o-word {m.group(2)!r} is outside what the simulator runs")
    if m:
        label, word, rest = m.group(1).lower(), m.group(2).lower(), m.group(3).strip()
        cond = _expression(rest) if word in ("while", "if", "elseif") else None
        if word == "endwhile" and rest:
            raise _Syntax("114", "endwhile takes no condition here")
        return _Block(line, raw, "o" + word, cond, label)
    if t.startswith("#"):
        lhs, eq, rhs = t.partition("=")
        if not eq:
            raise _Syntax("114", "a parameter without '='")
        lhs = lhs.strip()
        if lhs.startswith("#<"):
            return _Block(line, raw, "assign_named", lhs[2:-1].strip().lower(), _expression(rhs))
        return _Block(line, raw, "assign", _reference(lhs), _expression(rhs))
    return _words_block(line, raw, t, "linuxcnc")


_HH_OPERAND = r"([+-]?\s*(?:Q\d+|\d+\.?\d*|\.\d+))"


def _hh_operand(text: str):
    t = text.replace(" ", "")
    neg = t.startswith("-")
    t = t.lstrip("+-")
    if t.upper().startswith("Q"):
        n = int(t[1:])
        return (lambda m: m.ctx.minus(m.get(n))) if neg else (lambda m: m.get(n))
    return lambda m, v=("-" if neg else "") + t: m.const(v)


def _heidenhain_statement(line: int, raw: str, t: str) -> _Block:
    t = re.sub(r"^\d+\s+", "", t).rstrip("*").strip()
    if ";" in t:
        t = t.split(";", 1)[0].strip()
    u = t.upper()
    if not t or u.startswith(("BEGIN PGM", "BLK FORM", "TOOL CALL", "TOOL DEF", "CYCL")):
        return _Block(line, raw, "nop")
    if u.startswith("END PGM"):
        return _Block(line, raw, "stop")
    m = re.fullmatch(r"LBL\s+(\d+)", t, re.I)
    if m:
        return _Block(line, raw, "label", None, int(m.group(1)))
    t = re.sub(r"^(FN\s*5\s*:\s*Q\d+\s*=\s*)SQRT\s*", r"\1", t, flags=re.I)
    m = re.fullmatch(r"FN\s*(\d+)\s*:\s*Q(\d+)\s*=\s*" + _HH_OPERAND
                     + r"(?:\s*([-+*/])\s*" + _HH_OPERAND + r")?", t, re.I)
    if m:
        fn, q, a, op, b = int(m.group(1)), int(m.group(2)), m.group(3), m.group(4), m.group(5)
        fa = _hh_operand(a)
        ops = {1: "+", 2: "-", 3: "*", 4: "/"}
        if fn == 0 and op is None:
            f = fa
        elif fn in ops and op == ops[fn]:
            fb = _hh_operand(b)
            f = {1: lambda m: m.ctx.add(fa(m), fb(m)), 2: lambda m: m.ctx.subtract(fa(m), fb(m)),
                 3: lambda m: m.ctx.multiply(fa(m), fb(m)), 4: lambda m: m.divide(fa(m), fb(m))}[fn]
        elif fn == 5 and op is None:
            f = lambda m: m.func("SQRT", fa(m))  # noqa: E731
        else:
            raise _Syntax("114", f"FN {fn} does not take this form")
        return _Block(line, raw, "assign", lambda m, n=q: n, f)
    m = re.fullmatch(r"FN\s*(9|10|11|12)\s*:\s*IF\s+" + _HH_OPERAND + r"\s+(EQU|NE|GT|LT)\s+" + _HH_OPERAND
                     + r"\s+GOTO\s+LBL\s+(\d+)", t, re.I)
    if m:
        fn, rel, lbl = int(m.group(1)), m.group(3).upper(), int(m.group(5))
        a, b = _hh_operand(m.group(2)), _hh_operand(m.group(4))
        want = {9: "EQU", 10: "NE", 11: "GT", 12: "LT"}[fn]
        if rel != want:
            raise _Syntax("114", f"FN {fn} compares with {want}, not {rel}")
        test = {"EQU": lambda x, y: x == y, "NE": lambda x, y: x != y, "GT": lambda x, y: x > y,
                "LT": lambda x, y: x < y}[rel]
        return _Block(line, raw, "if_label", lambda mm: Decimal(int(test(a(mm), b(mm)))), lbl)
    m = re.fullmatch(r"L\s+(.*)", t, re.I)
    if m:
        words = []
        for w in re.findall(r"([XYZ])\s*" + _HH_OPERAND, m.group(1), re.I):
            words.append((w[0].upper(), _hh_operand(w[1])))
        feed = re.search(r"\bF\s*(\d+\.?\d*|MAX)\b", m.group(1), re.I)
        motion = "G0" if feed and feed.group(1).upper() == "MAX" else "G1"
        extra = [("G", lambda mm, v=motion[1]: Decimal(v))]
        if feed and feed.group(1).upper() != "MAX":
            extra.append(("F", lambda mm, v=feed.group(1): mm.const(v)))
        return _Block(line, raw, "words", extra + words)
    m = re.fullmatch(r"M\s*(\d+)", t, re.I)
    if m:
        return _Block(line, raw, "words", [("M", lambda mm, v=m.group(1): Decimal(v))])
    raise _Syntax("114", f"cannot read {t[:30]!r}")


def _compile(text: str, dialect: str) -> list[_Block]:
    limit = MAX_BLOCK[dialect]
    blocks = []
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    for n, raw in enumerate(lines, start=1):
        if len(raw) > limit:
            raise ControlAlarm("block", f"block of {len(raw)} characters, more than the {limit} the control reads",
                               n, raw)
        t = raw.strip()
        if t == "%" or not t or t.startswith("/"):
            continue
        try:
            if dialect == "heidenhain":
                b = _heidenhain_statement(n, raw, t)
            else:
                t = _strip_comments(t, dialect)
                if dialect == "fanuc":
                    b = _fanuc_block(n, raw, t)
                else:
                    t = re.sub(r"^[Nn]\d+\s*", "", t)
                    b = _linuxcnc_statement(n, raw, t)
        except _Syntax as e:
            raise ControlAlarm(e.alarm, e.message, n, raw) from None
        if b.kind != "nop" or b.label is not None:
            blocks.append(b)
    return blocks


def _match_loops(blocks: list[_Block], dialect: str) -> None:
    """Pair every loop start with its end (``a``/``target`` hold the partner index)."""
    stack: list[int] = []
    for i, b in enumerate(blocks):
        if b.kind == "while":
            if not 1 <= b.b <= MAX_DO:
                raise ControlAlarm("126", f"DO{b.b}: loop numbers are 1 to {MAX_DO}", b.line, b.text)
            if len(stack) >= MAX_DO:
                raise ControlAlarm("126", f"more than {MAX_DO} nested DO loops", b.line, b.text)
            if any(blocks[j].b == b.b for j in stack):
                raise ControlAlarm("126", f"DO{b.b} inside a loop with the same number", b.line, b.text)
            stack.append(i)
        elif b.kind == "end":
            if not stack or blocks[stack[-1]].b != b.b:
                raise ControlAlarm("124", f"END{b.b} without its DO{b.b}", b.line, b.text)
            j = stack.pop()
            blocks[j].target, b.target = i, j
        elif b.kind == "owhile":
            stack.append(i)
        elif b.kind == "oendwhile":
            if not stack or blocks[stack[-1]].kind != "owhile" or blocks[stack[-1]].b != b.b:
                raise ControlAlarm("o-word", f"o{b.b} endwhile without its o{b.b} while", b.line, b.text)
            j = stack.pop()
            blocks[j].target, b.target = i, j
        elif b.kind == "oif":
            stack.append(i)
        elif b.kind in ("oelse", "oelseif"):
            if not stack or blocks[stack[-1]].kind not in ("oif", "oelseif", "oelse") or blocks[stack[-1]].b != b.b:
                raise ControlAlarm("o-word", f"o{b.b} {b.kind[1:]} without its o{b.b} if", b.line, b.text)
            blocks[stack.pop()].target = i
            stack.append(i)
        elif b.kind == "oendif":
            if not stack or blocks[stack[-1]].kind not in ("oif", "oelseif", "oelse") or blocks[stack[-1]].b != b.b:
                raise ControlAlarm("o-word", f"o{b.b} endif without its o{b.b} if", b.line, b.text)
            blocks[stack.pop()].target = i
    if stack:
        b = blocks[stack[-1]]
        what = f"DO{b.b} without its END{b.b}" if b.kind == "while" else f"o{b.b} {b.kind[1:]} is never closed"
        raise ControlAlarm("124" if b.kind == "while" else "o-word", what, b.line, b.text)


def _if_chain_end(blocks, i):
    # From an if/elseif/else block, follow the targets to the endif.
    while blocks[i].kind != "oendif":
        i = blocks[i].target
    return i


def simulate(text: str, dialect: str | None = None, precision: int = 8, *,
             variable_ranges=None, max_blocks: int = 20_000_000) -> Simulation:
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
        Blocks executed before the run is stopped as a runaway loop.

    Raises
    ------
    ControlAlarm
        Where the control would raise an alarm.

    Examples
    --------
    >>> program = "#100=0.\\nWHILE [#100 LE 2.] DO1\\nG1 X#100 Y0. Z[#100*#100] F100.\\n#100=[#100+1.]\\nEND1\\nM30"
    >>> sim = simulate(program)
    >>> [(m.x, m.z) for m in sim.moves]
    [(0.0, 0.0), (1.0, 1.0), (2.0, 4.0)]
    """
    dialect = dialect or detect_dialect(text)
    if dialect not in SIM_DIALECTS:
        raise ProgramError(f"dialect {dialect!r} is not one of {', '.join(SIM_DIALECTS)}")
    if int(precision) < 1 or int(precision) > 34:
        raise ProgramError(f"precision {precision} must be 1 to 34 significant digits")
    blocks = _compile(text, dialect)
    _match_loops(blocks, dialect)
    labels: dict[int, int] = {}
    for i, b in enumerate(blocks):
        if b.kind == "label":
            labels[b.b] = i
        elif b.label is not None:
            labels.setdefault(b.label, i)
    m = _Machine(dialect, int(precision), variable_ranges or VARIABLE_RANGES[dialect])
    pc, executed = 0, 0
    while pc < len(blocks):
        b = blocks[pc]
        executed += 1
        if executed > max_blocks:
            raise ControlAlarm("runaway", f"more than {max_blocks} blocks executed; a loop that never ends?",
                               b.line, b.text)
        try:
            nxt = _step(m, blocks, pc, b, labels)
        except _Syntax as e:
            raise ControlAlarm(e.alarm, e.message, b.line, b.text) from None
        except (InvalidOperation, OverflowError, ArithmeticError) as e:
            raise ControlAlarm("111", f"calculated data out of range ({type(e).__name__})", b.line, b.text) from None
        if nxt is None:
            break
        pc = nxt
    return Simulation(dialect=dialect, precision=int(precision), moves=tuple(m.moves), blocks=executed)


def _jump(labels, n: int, b: _Block) -> int:
    if n not in labels:
        raise _Syntax("128", f"sequence number or label {n} not found")
    return labels[n]


def _step(m: _Machine, blocks, pc: int, b: _Block, labels) -> int | None:
    k = b.kind
    if k == "assign":
        m.set(b.a(m), b.b(m))
    elif k == "assign_named":
        m.names[b.a] = m.ctx.plus(b.b(m))
    elif k == "while":
        if b.a is not None and not b.a(m):
            return b.target + 1
    elif k == "end":
        return b.target
    elif k == "owhile":
        if not b.a(m):
            return b.target + 1
    elif k == "oendwhile":
        return b.target
    elif k == "oif":
        j = pc
        while not blocks[j].a(m):  # try the if, then each elseif, in turn
            j = blocks[j].target
            if blocks[j].kind in ("oendif", "oelse"):
                break
        return j + 1
    elif k in ("oelse", "oelseif"):
        return _if_chain_end(blocks, pc) + 1  # reached from a branch that ran: skip the rest
    elif k == "oendif":
        pass
    elif k == "if_then":
        if b.a(m):
            return _step(m, blocks, pc, b.b, labels)
    elif k == "if_goto":
        if b.a(m):
            return _jump(labels, m.index(b.b(m)), b)
    elif k == "goto":
        return _jump(labels, m.index(b.b(m)), b)
    elif k == "if_label":
        if b.a(m):
            return _jump(labels, b.b, b)
    elif k == "label":
        pass
    elif k == "stop":
        return None
    elif k == "words":
        return _words(m, b, pc)
    return pc + 1


def _words(m: _Machine, b: _Block, pc: int) -> int | None:
    values: dict[str, Decimal] = {}
    gs: list[Decimal] = []
    ms: list[Decimal] = []
    for letter, f in b.a:
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
        raise _Syntax("arc", "arcs are outside what the simulator runs")
    m.move(b.line, values)
    if any(v in (2, 30, 99) for v in ms):
        return None  # end of program
    return pc + 1


def moves_csv(sim: Simulation, decimals: int = 6) -> str:
    """The moves as CSV: ``line,motion,x,y,z,feed``."""
    rows = ["line,motion,x,y,z,feed"]
    for mv in sim.moves:
        rows.append(f"{mv.line},{mv.motion},{mv.x:.{decimals}f},{mv.y:.{decimals}f},{mv.z:.{decimals}f},{mv.feed:g}")
    return "\n".join(rows) + "\n"
