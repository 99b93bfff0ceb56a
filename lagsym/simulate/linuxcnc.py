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
from .blocks import (Assign, AssignNamed, Block, Nop, OElse, OElseIf, OEndIf, OEndWhile, OIf, OWhile, Output,
                     Words)
from .expressions import expression, reference, word_values


__all__ = ["parse_block"]

INCREMENTS = CONTROLS["linuxcnc"].macro.integer_increments  # how this language reads an axis word with no point

PROBE = float(CONTROLS["linuxcnc"].probing.move[1:])  # G38.2, probe toward the work, an error without contact
_LOG = re.compile(r"\(\s*(LOGOPEN|LOGAPPEND|LOGCLOSE|LOG)\s*(?:,([^)]*))?\)", re.I)
_OWORD = re.compile(r"[oO]\s*(\d+|<[^>]+>)\s*([a-z]+)\s*(.*)", re.I)
_CONDITIONAL = {"while": OWhile, "if": OIf, "elseif": OElseIf}
_PLAIN = {"else": OElse, "endif": OEndIf, "endwhile": OEndWhile}


def parse_block(line: int, raw: str, text: str) -> Block:
    """The block for one stripped, non-empty line ``text`` (``raw`` as it stood in the program)."""
    log = _LOG.search(text)
    t = re.sub(r"^[Nn]\d+\s*", "", strip_comments(text).strip())
    if log:
        if t:
            raise BlockAlarm("not-run", "a log comment on a line with other words, which the simulator does not run")
        return _log(line, raw, log.group(1).upper(), log.group(2) or "")
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
    return Words(line, raw, word_values(t, INCREMENTS, PROBE))


def _log(line: int, raw: str, word: str, rest: str) -> Output:
    """``(LOGOPEN,name)``, ``(LOG,text)`` with ``#n`` parameters, ``(LOGCLOSE)``."""
    if word in ("LOGOPEN", "LOGAPPEND"):
        return Output(line, raw, "open", name=rest.strip())
    if word == "LOGCLOSE":
        return Output(line, raw, "close")
    items, pos = [], 0
    for m in re.finditer(r"#(\d+)", rest):
        if m.start() > pos:
            items.append(("text", rest[pos:m.start()]))
        items.append(("param", int(m.group(1))))
        pos = m.end()
    if pos < len(rest):
        items.append(("text", rest[pos:]))
    return Output(line, raw, "print", tuple(items))
