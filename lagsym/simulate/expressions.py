"""Tokens and expressions of the macro languages, compiled once into closures ``f(control) -> Decimal``.

An expression (``[#1+2.]*SQRT[#3]``, ``#[#2+1]``, ``#<x> LT 5``) is read
into a closure that the executor calls each time the block runs, with the
:class:`~lagsym.simulate.control.Control` that holds the variables and does
the arithmetic.  Reading checks what a Fanuc checks when it reads a block:
brackets nested at most 5 deep (alarm 118) and well formed (alarm 114).
"""

from __future__ import annotations

import re
from decimal import Decimal

from ..gcode.words import FUNCTIONS, WordError, words
from .alarms import BlockAlarm

__all__ = ["expression", "reference", "word_values", "MAX_BRACKETS"]

MAX_BRACKETS = 5  # Fanuc alarm 118

_TOKEN = re.compile(r"\s*(?:(?P<num>\d+\.?\d*|\.\d+)|(?P<name>#<[^>]*>)|(?P<word>[A-Za-z_]+)"
                    r"|(?P<op>\*\*|[-+*/\[\]#]))")
_FUNCS = frozenset(FUNCTIONS)
_CMP = {"EQ", "NE", "GT", "GE", "LT", "LE"}
_LOGIC = {"AND", "OR", "XOR"}


def _tokens(text: str) -> list[tuple[str, str]]:
    out, pos, depth = [], 0, 0
    text = text.rstrip()
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            raise BlockAlarm("114", f"cannot read {text[pos:pos + 10]!r}")
        kind = m.lastgroup
        val = m.group(kind)
        if kind == "word":
            val = val.upper()
        if val == "[":
            depth += 1
            if depth > MAX_BRACKETS:
                raise BlockAlarm("118", f"brackets nested deeper than {MAX_BRACKETS}")
        elif val == "]":
            depth -= 1
            if depth < 0:
                raise BlockAlarm("118", "a ']' without its '['")
        out.append((kind, val))
        pos = m.end()
    if depth:
        raise BlockAlarm("118", "a '[' without its ']'")
    return out


class _Parser:
    """Recursive descent over tokens; builds closures ``f(control) -> Decimal``."""

    def __init__(self, toks):
        self.toks, self.i = toks, 0

    def peek(self):
        return self.toks[self.i] if self.i < len(self.toks) else (None, None)

    def take(self, value=None):
        tok = self.peek()
        if tok[0] is None or (value is not None and tok[1] != value):
            raise BlockAlarm("114", f"expected {value!r}" if value else "unexpected end of block")
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
        raise BlockAlarm("114", f"unexpected {val!r}")

    def reference(self):
        """After ``#``: a number, ``[expr]`` or another ``#``; returns ``f(control) -> int``."""
        kind, val = self.peek()
        if kind == "num":
            self.take()
            if "." in val:
                raise BlockAlarm("114", f"variable number #{val} is not an integer")
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
        raise BlockAlarm("114", "'#' without a variable number")


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


def expression(text: str):
    """The closure ``f(control) -> Decimal`` for the whole of ``text``; a value of 0 is false, any other true."""
    p = _Parser(_tokens(text))
    f = p.expr()
    if p.i != len(p.toks):
        raise BlockAlarm("114", f"unexpected {p.toks[p.i][1]!r}")
    return f


def reference(text: str):
    """The closure ``f(control) -> int`` for the variable number of ``#n``, ``#[expr]`` or ``##n``."""
    p = _Parser(_tokens(text))
    p.take("#")
    r = p.reference()
    if p.i != len(p.toks):
        raise BlockAlarm("114", f"unexpected {p.toks[p.i][1]!r}")
    return r


_AXIS_DECIMAL = set("XYZABCIJKRUVW")
_PLAIN_NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)")


def _word_value(letter: str, text: str, dialect: str):
    """The closure for the value of one word: a constant read as the control reads it, or an expression.

    A Fanuc reads an axis word without a decimal point in least input
    increments (``X12`` is 0.012 mm); the simulator refuses it rather than guess.
    """
    t = text.strip()
    if not t:
        raise BlockAlarm("114", f"address {letter} without a value")
    if _PLAIN_NUMBER.fullmatch(t):
        if letter in _AXIS_DECIMAL and "." not in t and dialect == "fanuc":
            raise BlockAlarm("decimal-point",
                             f"{letter}{t} has no decimal point (a Fanuc would read it in least increments)")
        return lambda m, v=t: m.const(v)
    return expression(t)


def word_values(text: str, dialect: str) -> tuple[tuple[str, object], ...]:
    """The words of a comment-free block as ``(letter, closure)`` pairs, each value read as ``dialect`` reads it."""
    try:
        split = words(text)
    except WordError as e:
        raise BlockAlarm("114", str(e)) from None
    return tuple((letter, _word_value(letter, value, dialect)) for letter, value in split)
