"""The one G-code word tokenizer: comments out, a block split into ``(letter, value)`` words.

A block of word-address G-code is a run of words, each an address letter and
its value: ``G1 X12.5 Y-3. F200.``.  Three readers in lagsym take blocks
apart this way, and all of them do it here:

* the point-list reader (:func:`lagsym.gcode.parse_moves`) and the resume
  of a transfer (modal tracking) need numbers only, and use
  :func:`numeric_words`;
* the macro simulator (:mod:`lagsym.simulate`) also meets values that are
  variables (``#112``, ``#<x>``), bracketed expressions (``[#1+2.]``) and
  functions (``SQRT[..]``), and uses :func:`words`.

Values stay text, so a caller reads them exactly (``Decimal(value)``) or
quickly (``float(value)``) as it needs.  Letters come back upper case.
"""

from __future__ import annotations

import re

__all__ = ["WordError", "FUNCTIONS", "strip_comments", "numeric_words", "plain_move", "words"]

FUNCTIONS = ("SQRT", "ABS", "FIX", "FUP", "ROUND", "SIN", "COS", "TAN", "ATAN", "ASIN", "ACOS", "EXP", "LN")

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)"
_NUMERIC_WORD = re.compile(r"([A-Za-z])\s*(" + _NUMBER + ")")
# Alternatives in one pattern, so whichever comment starts first wins: "; note (x" is one comment, and
# "(a;b)" another.  A comment holds no "(": LinuxCNC refuses a comment inside a comment, so "(a (b) c)" is
# not taken for "(a (b)" and a stray " c)", but left with its unmatched "(" for a strict reader to refuse.
_COMMENTS = re.compile(r"\([^()]*\)|;.*")
_PARENTHESES = re.compile(r"\([^()]*\)")
_NESTED = re.compile(r"\([^)]*\(")
# The block a point list is made of, in one piece: an optional G0/G1, then X, Y, Z, F each at most once, in order.
_PLAIN_MOVE = re.compile(r"(?:G0?([01])(?![0-9.])\s*)?(?:X(" + _NUMBER + r")\s*)?(?:Y(" + _NUMBER + r")\s*)?"
                         r"(?:Z(" + _NUMBER + r")\s*)?(?:F(" + _NUMBER + r")\s*)?")
_FUNCTION_NAME = re.compile(r"(?i)(" + "|".join(FUNCTIONS) + r")(?=\s*\[)")


class WordError(ValueError):
    """A block the tokenizer cannot split into words; the message says what it could not read."""


def strip_comments(block: str, *, semicolon: bool = True) -> str:
    """``block`` with each ``(...)`` comment, and with ``semicolon`` a ``;`` to the end, made a space.

    This is the one definition of a comment in lagsym: every reader of
    G-code (the point-list reader, the simulator, the DNC sender's checks,
    the resume, verify's resolution and units) takes comments out here.
    Whichever comment starts first wins (``(a;b)`` is one comment, and so is
    ``; note (x``); a comment ends at the first ``)`` and separates the words
    on either side of it, as in LinuxCNC's interpreter.  An unclosed ``(``,
    and a comment inside a comment (which LinuxCNC refuses), are left in the
    text with their ``(`` for the reader to refuse.

    Parameters
    ----------
    block : str
        One block (one line) of a program.
    semicolon : bool
        Whether ``;`` starts a comment to the end of the line (LinuxCNC, and a
        point-list reader); a Fanuc reads ``;`` as the end of block instead.

    Examples
    --------
    >>> strip_comments("G1 X1. (FEED) Y2. ; to the corner")
    'G1 X1.   Y2.  '
    >>> strip_comments("#1=2. ; not a comment here", semicolon=False)
    '#1=2. ; not a comment here'
    >>> strip_comments("G1 (a (b) c) X1.")
    'G1 (a   c) X1.'
    """
    if "(" not in block and (not semicolon or ";" not in block):
        return block
    return (_COMMENTS if semicolon else _PARENTHESES).sub(" ", block)


def numeric_words(block: str, *, semicolon: bool = True, strict: bool = True) -> list[tuple[str, str]]:
    """The words of a block whose values are all plain numbers, comments taken out first.

    Parameters
    ----------
    block : str
        One block of a program, comments included.
    semicolon : bool
        Whether ``;`` starts a comment (see :func:`strip_comments`).
    strict : bool
        Refuse anything in the block that is not a numeric word (a variable,
        an expression, a stray character, an unclosed comment).  With
        ``strict=False`` such text is passed over and only the numeric words
        are returned, as a reader of modal state that has refused macro
        blocks by other means may want.

    Returns
    -------
    list of (str, str)
        ``(letter, value)`` pairs in block order; letters upper case, values
        as written (``"-.5"``, ``"+1"``, ``"12."``).

    Raises
    ------
    WordError
        With ``strict``, for an unclosed comment, a comment inside a comment,
        or text that is not a word.

    Examples
    --------
    >>> numeric_words("n10 g1 x-.5 Y 2. (DOWN) F200.")
    [('N', '10'), ('G', '1'), ('X', '-.5'), ('Y', '2.'), ('F', '200.')]
    >>> numeric_words("G1 X#1")
    Traceback (most recent call last):
    ...
    lagsym.gcode.words.WordError: cannot read 'X#1'
    >>> numeric_words("G1 X#1", strict=False)
    [('G', '1')]
    """
    text = strip_comments(block, semicolon=semicolon)
    found = _NUMERIC_WORD.findall(text)
    if strict:
        if "(" in text:
            raise WordError("a comment inside a comment" if _NESTED.search(block) else "unclosed comment")
        rest = _NUMERIC_WORD.sub("", text).strip()
        if rest:
            raise WordError(f"cannot read {rest!r}")
    if not text.isupper():  # some letter is lower case (most programs have none: skip the copy)
        found = [(letter.upper(), value) for letter, value in found]
    return found


def plain_move(block: str) -> tuple[str | None, ...] | None:
    """The words of the commonest point-list block in one step, or None for any other block.

    A block of nothing but ``G0``/``G00``/``G1``/``G01``, ``X``, ``Y``, ``Z``
    and ``F`` words, upper case, each at most once and in that order, no
    comment (``X84.195 Z20.524``, ``G01 Z17.214 F200.0``), comes back as
    ``(g, x, y, z, f)``, the values as written and None for a word not given:
    the same words :func:`numeric_words` finds in it.  Anything else is None,
    for the caller to read with :func:`numeric_words`.

    Examples
    --------
    >>> plain_move("G01 Z17.214 F200.0"), plain_move("X84.195 Z20.524")
    (('1', None, None, '17.214', '200.0'), (None, '84.195', None, '20.524', None))
    >>> plain_move("Y1. X2."), plain_move("G1.5 X1."), plain_move("x1.")
    (None, None, None)
    """
    m = _PLAIN_MOVE.fullmatch(block)
    return None if m is None or not block else m.groups()


def words(block: str) -> list[tuple[str, str]]:
    """Split a comment-free block into words whose values may be numbers, variables or expressions.

    A value runs to the next address letter or space outside brackets:
    ``#112``, ``#<name>``, ``-#3``, ``[#1+2.]`` and ``SQRT[..]`` each stay
    whole (a function name is part of the value, not the next address).
    Values are not checked: an empty value (``X`` alone) comes back as ``""``
    for the caller to refuse.

    Raises
    ------
    WordError
        For a character that cannot start a word, or ``#<`` without its ``>``.

    Examples
    --------
    >>> words("G1 X#112 Y[#1 + 2.] Z-1.5 F#<feed>")
    [('G', '1'), ('X', '#112'), ('Y', '[#1 + 2.]'), ('Z', '-1.5'), ('F', '#<feed>')]
    >>> words("X SQRT[#1]")
    [('X', 'SQRT[#1]')]
    """
    out, i, s = [], 0, block
    while i < len(s):
        if s[i].isspace():
            i += 1
            continue
        letter = s[i].upper()
        if not letter.isalpha():
            raise WordError(f"cannot read {s[i:i + 10]!r}")
        i += 1
        while i < len(s) and s[i].isspace():
            i += 1
        start, depth = i, 0
        while i < len(s):
            ch = s[i]
            fn = _FUNCTION_NAME.match(s, i) if depth == 0 and s[start:i].strip() in ("", "-", "+") else None
            if fn:
                i = fn.end()
                continue
            if s.startswith("#<", i):
                close = s.find(">", i)
                if close < 0:
                    raise WordError("a '#<' without its '>'")
                i = close + 1
                continue
            if ch == "[":
                depth += 1
            elif ch == "]":
                depth -= 1
            elif depth == 0 and (ch.isspace() or ch.isalpha()):
                break
            i += 1
        out.append((letter, s[start:i]))
    return out
