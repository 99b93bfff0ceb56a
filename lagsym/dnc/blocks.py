"""A part program as the blocks a control receives, and the framing that carries them down the line.

A part program is split into *blocks*: block ``N`` is the ``N``-th non-empty
line after the leading ``%`` line, counted from 1 (so the ``O1000`` line of a
Fanuc program is block 1).  This is the number ``lagsym send --start-block``
takes and the number a fault message prints.  N-words inside the blocks play
no part in it: many programs have none, and some repeat them.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError
from ..gcode.program import macro_uses

__all__ = ["Program", "parse_program", "frame", "check_drip", "check_iso", "tv_padded", "ISO_840", "DC1", "DC2", "DC3",
           "DC4"]

DC1, DC2, DC3, DC4 = 0x11, 0x12, 0x13, 0x14
_CONTROL_CODES = {DC1: "DC1", DC2: "DC2", DC3: "DC3", DC4: "DC4"}
ISO_840 = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789 \t+-./%():#=[]*,&$?@;<>'\"!")
"""The printable characters of the ISO 840 tape code as Fanuc's ISO code table lists them (no lower case)."""
# A control reading from tape cannot jump back: loops, jumps and M99 returns need the program in memory
# (M98 and G65 call a program that is already in memory, which a drip feed may do).
_JUMPS = frozenset({"loop", "jump", "return"})


@dataclass(frozen=True)
class Program:
    """A part program as the blocks a control receives, without framing or line ends.

    Attributes
    ----------
    blocks : tuple of str
        Block ``N`` (1-based, as ``--start-block`` counts) is ``blocks[N - 1]``.
    source : str
        Where the program came from, for messages.
    """

    blocks: tuple[str, ...]
    source: str = "<program>"

    def __len__(self) -> int:
        return len(self.blocks)

    def block(self, number: int) -> str:
        """Block ``number`` (1-based)."""
        return self.blocks[number - 1]


def parse_program(text: str, source: str = "<program>") -> Program:
    """Split program text into blocks: non-empty lines inside the ``%`` framing.

    A leading ``%`` line and the closing ``%`` line are framing, not blocks;
    the sender adds its own.  Characters a 7-bit line cannot carry, and the
    DC1 to DC4 codes that steer the line, are refused with the line they are on.

    Examples
    --------
    >>> parse_program("%\\nO1000\\nG21 G90\\n\\nG0 Z50.\\n%\\n").blocks
    ('O1000', 'G21 G90', 'G0 Z50.')
    """
    lines = [(i, line.strip()) for i, line in enumerate(text.splitlines(), start=1)]
    lines = [(i, line) for i, line in lines if line]
    if lines and lines[0][1] == "%":
        lines = lines[1:]
    for k, (i, line) in enumerate(lines):
        if line == "%":
            extra = lines[k + 1:]
            if extra:
                raise InputError(f"{source}: line {extra[0][0]} comes after the closing %; a control would not read it")
            lines = lines[:k]
            break
    if not lines:
        raise InputError(f"{source}: the program has no blocks")
    for i, line in lines:
        for ch in line:
            code = ord(ch)
            if code in _CONTROL_CODES:
                raise InputError(f"{source}: line {i} holds {_CONTROL_CODES[code]}, which would steer the line")
            if code > 126 or (code < 32 and ch != "\t"):
                raise InputError(f"{source}: line {i} holds {ch!r}, which a 7-bit serial line cannot carry")
            if ch == "%":
                raise InputError(f"{source}: line {i} holds %, which a control reads as the end of the program")
    return Program(tuple(line for _, line in lines), source)


def frame(blocks, eol: str, percent: bool, leader: str = "", trailer: str = "") -> list[tuple[int | None, bytes]]:
    """The line's contents as ``(block number or None, bytes)`` segments, in order.

    ``blocks`` is a sequence of ``(number, text)`` pairs; a number of ``None``
    marks a block that is not part of the program (a resume set-up block).
    Framing (leader, ``%`` lines, trailer) also has ``None``.

    Examples
    --------
    >>> frame([(1, "O1"), (2, "M30")], "\\n", True)
    [(None, b'%\\n'), (1, b'O1\\n'), (2, b'M30\\n'), (None, b'%\\n')]
    """
    out: list[tuple[int | None, bytes]] = []
    head = leader + ("%" + eol if percent else "")
    if head:
        out.append((None, head.encode("ascii")))
    out.extend((n, (text + eol).encode("ascii")) for n, text in blocks)
    tail = ("%" + eol if percent else "") + trailer
    if tail:
        out.append((None, tail.encode("ascii")))
    return out


def check_drip(program: Program) -> None:
    """Refuse a program a control cannot run from tape (a drip feed): loops, jumps and M99 returns.

    Examples
    --------
    >>> check_drip(parse_program("O1\\n#1=0\\nWHILE[#1LT3]DO1\\n#1=#1+1\\nEND1\\nM30", "m.nc"))
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: m.nc: block 3 (WHILE[#1LT3]DO1) loops or jumps, which a control cannot do in a program it reads from tape; upload it (--mode upload)
    """
    for number, block in enumerate(program.blocks, start=1):
        if macro_uses(block) & _JUMPS:
            raise InputError(f"{program.source}: block {number} ({block}) loops or jumps, which a control cannot "
                             "do in a program it reads from tape; upload it (--mode upload)")


def check_iso(program: Program) -> None:
    """Refuse characters outside :data:`ISO_840`, naming the block (for a control that checks the tape code)."""
    for number, block in enumerate(program.blocks, start=1):
        bad = sorted(set(block) - ISO_840)
        if bad:
            raise InputError(f"{program.source}: block {number} holds {''.join(bad)!r}, outside the ISO 840 tape "
                             "code the control checks (lower case, for one); change the program or drop --iso-check")


def tv_padded(text: str, eol: str) -> str:
    """``text`` with a space added where the block and its end of block would hold an odd number of characters.

    Examples
    --------
    >>> tv_padded("G0 X1.", "\\n"), tv_padded("G0 X10.", "\\n")
    ('G0 X1. ', 'G0 X10.')
    """
    return text + " " if (len(text) + len(eol)) % 2 else text
