"""Heidenhain conversational programs read into blocks: ``FN`` Q-parameter arithmetic and jumps, ``LBL``, ``L``.

What lagsym's Heidenhain macros use, and the common core around it: ``FN 0``
to ``FN 5`` assignments, ``FN 9`` to ``FN 12`` conditional jumps to a
label, straight ``L`` moves with ``F`` or ``FMAX``, ``M`` functions.  Set-up
blocks (``BLK FORM``, ``TOOL CALL``, ``CYCL``) do nothing here; ``;`` starts
a comment.
"""

from __future__ import annotations

import re
from decimal import Decimal

from .alarms import BlockAlarm
from .blocks import Assign, Block, IfGotoLabel, Label, Nop, Stop, Words

__all__ = ["parse_block"]

_OPERAND = r"([+-]?\s*(?:Q\d+|\d+\.?\d*|\.\d+))"
_ASSIGN = re.compile(r"FN\s*(\d+)\s*:\s*Q(\d+)\s*=\s*" + _OPERAND + r"(?:\s*([-+*/])\s*" + _OPERAND + r")?", re.I)
_JUMP = re.compile(r"FN\s*(9|10|11|12)\s*:\s*IF\s+" + _OPERAND + r"\s+(EQU|NE|GT|LT)\s+" + _OPERAND
                   + r"\s+GOTO\s+LBL\s+(\d+)", re.I)
_SET_UP = ("BEGIN PGM", "BLK FORM", "TOOL CALL", "TOOL DEF", "CYCL")
_OPERATORS = {1: "+", 2: "-", 3: "*", 4: "/"}
_RELATIONS = {9: "EQU", 10: "NE", 11: "GT", 12: "LT"}
_TESTS = {"EQU": lambda x, y: x == y, "NE": lambda x, y: x != y, "GT": lambda x, y: x > y, "LT": lambda x, y: x < y}


def parse_block(line: int, raw: str, text: str) -> Block:
    """The block for one stripped, non-empty line ``text`` (``raw`` as it stood in the program)."""
    t = re.sub(r"^\d+\s+", "", text).rstrip("*").strip()
    if ";" in t:
        t = t.split(";", 1)[0].strip()
    u = t.upper()
    if not t or u.startswith(_SET_UP):
        return Nop(line, raw)
    if u.startswith("END PGM"):
        return Stop(line, raw)
    m = re.fullmatch(r"LBL\s+(\d+)", t, re.I)
    if m:
        return Label(line, raw, int(m.group(1)))
    t = re.sub(r"^(FN\s*5\s*:\s*Q\d+\s*=\s*)SQRT\s*", r"\1", t, flags=re.I)
    m = _ASSIGN.fullmatch(t)
    if m:
        return Assign(line, raw, lambda c, n=int(m.group(2)): n, _arithmetic(*m.group(1, 3, 4, 5)))
    m = _JUMP.fullmatch(t)
    if m:
        return IfGotoLabel(line, raw, _comparison(*m.group(1, 2, 3, 4)), int(m.group(5)))
    m = re.fullmatch(r"L\s+(.*)", t, re.I)
    if m:
        return Words(line, raw, _straight(m.group(1)))
    m = re.fullmatch(r"M\s*(\d+)", t, re.I)
    if m:
        return Words(line, raw, (("M", lambda c, v=m.group(1): Decimal(v)),))
    raise BlockAlarm("114", f"cannot read {t[:30]!r}")


def _operand(text: str):
    t = text.replace(" ", "")
    neg = t.startswith("-")
    t = t.lstrip("+-")
    if t.upper().startswith("Q"):
        n = int(t[1:])
        return (lambda c: c.ctx.minus(c.get(n))) if neg else (lambda c: c.get(n))
    return lambda c, v=("-" if neg else "") + t: c.const(v)


def _arithmetic(fn: str, a: str, op: str | None, b: str | None):
    """``FN 0: Qn = a``, ``FN 1..4: Qn = a op b``, ``FN 5: Qn = SQRT a``."""
    fn, fa = int(fn), _operand(a)
    if fn == 0 and op is None:
        return fa
    if fn in _OPERATORS and op == _OPERATORS[fn]:
        fb = _operand(b)
        return {1: lambda c: c.ctx.add(fa(c), fb(c)), 2: lambda c: c.ctx.subtract(fa(c), fb(c)),
                3: lambda c: c.ctx.multiply(fa(c), fb(c)), 4: lambda c: c.divide(fa(c), fb(c))}[fn]
    if fn == 5 and op is None:
        return lambda c: c.func("SQRT", fa(c))
    raise BlockAlarm("114", f"FN {fn} does not take this form")


def _comparison(fn: str, a: str, relation: str, b: str):
    """``FN 9..12: IF a EQU|NE|GT|LT b``: each FN has its one relation."""
    fn, relation = int(fn), relation.upper()
    want = _RELATIONS[fn]
    if relation != want:
        raise BlockAlarm("114", f"FN {fn} compares with {want}, not {relation}")
    fa, fb, test = _operand(a), _operand(b), _TESTS[relation]
    return lambda c: test(fa(c), fb(c))


def _straight(rest: str):
    """The words of ``L X.. Y.. Z.. F..``: ``FMAX`` is a rapid (``G0``), any other feed a ``G1``."""
    axes = [(w[0].upper(), _operand(w[1])) for w in re.findall(r"([XYZ])\s*" + _OPERAND, rest, re.I)]
    feed = re.search(r"\bF\s*(\d+\.?\d*|MAX)\b", rest, re.I)
    rapid = feed is not None and feed.group(1).upper() == "MAX"
    out = [("G", lambda c, v="0" if rapid else "1": Decimal(v))]
    if feed and not rapid:
        out.append(("F", lambda c, v=feed.group(1): c.const(v)))
    return tuple(out + axes)
