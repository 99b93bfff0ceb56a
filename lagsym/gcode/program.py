"""A whole program read block by block: the lines a control reads, its units, and what in it is a macro.

Every reader of a whole program in lagsym asks its questions here, on top of
the one word tokenizer (:mod:`lagsym.gcode.words`), so they read a program
alike:

* :func:`program_blocks`: the lines a control reads, up to the closing ``%``;
* :func:`program_units`: ``G20`` or ``G21``, read as words (``G90G20`` too);
* :func:`macro_uses` and :func:`is_macro`: what in a block or a program is
  more than plain words (variables, expressions, loops, jumps, conditions,
  subprogram calls and returns), with comments taken out first, so a ``#``
  in ``(TOOL #2)`` is text and ``M98P100`` a call;
* :func:`first_line_with`: the first block that gives a word, whatever its
  value (a number, a variable or an expression);
* :func:`unrun_code`: why a ``G`` or ``M`` word moves the tool in a way a
  reader of straight moves does not follow (a subprogram call, a return, a
  canned cycle, a reference return, a shift of the coordinates), so every
  reader refuses the same words.
"""

from __future__ import annotations

import re

from ..errors import ProgramError
from ..values import choice
from .words import WordError, numeric_words, strip_comments, words

__all__ = ["ascii_program", "MACRO_USES", "PASSED_G", "PLAIN_M", "END_M", "unrun_code", "program_blocks", "program_units", "macro_uses", "is_macro", "first_line_with"]

MACRO_USES = ("variable", "expression", "loop", "jump", "condition", "call", "return")
"""What :func:`macro_uses` names: ``#`` variables; ``[..]`` expressions; loops (``WHILE .. DO``, ``END``,
``o.. while``, ``do``, ``repeat``); jumps (``GOTO``); conditions (``IF``, ``THEN``, ``o.. if``, ``else``);
subprogram calls (``M98``, ``G65``, ``G66``, ``o.. call``); returns and subprogram bodies (``M99``,
``o.. sub``, ``endsub``, ``return``)."""

_O_WORDS = {"while": "loop", "do": "loop", "endwhile": "loop", "repeat": "loop", "endrepeat": "loop",
            "break": "loop", "continue": "loop", "if": "condition", "elseif": "condition", "else": "condition",
            "endif": "condition", "call": "call", "sub": "return", "endsub": "return", "return": "return"}
_O_WORD = re.compile(r"O\s*(?:\d+|<[^>]*>)\s*([A-Z]+)")
_KEYWORDS = {"WHILE": "loop", "DO": "loop", "END": "loop", "GOTO": "jump", "IF": "condition", "THEN": "condition"}
# Keywords are runs of letters (a word is one letter and a number); DO and END count with their loop number, so
# Heidenhain's END PGM is not a loop.
_KEYWORD = re.compile(r"(?<![A-Z])(?:(WHILE|GOTO|IF|THEN)(?![A-Z])|(DO|END)\s*\d)")
_NAMED = re.compile(r"#<[^>]*>")
_N_NUMBER = re.compile(r"N\s*\d+\s*")
_CALLS = {("G", 65.0): "call", ("G", 66.0): "call", ("G", 66.1): "call", ("M", 98.0): "call", ("M", 99.0): "return"}
PASSED_G = frozenset({17.0, 18.0, 19.0, 20.0, 21.0, 40.0, 43.0, 49.0, 54.0, 55.0, 56.0, 57.0, 58.0, 59.0, 59.1,
                      59.2, 59.3, 61.0, 64.0, 80.0, 90.0, 91.0, 91.1, 94.0, 97.0})
"""``G`` codes that set a mode without moving the tool or changing where a later move goes: plane, units,
cutter-compensation and canned-cycle cancel, tool length offset (the program gives tool-tip positions),
work offsets, path control, absolute and incremental, feed per minute, spindle speed mode.  With ``G00`` to
``G03`` they are all a reader of straight moves needs; any other ``G`` code is refused (:func:`unrun_code`)."""
PLAIN_M = frozenset({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 30})
"""``M`` codes that move no axis: stops, program end, spindle, tool change (the program's next moves say where
the tool goes), coolant.  Any other ``M`` code may call a subprogram or a macro (``M98``, ``M97``, ``M198``,
or one a machine builder maps to a program) and is refused (:func:`unrun_code`)."""
END_M = frozenset({2, 30})
"""The ``M`` codes that end a program: a control runs nothing after them."""
_UNRUN = {("M", 98.0): "calls a subprogram", ("M", 97.0): "calls a subprogram", ("M", 198.0): "calls a subprogram",
          ("M", 99.0): "returns from a subprogram (in a main program: jumps back)",
          ("G", 65.0): "calls a macro", ("G", 66.0): "calls a macro at every move", ("G", 66.1): "calls a macro",
          ("G", 90.1): "gives arc centres as absolute positions", ("G", 4.0): "dwells (its X or P is a time, not a position)", ("G", 28.0): "moves through the reference point",
          ("G", 30.0): "moves through a reference point", ("G", 53.0): "moves in machine coordinates",
          ("G", 10.0): "sets offsets", ("G", 52.0): "shifts the coordinates", ("G", 92.0): "shifts the coordinates",
          ("G", 68.0): "rotates the coordinates", ("G", 51.0): "scales the coordinates",
          ("G", 51.1): "mirrors the coordinates", ("G", 16.0): "reads polar coordinates",
          ("G", 41.0): "offsets the path (cutter compensation)", ("G", 42.0): "offsets the path (cutter compensation)"}
_CYCLES = frozenset({73.0, 74.0, 76.0, *(float(g) for g in range(81, 90))})


def unrun_code(letter: str, value: float) -> str | None:
    """What a ``G`` or ``M`` word does that a reader of straight moves does not follow; None when it may pass.

    ``G00`` to ``G03`` (read by the reader itself), :data:`PASSED_G` and
    :data:`PLAIN_M` pass; every other ``G`` or ``M`` code is named here, with
    what it does where it is a known one, so the point-list reader and the
    simulator refuse the same words rather than skip a call, a cycle or a
    shift and report a path the machine would not take.

    Examples
    --------
    >>> unrun_code("M", 98), unrun_code("G", 81), unrun_code("M", 3), unrun_code("G", 43)
    ('calls a subprogram', 'is a canned cycle', None, None)
    >>> unrun_code("M", 47)
    'may call a subprogram or move the tool (a code of the machine builder)'
    """
    v = round(float(value), 1)
    if letter == "G":
        if v in (0.0, 1.0, 2.0, 3.0) or v in PASSED_G:
            return None
        if v in _CYCLES:
            return "is a canned cycle"
        return _UNRUN.get(("G", v), "moves the tool or changes where it goes in a way not read here")
    if letter == "M":
        if v in PLAIN_M:
            return None
        return _UNRUN.get(("M", v), "may call a subprogram or move the tool (a code of the machine builder)")
    return None


_EOL = "\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"  # where str.splitlines ends a line
_LINE_END = re.compile(f"[{_EOL}]")
_SPACE = f"[^\\S{_EOL}]*"  # space within a line, as numeric_words allows between a letter and its number
# Every block macro_uses finds something in matches this (most blocks of a point list do not), so it is a quick
# first look: "#", "[", the O of an o-word, GOTO and DO, the W of WHILE, the I of IF, the E of THEN and END, and
# M98, M99, G65, G66 (letter classes rather than re.I: several times faster on a block of plain words).
_HINT = re.compile(f"[#\\[OoWwIiEe]|[Mm]{_SPACE}\\+?0*9[89]|[Gg]{_SPACE}\\+?0*6[56]")
_UNITS_HINT = re.compile(f"[Gg]{_SPACE}\\+?0*2[01]")
_PERCENT = re.compile(f"(?:^|(?<=[{_EOL}]))[^\\S{_EOL}]*%")


def ascii_program(text, source: str = "<program>") -> str:
    """``text`` if it is a program's text in ASCII; else a ProgramError naming the line and the character.

    A control reads ASCII: a digit of another script (Arabic-Indic, full width), which Python's
    ``\\d`` and ``float`` would take as a digit, is refused rather than read as a number.
    """
    if not isinstance(text, str):
        raise ProgramError(f"{source}: {type(text).__name__} {text!r:.60} is not a program's text (a str)")
    if text.isascii():
        return text
    at = next(i for i, c in enumerate(text) if ord(c) > 127)
    line = text.count("\n", 0, at) + 1
    raise ProgramError(f"{source}, line {line}: character {text[at]!r} (U+{ord(text[at]):04X}) is not ASCII; "
                       f"a control reads ASCII programs")


def program_blocks(text: str):
    """``(line number, raw line, block)`` for each block a control reads, comments still in.

    Blank lines are passed over; a line starting with ``%`` is framing, and
    the second one ends the program (a control reads nothing after it).  A
    block-delete ``/`` is taken off and the block read (block delete off).
    Line numbers count from 1, over every line of ``text``.

    Examples
    --------
    >>> [(no, block) for no, _, block in program_blocks("%\\nO1 (A)\\n\\n/G0 X1.\\n%\\nG1 Z-9.\\n")]
    [(2, 'O1 (A)'), (4, 'G0 X1.')]
    """
    percent = 0
    for no, raw in enumerate(text.splitlines(), start=1):
        s = raw.strip()
        if not s:
            continue
        if s.startswith("%"):
            percent += 1
            if percent == 2:
                return  # the end of the program: anything after is not read by a control
            continue
        yield no, raw, s[1:] if s.startswith("/") else s


def program_units(text: str) -> str | None:
    """The units a program's coordinates are in: ``"inch"`` if any block selects ``G20``, ``"mm"`` for ``G21``.

    A program that selects both writes some of its coordinates in inches, the
    coarser unit, so it counts as inch.  None when it selects neither.
    Macro text is passed over (:func:`~lagsym.gcode.words.numeric_words`
    without ``strict``).

    Examples
    --------
    >>> program_units("G21 G90\\nG1 X1.\\n"), program_units("G90G20 (INCH)\\n"), program_units("G1 X1.\\n")
    ('mm', 'inch', None)
    """
    found = None
    for block in _blocks_hinted(text, _UNITS_HINT):
        for letter, value in numeric_words(block, strict=False):
            if letter == "G" and round(float(value), 1) in (20.0, 21.0):
                if round(float(value), 1) == 20.0:
                    return "inch"
                found = "mm"
    return found


def macro_uses(block: str, *, semicolon: bool = True) -> frozenset[str]:
    """What one block uses beyond plain words, each named as in :data:`MACRO_USES`; empty for plain words.

    Comments are taken out first (:func:`~lagsym.gcode.words.strip_comments`,
    ``semicolon`` as there), letters read in either case, and calls read as
    words, so ``N10M98P100`` is a call and ``T2 M06 (TOOL #2)`` is plain.

    Examples
    --------
    >>> sorted(macro_uses("WHILE [#1 LT 10.] DO1")), sorted(macro_uses("o100 if [#<n> GT 2]"))
    (['expression', 'loop', 'variable'], ['condition', 'expression', 'variable'])
    >>> sorted(macro_uses("GOTO10")), sorted(macro_uses("N10M98P100")), macro_uses("O1000 (DEMO #1)")
    (['jump'], ['call'], frozenset())
    """
    if not _HINT.search(block):
        return frozenset()
    t = strip_comments(block, semicolon=semicolon).strip().upper()
    found = set()
    if "#" in t:
        found.add("variable")
    if "[" in t:
        found.add("expression")
    head = _N_NUMBER.match(t)
    o_word = _O_WORD.match(t, head.end() if head else 0)
    if o_word and o_word.group(1).lower() in _O_WORDS:
        found.add(_O_WORDS[o_word.group(1).lower()])
    for m in _KEYWORD.finditer(_NAMED.sub("#", t)):
        found.add(_KEYWORDS[m.group(1) or m.group(2)])
    for letter, value in numeric_words(t, strict=False):
        if letter in "GM":
            use = _CALLS.get((letter, round(float(value), 1)))
            if use:
                found.add(use)
    return frozenset(found)


def is_macro(text: str, uses=MACRO_USES, *, semicolon: bool = True) -> bool:
    """Whether a block, or any block of a program, uses any of ``uses`` (:func:`macro_uses`).

    Parameters
    ----------
    text : str
        One block or a whole program (read as :func:`program_blocks` does).
    uses : sequence of str
        Which uses count, from :data:`MACRO_USES` (all by default).
    semicolon : bool
        Whether ``;`` starts a comment (see :func:`~lagsym.gcode.words.strip_comments`).

    Examples
    --------
    >>> is_macro("O1000 (DEMO)\\nG1 X1. Z#1\\n"), is_macro("O1000 (DEMO)\\nT2 M06 (TOOL #2)\\n")
    (True, False)
    >>> is_macro("G65 P9010 A1.", uses=("loop", "jump")), is_macro("M99", uses=("loop", "jump", "return"))
    (False, True)
    """
    wanted = frozenset(choice(u, MACRO_USES, "macro use") for u in uses)
    return any(wanted & macro_uses(block, semicolon=semicolon) for block in _blocks_hinted(text, _HINT))


def first_line_with(text: str, letter: str) -> int | None:
    """The line of the first block that gives a ``letter`` word, whatever its value; None if none does.

    Macro statements (assignments, loops, jumps, conditions: their letters
    are names, not words) are passed over; a value may be a number, a
    variable or an expression (``Z#105``, ``Z[#1-2.]``).

    Examples
    --------
    >>> first_line_with("(STOCK TOP Z73.5)\\n#1=2.\\nG0 X0 Y0\\nG1 Z#1\\n", "Z")
    4
    """
    letter = letter.upper()
    for no, _, block in program_blocks(text):
        t = strip_comments(block).strip()
        if letter not in t.upper() or _statement(t.upper()):
            continue
        try:
            found = words(t)
        except WordError:
            continue  # not words: no reader of the program takes it for a move
        if any(w == letter for w, _ in found):
            return no
    return None


def _blocks_hinted(text: str, hint: re.Pattern):
    """The blocks of :func:`program_blocks` on the lines where ``hint`` matches, found by one search of the text.

    A long point list has few such lines (for most questions, its comments), so most lines are never split off.
    """
    frame = [m.end() - 1 for m in _PERCENT.finditer(text)][:2]
    end = frame[1] if len(frame) == 2 else len(text)
    pos = 0
    while True:
        found = hint.search(text, pos, end)
        if found is None:
            return
        start = max(text.rfind(c, 0, found.start()) for c in _EOL) + 1
        line_end = _LINE_END.search(text, found.end(), end)
        stop = end if line_end is None else line_end.start()
        block = text[start:stop].strip()
        if block and not block.startswith("%"):
            yield block[1:] if block.startswith("/") else block
        pos = stop + 1


def _statement(t: str) -> bool:
    """Whether an upper-case, comment-free block is a macro statement rather than words."""
    head = _N_NUMBER.match(t)
    t = t[head.end():] if head else t
    o_word = _O_WORD.match(t)
    return t.startswith("#") or bool(o_word and o_word.group(1).lower() in _O_WORDS) or bool(_KEYWORD.match(t))
