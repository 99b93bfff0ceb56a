"""Program text to blocks: the lines a control skips, the block-length alarm, one parser per dialect."""

from __future__ import annotations

import re

from ..controls import Control, control, names
from ..gcode.program import program_blocks
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
    """The blocks of ``text`` in order, as every reader of a program takes them (:func:`lagsym.gcode.program_blocks`).

    Blank and ``%`` lines are passed over and the second ``%`` line ends the
    program; a block-delete ``/`` is taken off and the block run, as a control
    runs it with its block-delete switch off (and as ``verify`` reads it).

    Raises
    ------
    ControlAlarm
        For a line longer than the control reads, or one its parser cannot read.
    """
    c = control(dialect)
    limit = c.max_block
    parse = PARSERS[c.macro.name]
    blocks = []
    for n, raw, t in program_blocks(text):
        if len(raw) > limit:
            raise ControlAlarm("block", f"block of {len(raw)} characters, more than the {limit} the control reads",
                               n, raw)
        try:
            b = parse(n, raw, t)
        except BlockAlarm as e:
            raise ControlAlarm(e.alarm, e.message, n, raw) from None
        if not isinstance(b, Nop) or b.sequence is not None:
            blocks.append(b)
    return blocks
