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

__all__ = ["Program", "parse_program", "frame", "DC1", "DC2", "DC3", "DC4"]

DC1, DC2, DC3, DC4 = 0x11, 0x12, 0x13, 0x14
_CONTROL_CODES = {DC1: "DC1", DC2: "DC2", DC3: "DC3", DC4: "DC4"}


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
