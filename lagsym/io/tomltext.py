"""TOML text checked before :mod:`tomllib` reads it: no dotted key or table header nested past a small depth.

The standard library's reader takes time and memory that grow with the
square of a dotted key's depth: ``a.a.a.… = 1`` 20,000 levels deep takes
seconds and gigabytes, 100,000 levels more than half a minute and 5 GB.  No
job file or DNC configuration nests more than a few levels, so a key or a
header deeper than :data:`MAX_TOML_DEPTH` is refused, with its line, before
the reader starts.  Arrays and inline tables nested too deep are refused by
the callers when the reader runs out of recursion.
"""

from __future__ import annotations

import re

from ..errors import InputError

__all__ = ["MAX_TOML_DEPTH", "check_toml_depth"]

MAX_TOML_DEPTH = 32  # levels of one dotted key or table header ([a.b.c] is 3)

# Strings and comments, whose dots are no key's: multi-line strings first (a closing quote may be followed by one
# or two more of the string's own), then one-line strings, then comments.
_NOT_KEYS = re.compile(r'"""(?:[^"\\]++|\\[\s\S]|"(?!""(?!")))*+"""|\'\'\'[\s\S]*?\'\'\'(?!\')'
                       r'|"[^"\\\n]*+(?:\\.[^"\\\n]*+)*+"|\'[^\'\n]*+\'|#[^\n]*+')
_DOT = re.compile(r"[ \t]*+\.[ \t]*+")  # the dot between two parts of a key, with the spaces it may have around it
# A key (after _DOT): bare parts and quoted ones (replaced by \x00) joined by dots; one of more than
# MAX_TOML_DEPTH parts, sought only where a key starts, so that each is walked once.
_DEEP = re.compile(rf"(?<![A-Za-z0-9_\-\x00.])(?:[A-Za-z0-9_\-\x00]*+\.){{{MAX_TOML_DEPTH}}}")


def _placeholder(m: re.Match) -> str:
    token = m.group()
    return "" if token.startswith("#") else "\x00" + "\n" * token.count("\n")  # lines kept, to name the line


def check_toml_depth(text: str, source: str, what: str) -> None:
    """Refuse TOML ``text`` (of the file ``source``, ``what`` it should be) holding a dotted key or table header
    more than :data:`MAX_TOML_DEPTH` levels deep, naming its line.

    >>> check_toml_depth("[port.line]\\nbaud = 9600\\n", "dnc.toml", "a configuration")
    >>> check_toml_depth(".".join(["a"] * 40) + " = 1", "job.toml", "a job file")
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: job.toml: line 1: not a job file: a dotted key or table header 40 levels deep (a.a.a...), more than 32
    """
    if text.count(".") < MAX_TOML_DEPTH:
        return
    bare = _DOT.sub(".", _NOT_KEYS.sub(_placeholder, text))
    if (m := _DEEP.search(bare)) is None:
        return
    key = re.match(r"[A-Za-z0-9_\-\x00.]*", bare[m.start():]).group()
    line, head = bare.count("\n", 0, m.start()) + 1, key[:5].replace("\x00", '"…"')
    raise InputError(f"{source}: line {line}: not {what}: a dotted key or table header {key.count('.') + 1} levels "
                     f"deep ({head}...), more than {MAX_TOML_DEPTH}")
