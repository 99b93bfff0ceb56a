"""Tokens and expressions of the macro languages, read once into trees and closures ``f(control) -> Decimal``.

An expression (``[#1+2.]*SQRT[#3]``, ``#[#2+1]``, ``#<x> LT 5``) is read
into an :class:`Expr`: its tree (:data:`Node`), which
:mod:`~lagsym.simulate.compiler` turns into the Python code the executor
runs, and a closure over the methods of
:class:`~lagsym.simulate.control.Control` (the variables and the
arithmetic), which the runaway guard's analysis calls on probe controls.  Reading checks what a Fanuc checks when it reads a block:
brackets nested at most 5 deep (alarm 118) and well formed (alarm 114).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from decimal import Decimal

from ..gcode.program import unrun_code
from ..gcode.words import FUNCTIONS, WordError, words
from .alarms import BlockAlarm

__all__ = ["Expr", "Node", "expression", "reference", "word_values", "closure", "expr_of", "MAX_BRACKETS"]

MAX_BRACKETS = 5  # Fanuc alarm 118

_TOKEN = re.compile(r"\s*(?:(?P<num>\d+\.?\d*|\.\d+)|(?P<name>#<[^>]*>)|(?P<word>[A-Za-z_]+)"
                    r"|(?P<op>\*\*|[-+*/\[\]#]))")
_FUNCS = frozenset(FUNCTIONS)
_CMP = {"EQ", "NE", "GT", "GE", "LT", "LE"}
_LOGIC = {"AND", "OR", "XOR"}

Node = tuple
"""An expression tree: ``("num", text)`` a constant as written, ``("dec", text)`` an exact one, ``("var", ref)``,
``("named", name)``, ``("neg", a)``, ``("add"|"sub"|"mul"|"div"|"mod"|"pow"|"atan2", a, b)``,
``("func", NAME, a)``, ``("cmp"|"logic", OP, a, b)``; a reference is ``("lit", n)``, ``("idx", expr)``
(``#[expr]``) or ``("ind", ref)`` (``##n``)."""


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
    """Recursive descent over tokens; builds expression trees (:data:`Node`)."""

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
            f = ("logic", op, f, self.compare())
        return f

    def compare(self):
        f = self.additive()
        while self.peek()[1] in _CMP:
            op = self.take()[1]
            f = ("cmp", op, f, self.additive())
        return f

    def additive(self):
        f = self.term()
        while self.peek()[1] in ("+", "-"):
            op = self.take()[1]
            f = ("add" if op == "+" else "sub", f, self.term())
        return f

    def term(self):
        f = self.power()
        while self.peek()[1] in ("*", "/", "MOD"):
            op = self.take()[1]
            f = ({"*": "mul", "/": "div"}.get(op, "mod"), f, self.power())
        return f

    def power(self):
        f = self.unary()
        if self.peek()[1] == "**":
            self.take()
            return ("pow", f, self.unary())
        return f

    def unary(self):
        # A run of signs read in a loop and folded to at most one negation: 250 of them would otherwise nest
        # 250 deep here and in the generated code, past what Python compiles.
        negative = False
        while self.peek()[1] in ("-", "+"):
            negative ^= self.take()[1] == "-"
        return ("neg", self.primary()) if negative else self.primary()

    def primary(self):
        kind, val = self.take()
        if kind == "num":
            return ("num", val)
        if val == "[":
            f = self.expr()
            self.take("]")
            return f
        if kind == "name":
            return ("named", val[2:-1].strip().lower())
        if val == "#":
            return ("var", self.reference())
        if kind == "word" and val in _FUNCS:
            self.take("[")
            a = self.expr()
            self.take("]")
            if val == "ATAN" and self.peek()[1] == "/":
                self.take("/")
                self.take("[")
                b = self.expr()
                self.take("]")
                return ("atan2", a, b)
            return ("func", val, a)
        raise BlockAlarm("114", f"unexpected {val!r}")

    def reference(self):
        """After ``#``: a number, ``[expr]`` or another ``#``; returns a reference node."""
        kind, val = self.peek()
        if kind == "num":
            self.take()
            if "." in val:
                raise BlockAlarm("114", f"variable number #{val} is not an integer")
            return ("lit", int(val))
        if val == "[":
            self.take()
            f = self.expr()
            self.take("]")
            return ("idx", f)
        if val == "#":
            self.take()
            return ("ind", self.reference())
        raise BlockAlarm("114", "'#' without a variable number")


_TESTS = {"EQ": lambda a, b: a == b, "NE": lambda a, b: a != b, "GT": lambda a, b: a > b,
          "GE": lambda a, b: a >= b, "LT": lambda a, b: a < b, "LE": lambda a, b: a <= b}


def closure(node: Node):
    """The closure ``f(control) -> Decimal`` (``-> int`` for a reference node) that evaluates ``node``.

    Every operation goes through the control's methods, so a control that
    overrides them (the runaway guard's probes) sees every read; the
    executor runs the compiled form of :mod:`~lagsym.simulate.compiler`.
    """
    kind = node[0]
    if kind == "num":
        return lambda m, t=node[1]: m.const(t)
    if kind == "dec":
        return lambda m, v=Decimal(node[1]): v
    if kind == "named":
        return lambda m, n=node[1]: m.named(n)
    if kind == "lit":
        return lambda m, n=node[1]: n
    if kind == "neg":
        f = closure(node[1])
        return lambda m: m.ctx.minus(f(m))
    if kind == "func":
        f, name = closure(node[2]), node[1]
        return lambda m: m.func(name, f(m))
    if kind in ("var", "idx", "ind"):
        f = closure(node[1])
        if kind == "var":
            return lambda m: m.get(f(m))
        return (lambda m: m.index(f(m))) if kind == "idx" else (lambda m: m.index(m.get(f(m))))
    f, g = closure(node[-2]), closure(node[-1])
    return _BINARY[kind](node[1], f, g)


def _logic(op, f, g):
    def run(m):
        a, b = bool(f(m)), bool(g(m))
        return Decimal(int(a and b if op == "AND" else a or b if op == "OR" else a != b))

    return run


def _cmp(op, f, g):
    t = _TESTS[op]
    return lambda m: Decimal(int(t(f(m), g(m))))


def _mod(f, g):
    return lambda m: m.ctx.remainder(f(m), g(m)) if g(m) else m.divide(f(m), g(m))


_BINARY = {
    "add": lambda op, f, g: lambda m: m.ctx.add(f(m), g(m)),
    "sub": lambda op, f, g: lambda m: m.ctx.subtract(f(m), g(m)),
    "mul": lambda op, f, g: lambda m: m.ctx.multiply(f(m), g(m)),
    "div": lambda op, f, g: lambda m: m.divide(f(m), g(m)),
    "mod": lambda op, f, g: _mod(f, g),
    "pow": lambda op, f, g: lambda m: m.ctx.power(f(m), g(m)),
    "atan2": lambda op, f, g: lambda m: m.atan2(f(m), g(m)),
    "cmp": _cmp, "logic": _logic,
}


@dataclass(frozen=True)
class Expr:
    """An expression read once: its tree ``node`` and, called with a control, its value.

    The tree is what :mod:`~lagsym.simulate.compiler` turns into Python code;
    calling the expression runs :func:`closure` (the runaway guard's analysis
    does, on probe controls).
    """

    node: tuple

    @cached_property
    def run(self) -> Callable:
        """The closure of the tree, built on the first call (most expressions are only compiled)."""
        return closure(self.node)

    def __call__(self, m):
        return self.run(m)


def expr_of(node: Node) -> Expr:
    """The :class:`Expr` of a tree."""
    return Expr(node)


def expression(text: str):
    """The closure ``f(control) -> Decimal`` for the whole of ``text``; a value of 0 is false, any other true."""
    p = _Parser(_tokens(text))
    f = p.expr()
    if p.i != len(p.toks):
        raise BlockAlarm("114", f"unexpected {p.toks[p.i][1]!r}")
    return expr_of(f)


def reference(text: str):
    """The closure ``f(control) -> int`` for the variable number of ``#n``, ``#[expr]`` or ``##n``."""
    p = _Parser(_tokens(text))
    p.take("#")
    r = p.reference()
    if p.i != len(p.toks):
        raise BlockAlarm("114", f"unexpected {p.toks[p.i][1]!r}")
    return expr_of(r)


_AXIS_DECIMAL = set("XYZABCIJKRUVW")
# The addresses the simulator reads or that move nothing (S T H D, the P of G64, the O of a program number);
# I J K R belong to arcs, which raise their own alarm.  Any other (A B C U V W: more axes; Q L E: a cycle's
# or a call's parameters) would be skipped, and the path the simulator reports would not be the machine's.
_RUN_LETTERS = frozenset("GMXYZFSTHDPNOIJKR")
_PLAIN_NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)")
_SIGNS = re.compile(r"[-+]\s*[-+]")  # X--1. or X+-1.: a control's number has one sign at most


def _word_value(letter: str, text: str, increments: bool):
    """The closure for the value of one word: a constant read as the control reads it, or an expression.

    A Fanuc (``increments``) reads an axis word without a decimal point in
    least input increments (``X12`` is 0.012 mm); the simulator refuses it
    rather than guess.
    """
    t = text.strip()
    if letter not in _RUN_LETTERS:
        raise BlockAlarm("not-run", f"address {letter} ({letter}{t}) moves an axis or sets a parameter "
                                    "the simulator does not run")
    if not t:
        raise BlockAlarm("114", f"address {letter} without a value")
    if _SIGNS.match(t):
        raise BlockAlarm("114", f"{letter}{t}: two signs in a row, which a control reads as no number")
    if _PLAIN_NUMBER.fullmatch(t):
        if letter in _AXIS_DECIMAL and "." not in t and increments:
            raise BlockAlarm("decimal-point",
                             f"{letter}{t} has no decimal point (a Fanuc would read it in least increments)")
        return expr_of(("num", t))
    return expression(t)


def word_values(text: str, increments: bool, probe: float | None = None) -> tuple[tuple[str, object], ...]:
    """The words of a comment-free block as ``(letter, closure)`` pairs, each value read as the control reads it.

    ``increments``: the control reads an axis word without a decimal point in
    least input increments (:attr:`lagsym.controls.MacroLanguage.integer_increments`).
    ``probe``: the control's probing move (``31.0``, ``38.2``), which passes
    here; the executor runs it against a given surface, and refuses it without one.
    """
    try:
        split = words(text)
    except WordError as e:
        raise BlockAlarm("114", str(e)) from None
    for letter, value in split:  # a call's own words (G65 P9010 A1.) are named by the call, not by its A
        if letter in "GM" and _PLAIN_NUMBER.fullmatch(value.strip()):
            if letter == "G" and probe is not None and round(float(value), 1) == probe:
                continue
            why = unrun_code(letter, value)
            if why is not None:
                code = round(float(value), 1)
                raise BlockAlarm("not-run", f"{letter}{code:g} {why}, which the simulator does not run")
    return tuple((letter, _word_value(letter, value, increments)) for letter, value in split)
