"""Program text to blocks: the lines a control skips, the block-length alarm, one parser per dialect."""

from __future__ import annotations

import re

from ..controls import Control, control, names
from . import fanuc, heidenhain, linuxcnc
from .alarms import BlockAlarm, ControlAlarm
from .blocks import Block, Nop

__all__ = ["SIM_DIALECTS", "PARSERS", "detect_dialect", "read_blocks"]

PARSERS = {"fanuc": fanuc.parse_block, "linuxcnc": linuxcnc.parse_block, "heidenhain": heidenhain.parse_block}
"""The parser of each macro language (:attr:`lagsym.controls.MacroLanguage.name`)."""
SIM_DIALECTS = names(macros=True)
"""The controls the simulator runs: those with a macro language."""


def detect_dialect(text: str) -> str:
    """Guess the dialect of a program: ``BEGIN PGM`` is Heidenhain, ``o100 while``, ``#<name>``, a ``G38.2``
    probe or a ``(LOGOPEN,..)`` LinuxCNC, else Fanuc.

    Examples
    --------
    >>> detect_dialect("0 BEGIN PGM 1 MM\\n1 END PGM 1 MM\\n"), detect_dialect("o100 while [1 LT 2]\\n")
    ('heidenhain', 'linuxcnc')
    """
    if re.search(r"^\s*\d*\s*BEGIN\s+PGM", text, re.M | re.I):
        return "heidenhain"
    if re.search(r"^[ \t]*o[ \t]*[\d<]\S*[ \t]+(while|if|do|sub|repeat)\b", text, re.M | re.I) or "#<" in text:
        return "linuxcnc"
    if re.search(r"\bG\s*38\.[2-5]|\(\s*LOG(OPEN|APPEND)\s*,", text, re.I):
        return "linuxcnc"
    return "fanuc"


def read_blocks(text: str, dialect: str | Control) -> list[Block]:
    """The blocks of ``text`` in order, without blank, ``%`` and block-delete (``/``) lines.

    The second ``%`` line ends the program, as for every reader of a program
    (:func:`lagsym.gcode.program_blocks`): a control reads nothing after it.

    Raises
    ------
    ControlAlarm
        For a line longer than the control reads, or one its parser cannot read.
    """
    c = control(dialect)
    limit = c.max_block
    parse = PARSERS[c.macro.name]
    blocks = []
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    percent = 0
    for n, raw in enumerate(lines, start=1):
        t = raw.strip()
        if t.startswith("%"):
            percent += 1
            if percent == 2:
                break
            continue
        if len(raw) > limit:
            raise ControlAlarm("block", f"block of {len(raw)} characters, more than the {limit} the control reads",
                               n, raw)
        if not t or t.startswith("/"):
            continue
        try:
            b = parse(n, raw, t)
        except BlockAlarm as e:
            raise ControlAlarm(e.alarm, e.message, n, raw) from None
        if not isinstance(b, Nop) or b.sequence is not None:
            blocks.append(b)
    return blocks
