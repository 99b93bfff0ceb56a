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
from .blocks import Assign, Block, End, Goto, IfGoto, IfThen, Nop, While, Words
from .expressions import expression, reference, word_values

__all__ = ["parse_block"]

INCREMENTS = CONTROLS["fanuc"].macro.integer_increments  # how this language reads an axis word with no point


def parse_block(line: int, raw: str, text: str) -> Block:
    """The block for one stripped, non-empty line ``text`` (``raw`` as it stood in the program)."""
    text = strip_comments(text, semicolon=False).strip()
    m = re.match(r"N\s*(\d+)\s*", text, re.I)
    b = _statement(line, raw, text[m.end():] if m else text)
    return replace(b, sequence=int(m.group(1))) if m else b


def _statement(line: int, raw: str, t: str) -> Block:
    if not t:
        return Nop(line, raw)
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
    return Words(line, raw, word_values(t, INCREMENTS))
