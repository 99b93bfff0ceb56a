"""Heidenhain conversational programs read into blocks: ``FN`` Q-parameter arithmetic and jumps, ``LBL``, ``L``.

What lagsym's Heidenhain macros use, and the common core around it: ``FN 0``
to ``FN 5`` assignments, ``FN 9`` to ``FN 12`` conditional jumps to a
label, straight ``L`` moves with ``X Y Z`` (absolute), ``R0``, ``F`` or ``FMAX``
and ``M`` functions.  Set-up blocks (``BLK FORM``, ``TOOL CALL``, ``TOOL DEF``)
do nothing here; ``;`` starts a comment.  What would move the tool another
way is refused with its block, never skipped: cycles (``CYCL DEF`` may shift,
rotate or scale the datum; ``CYCL CALL``, ``M99`` and ``M89`` run a cycle),
incremental ``IX``, radius compensation ``RL``/``RR``, other axes, and ``M``
functions outside :data:`lagsym.gcode.program.PLAIN_M` (``M91``/``M92``
machine positions among them).
"""

from __future__ import annotations

import re
from ..gcode.program import unrun_code
from .alarms import BlockAlarm
from .blocks import Assign, Block, IfGotoLabel, Label, Nop, Stop, Words
from .expressions import expr_of

__all__ = ["parse_block"]

_OPERAND = r"([+-]?\s*(?:Q\d+|\d+\.?\d*|\.\d+))"
_ASSIGN = re.compile(r"FN\s*(\d+)\s*:\s*Q(\d+)\s*=\s*" + _OPERAND + r"(?:\s*([-+*/])\s*" + _OPERAND + r")?", re.I)
_JUMP = re.compile(r"FN\s*(9|10|11|12)\s*:\s*IF\s+" + _OPERAND + r"\s+(EQU|NE|GT|LT)\s+" + _OPERAND
                   + r"\s+GOTO\s+LBL\s+(\d+)", re.I)
_SET_UP = ("BEGIN PGM", "BLK FORM", "TOOL CALL", "TOOL DEF")
_AXIS = re.compile(r"(?<![A-Z])([XYZ])\s*" + _OPERAND, re.I)
_FEED = re.compile(r"(?<![A-Z])F\s*(\d+\.?\d*|MAX)(?![A-Z0-9.])", re.I)
_M = re.compile(r"(?<![A-Z])M\s*(\d+)(?![0-9.])", re.I)
_R0 = re.compile(r"(?<![A-Z])R0(?![0-9.])", re.I)
_OPERATORS = {1: "+", 2: "-", 3: "*", 4: "/"}
_RELATIONS = {9: "EQU", 10: "NE", 11: "GT", 12: "LT"}
_TESTS = {"EQU": "EQ", "NE": "NE", "GT": "GT", "LT": "LT"}  # the relation as the expression trees name it


def parse_block(line: int, raw: str, text: str) -> Block:
    """The block for one stripped, non-empty line ``text`` (``raw`` as it stood in the program)."""
    t = re.sub(r"^\d+\s+", "", text).rstrip("*").strip()
    if ";" in t:
        t = t.split(";", 1)[0].strip()
    u = t.upper()
    if not t or u.startswith(_SET_UP):
        return Nop(line, raw)
    if u.startswith("CYCL"):
        raise BlockAlarm("not-run", "cycles (CYCL DEF, CYCL CALL) are outside what the simulator runs")
    if u.startswith("END PGM"):
        return Stop(line, raw)
    m = re.fullmatch(r"LBL\s+(\d+)", t, re.I)
    if m:
        return Label(line, raw, int(m.group(1)))
    t = re.sub(r"^(FN\s*5\s*:\s*Q\d+\s*=\s*)SQRT\s*", r"\1", t, flags=re.I)
    m = _ASSIGN.fullmatch(t)
    if m:
        return Assign(line, raw, expr_of(("lit", int(m.group(2)))), expr_of(_arithmetic(*m.group(1, 3, 4, 5))))
    m = _JUMP.fullmatch(t)
    if m:
        return IfGotoLabel(line, raw, expr_of(_comparison(*m.group(1, 2, 3, 4))), int(m.group(5)))
    m = re.fullmatch(r"L\s+(.*)", t, re.I)
    if m:
        return Words(line, raw, _straight(m.group(1)))
    m = re.fullmatch(r"M\s*(\d+)", t, re.I)
    if m:
        _check_m(m.group(1))
        return Words(line, raw, (("M", expr_of(("dec", m.group(1)))),))
    raise BlockAlarm("114", f"cannot read {t[:30]!r}")


def _check_m(code: str) -> None:
    """Refuse an ``M`` function that may run a cycle, call, or move (:func:`lagsym.gcode.program.unrun_code`)."""
    why = unrun_code("M", int(code))
    if why is not None:
        raise BlockAlarm("not-run", f"M{int(code)} {why}, which the simulator does not run")


def _operand(text: str):
    """The tree of ``Qn``, ``-Qn`` or a signed constant."""
    t = text.replace(" ", "")
    neg = t.startswith("-")
    t = t.lstrip("+-")
    if t.upper().startswith("Q"):
        q = ("var", ("lit", int(t[1:])))
        return ("neg", q) if neg else q
    return ("num", ("-" if neg else "") + t)


def _arithmetic(fn: str, a: str, op: str | None, b: str | None):
    """``FN 0: Qn = a``, ``FN 1..4: Qn = a op b``, ``FN 5: Qn = SQRT a``."""
    fn, fa = int(fn), _operand(a)
    if fn == 0 and op is None:
        return fa
    if fn in _OPERATORS and op == _OPERATORS[fn]:
        return ({1: "add", 2: "sub", 3: "mul", 4: "div"}[fn], fa, _operand(b))
    if fn == 5 and op is None:
        return ("func", "SQRT", fa)
    raise BlockAlarm("114", f"FN {fn} does not take this form")


def _comparison(fn: str, a: str, relation: str, b: str):
    """``FN 9..12: IF a EQU|NE|GT|LT b``: each FN has its one relation."""
    fn, relation = int(fn), relation.upper()
    want = _RELATIONS[fn]
    if relation != want:
        raise BlockAlarm("114", f"FN {fn} compares with {want}, not {relation}")
    return ("cmp", _TESTS[relation], _operand(a), _operand(b))


def _straight(rest: str):
    """The words of ``L X.. Y.. Z.. F..``: ``FMAX`` is a rapid (``G0``), any other feed a ``G1``."""
    axes = [(w[0].upper(), expr_of(_operand(w[1]))) for w in _AXIS.findall(rest)]
    for code in _M.findall(rest):
        _check_m(code)
    left = _R0.sub(" ", _M.sub(" ", _FEED.sub(" ", _AXIS.sub(" ", rest)))).strip()
    if left:
        raise BlockAlarm("not-run", f"{left[:20]!r} in a straight move is outside what the simulator runs "
                                    "(it reads X Y Z absolute, R0, F or FMAX, M)")
    feed = _FEED.search(rest)
    rapid = feed is not None and feed.group(1).upper() == "MAX"
    out = [("G", expr_of(("dec", "0" if rapid else "1")))]
    if feed and not rapid:
        out.append(("F", expr_of(("num", feed.group(1)))))
    return tuple(out + axes)
