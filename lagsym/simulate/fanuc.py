"""Fanuc Custom Macro B read into blocks: ``#n=..``, ``WHILE [..] DOm``, ``ENDm``, ``IF``, ``GOTO``, words.

A leading ``N`` number makes the block a ``GOTO`` target.  ``;`` is the end of
block on a Fanuc, not a comment, so only ``(...)`` comments are taken out.
"""

from __future__ import annotations

import re
from dataclasses import replace

from ..gcode.words import strip_comments
from ..controls import CONTROLS
from .alarms import BlockAlarm
from .blocks import Assign, Block, End, Goto, IfGoto, IfThen, Nop, Output, While, Words
from .expressions import expression, reference, word_values

__all__ = ["parse_block"]

INCREMENTS = CONTROLS["fanuc"].macro.integer_increments  # how this language reads an axis word with no point
PROBE = float(CONTROLS["fanuc"].probing.move[1:])  # G31, the skip move
_DPRNT_VAR = re.compile(r"#\s*(\d+)\s*\[\s*(\d)\s*(\d)\s*\]")
_DPRNT_TEXT = re.compile(r"[A-Z0-9*+\-./:= ]+", re.I)


def parse_block(line: int, raw: str, text: str) -> Block:
    """The block for one stripped, non-empty line ``text`` (``raw`` as it stood in the program)."""
    text = strip_comments(text, semicolon=False).strip()
    m = re.match(r"N\s*(\d+)\s*", text, re.I)
    b = _statement(line, raw, text[m.end():] if m else text)
    return replace(b, sequence=int(m.group(1))) if m else b


def _statement(line: int, raw: str, t: str) -> Block:
    if not t:
        return Nop(line, raw)
    m = re.fullmatch(r"(POPEN|PCLOS|DPRNT\s*\[(.*)\])", t, re.I)
    if m:
        word = m.group(1)[:5].upper()
        if word == "DPRNT":
            return Output(line, raw, "print", _dprnt(m.group(2)))
        return Output(line, raw, "open" if word == "POPEN" else "close")
    m = re.fullmatch(r"WHILE\s*(\[.*\])\s*DO\s*(\d+)", t, re.I)
    if m:
        return While(line, raw, expression(m.group(1)), int(m.group(2)))
    m = re.fullmatch(r"DO\s*(\d+)", t, re.I)
    if m:
        return While(line, raw, None, int(m.group(1)))
    m = re.fullmatch(r"END\s*(\d+)", t, re.I)
    if m:
        return End(line, raw, int(m.group(1)))
    m = re.fullmatch(r"IF\s*(\[.*\])\s*GOTO\s*(.+)", t, re.I)
    if m:
        return IfGoto(line, raw, expression(m.group(1)), expression(m.group(2)))
    m = re.fullmatch(r"IF\s*(\[.*\])\s*THEN\s*(.+)", t, re.I)
    if m:
        inner = _statement(line, raw, m.group(2).strip())
        if not isinstance(inner, Assign):
            raise BlockAlarm("114", "THEN must be followed by an assignment")
        return IfThen(line, raw, expression(m.group(1)), inner)
    m = re.fullmatch(r"GOTO\s*(.+)", t, re.I)
    if m:
        return Goto(line, raw, expression(m.group(1)))
    if t.startswith("#"):
        lhs, eq, rhs = t.partition("=")
        if not eq:
            raise BlockAlarm("114", "a variable without '='")
        return Assign(line, raw, reference(lhs), expression(rhs))
    if t.upper().startswith("O") and re.fullmatch(r"O\d+\s*", t, re.I):
        n = int(t[1:])
        if not 1 <= n <= 9999:
            raise BlockAlarm("114", f"program number O{n} is not 1-9999")
        return Nop(line, raw)
    return Words(line, raw, word_values(t, INCREMENTS, PROBE))


def _dprnt(body: str) -> tuple:
    """The items of ``DPRNT[..]``: text (``*`` prints a space) and variables ``#n[ab]``, ``a`` digits before the
    point and ``b`` after it."""
    items, pos = [], 0
    for m in _DPRNT_VAR.finditer(body):
        items += _text(body[pos:m.start()])
        digits, decimals = int(m.group(2)), int(m.group(3))
        if digits + decimals > 8 or digits == 0:
            raise BlockAlarm("114", f"DPRNT format [{digits}{decimals}]: 1 to 8 digits before the point, "
                                    f"at most 8 in all")
        items.append(("var", int(m.group(1)), digits, decimals))
        pos = m.end()
    items += _text(body[pos:])
    return tuple(items)


def _text(part: str) -> list:
    if not part:
        return []
    if "#" in part or not _DPRNT_TEXT.fullmatch(part):
        raise BlockAlarm("114", f"DPRNT text {part!r}: letters, digits, * and #n[ab] variables only")
    return [("text", part.replace("*", " ").upper())]
