"""The blocks a dialect's parser turns program text into, one frozen dataclass per kind of statement.

Expressions inside a block are :class:`~lagsym.simulate.expressions.Expr`
values: a tree the compiler turns into code, callable as ``f(control) ->
Decimal``; a variable target is one of a reference tree, ``f(control) -> int``.  Indices of partner blocks (a loop's end, an if's
next branch) are filled in by the executor when it links the program; until
then they are ``-1``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from decimal import Decimal
from typing import ClassVar

__all__ = ["Block", "Nop", "Stop", "Assign", "AssignNamed", "Words", "While", "End", "IfThen", "Goto",
           "IfGoto", "Label", "IfGotoLabel", "OWhile", "OEndWhile", "OIf", "OElseIf", "OElse", "OEndIf", "Output",
           "PROBE_CODES", "probe_code"]

PROBE_CODES = (31.0, 38.2)
"""The probing moves the simulator runs against a given surface: Fanuc/Haas ``G31`` and LinuxCNC ``G38.2``."""

Expr = Callable[..., Decimal]
Ref = Callable[..., int]


@dataclass(frozen=True)
class Block:
    """Where a block came from: its ``line`` (1-based), its ``text``, and its Fanuc ``N`` number if any."""

    line: int
    text: str
    sequence: int | None = field(default=None, kw_only=True)


@dataclass(frozen=True)
class Nop(Block):
    """A block that does nothing when run (an ``O`` number, a bare ``N10``); kept only as a jump target."""


@dataclass(frozen=True)
class Stop(Block):
    """The end of the program (Heidenhain ``END PGM``)."""


@dataclass(frozen=True)
class Assign(Block):
    """``#n = expr`` (``Qn`` for Heidenhain): ``target`` gives the variable number."""

    target: Ref
    value: Expr


@dataclass(frozen=True)
class AssignNamed(Block):
    """LinuxCNC ``#<name> = expr``; ``name`` is lower case, as LinuxCNC compares names."""

    name: str
    value: Expr


@dataclass(frozen=True)
class Words(Block):
    """Address words (``G1 X#1 Y2. F100.``): ``(letter, value)`` pairs in block order."""

    words: tuple[tuple[str, Expr], ...]


@dataclass(frozen=True)
class While(Block):
    """Fanuc ``WHILE [cond] DOm`` (``cond`` None for a bare ``DOm``, which loops for ever)."""

    cond: Expr | None
    loop: int
    end: int = -1


@dataclass(frozen=True)
class End(Block):
    """Fanuc ``ENDm``: back to its ``DOm``."""

    loop: int
    start: int = -1


@dataclass(frozen=True)
class IfThen(Block):
    """Fanuc ``IF [cond] THEN #n = expr``."""

    cond: Expr
    then: Assign


@dataclass(frozen=True)
class Goto(Block):
    """Fanuc ``GOTO n``, with the sequence number computed when the block runs."""

    number: Expr


@dataclass(frozen=True)
class IfGoto(Block):
    """Fanuc ``IF [cond] GOTO n``."""

    cond: Expr
    number: Expr


@dataclass(frozen=True)
class Label(Block):
    """Heidenhain ``LBL n``: a jump target."""

    number: int


@dataclass(frozen=True)
class IfGotoLabel(Block):
    """Heidenhain ``FN 9..12: IF .. GOTO LBL n``; ``cond`` returns a truth value."""

    cond: Callable[..., bool]
    label: int


@dataclass(frozen=True)
class OWhile(Block):
    """LinuxCNC ``o<oword> while [cond]``."""

    KEYWORD: ClassVar[str] = "while"
    oword: str
    cond: Expr
    end: int = -1


@dataclass(frozen=True)
class OEndWhile(Block):
    """LinuxCNC ``o<oword> endwhile``: back to its ``while``."""

    KEYWORD: ClassVar[str] = "endwhile"
    oword: str
    start: int = -1


@dataclass(frozen=True)
class OIf(Block):
    """LinuxCNC ``o<oword> if [cond]``: ``next`` is the following branch, ``endif`` the chain's end."""

    KEYWORD: ClassVar[str] = "if"
    oword: str
    cond: Expr
    next: int = -1
    endif: int = -1


@dataclass(frozen=True)
class OElseIf(Block):
    """LinuxCNC ``o<oword> elseif [cond]``."""

    KEYWORD: ClassVar[str] = "elseif"
    oword: str
    cond: Expr
    next: int = -1
    endif: int = -1


@dataclass(frozen=True)
class OElse(Block):
    """LinuxCNC ``o<oword> else``."""

    KEYWORD: ClassVar[str] = "else"
    oword: str
    endif: int = -1


@dataclass(frozen=True)
class OEndIf(Block):
    """LinuxCNC ``o<oword> endif``."""

    KEYWORD: ClassVar[str] = "endif"
    oword: str


@dataclass(frozen=True)
class Output(Block):
    """Text the program sends out: Fanuc ``POPEN``, ``DPRNT[..]``, ``PCLOS``; LinuxCNC ``(LOGOPEN,..)``,
    ``(LOG,..)``, ``(LOGCLOSE)``.

    ``action`` is ``open``, ``print`` or ``close``; ``items`` the parts of a
    printed line in order: ``("text", s)``, ``("var", n, digits, decimals)``
    (a Fanuc ``#n[ab]``) or ``("param", n)`` (a LinuxCNC ``#n``, printed as
    ``%f``); ``name`` the file a LinuxCNC log opens.
    """

    action: str
    items: tuple = ()
    name: str = ""


def probe_code(b: Block) -> float | None:
    """The probing move (:data:`PROBE_CODES`) a block of words makes, or None."""
    if not isinstance(b, Words):
        return None
    for letter, e in b.words:
        node = getattr(e, "node", None)
        if letter == "G" and node is not None and node[0] in ("num", "dec"):
            code = round(float(node[1]), 1)
            if code in PROBE_CODES:
                return code
    return None
