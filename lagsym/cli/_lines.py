"""Messages as one printable line: every error, warning and note on standard error goes through here.

A file name may hold a newline or another control character, and a field
of a file may be very long; neither may break a message into several lines
or flood the terminal.
"""

from __future__ import annotations

from typing import IO

__all__ = ["MAX_MESSAGE", "one_line", "say"]

MAX_MESSAGE = 2_000  # characters of one message: a longer one (a path near the system's limit) is cut in the middle


def one_line(message: str) -> str:
    """``message`` as one printable line: a newline or other control character in a name is escaped, a long one cut.

    Examples
    --------
    >>> one_line("bad\\nname.csv: no such file")
    'bad\\\\nname.csv: no such file'
    """
    text = message if message.isprintable() else "".join(
        c if c.isprintable() else repr(c)[1:-1] for c in message)
    if len(text) <= MAX_MESSAGE:
        return text
    half = MAX_MESSAGE // 2  # the head names the value, the tail says what is wrong with it
    return f"{text[:half]}...[{len(text) - 2 * half:,} characters]...{text[-half:]}"


def say(stream: IO[str], message: str) -> None:
    """Write ``message`` on ``stream`` as one line (:func:`one_line`): a note or warning that names a file.

    Examples
    --------
    >>> import io
    >>> s = io.StringIO(); say(s, "semi\\ncolon.csv: read as semicolon-separated"); s.getvalue()
    'semi\\\\ncolon.csv: read as semicolon-separated\\n'
    """
    stream.write(one_line(message) + "\n")
