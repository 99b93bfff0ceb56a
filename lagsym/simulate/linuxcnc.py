"""LinuxCNC O-word programs read into blocks: ``#n``/``#<name>`` parameters, ``while``/``if`` o-words, words.

``(...)`` and ``;`` comments are taken out and a leading ``N`` number is
dropped (LinuxCNC has no ``GOTO``).  Other o-words (``sub``, ``call``,
``repeat``, ``do``) are refused rather than skipped.
"""

from __future__ import annotations

import re

from ..gcode.words import strip_comments
from ..controls import CONTROLS
from .alarms import BlockAlarm
from .blocks import Assign, AssignNamed, Block, Nop, OElse, OElseIf, OEndIf, OEndWhile, OIf, OWhile, Words
from .expressions import expression, reference, word_values


__all__ = ["parse_block"]

INCREMENTS = CONTROLS["linuxcnc"].macro.integer_increments  # how this language reads an axis word with no point

_OWORD = re.compile(r"[oO]\s*(\d+|<[^>]+>)\s*([a-z]+)\s*(.*)", re.I)
_CONDITIONAL = {"while": OWhile, "if": OIf, "elseif": OElseIf}
_PLAIN = {"else": OElse, "endif": OEndIf, "endwhile": OEndWhile}


def parse_block(line: int, raw: str, text: str) -> Block:
    """The block for one stripped, non-empty line ``text`` (``raw`` as it stood in the program)."""
    t = re.sub(r"^[Nn]\d+\s*", "", strip_comments(text).strip())
    if not t:
        return Nop(line, raw)
    m = _OWORD.fullmatch(t)
    if m:
        oword, keyword, rest = m.group(1).lower(), m.group(2).lower(), m.group(3).strip()
        if keyword in _CONDITIONAL:
            return _CONDITIONAL[keyword](line, raw, oword, expression(rest))
        if keyword not in _PLAIN:
            raise BlockAlarm("o-word", f"o-word {m.group(2)!r} is outside what the simulator runs")
        if keyword == "endwhile" and rest:
            raise BlockAlarm("114", "endwhile takes no condition here")
        return _PLAIN[keyword](line, raw, oword)
    if t.startswith("#"):
        lhs, eq, rhs = t.partition("=")
        if not eq:
            raise BlockAlarm("114", "a parameter without '='")
        lhs = lhs.strip()
        if lhs.startswith("#<"):
            return AssignNamed(line, raw, lhs[2:-1].strip().lower(), expression(rhs))
        return Assign(line, raw, reference(lhs), expression(rhs))
    return Words(line, raw, word_values(t, INCREMENTS))
