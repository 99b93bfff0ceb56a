"""Reading the bytes of an input: only a regular file or standard input, always within a size limit.

A device or a named pipe could hand over endless bytes or none, so it is
refused with a line that says what it is; standard input (``-``) that stays
silent is refused after :data:`STDIN_SILENCE_S`.  Programs are read as a
control reads them: ASCII, line endings kept.
"""

from __future__ import annotations

import contextlib
import contextvars
import errno
import os
import stat
import time
from collections.abc import Iterator

from ..errors import InputError

__all__ = ["MAX_BYTES", "MAX_FILE_POINTS", "STDIN_NAMES", "STDIN_SILENCE_S", "display_name", "path_problem", "read_bytes",
           "read_text", "read_program", "event_log", "EventLog", "file_points_limit", "estimate_points",
           "check_point_count"]

MAX_BYTES = 64 * 1024 * 1024
# Points of one points file (--max-file-points): reading takes about 0.1 ms and 1 kB a point, so a million is
# minutes and a gigabyte, four times the largest grid 'lagsym piecewise' takes and far beyond any fit's data.
MAX_FILE_POINTS = 1_000_000
_POINTS_LIMIT: contextvars.ContextVar[int | None] = contextvars.ContextVar("file_points_limit", default=MAX_FILE_POINTS)

_KINDS = ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a pipe (FIFO)"),
          (stat.S_ISSOCK, "a socket"))
STDIN_NAMES = ("-", "/dev/stdin")
STDIN_SILENCE_S = 10.0  # standard input that sends nothing for this long is refused, not waited on forever


def display_name(path: str | os.PathLike) -> str:
    """``path`` as a message shows it: control characters (a newline, a tab) escaped, so a message stays one line."""
    name = str(path)
    return name if name.isprintable() else name.encode("unicode_escape", "backslashreplace").decode("ascii")


def path_problem(e: OSError) -> str | None:
    """What is wrong with a path itself, said the same for an input and an output; None for other errors."""
    if e.errno == errno.ELOOP:
        return "too many levels of symbolic links (a loop?)"
    if e.errno == errno.ENAMETOOLONG:
        return "the name or path is longer than the system allows"
    return None


def read_bytes(path: str | os.PathLike, what: str, limit: int = MAX_BYTES) -> bytes:
    """The bytes of ``path`` (``-``: standard input), at most ``limit``; every failure is one InputError naming it.

    Only a regular file or standard input is read: a device or a named pipe
    could hand over endless bytes or none, so it is refused with a line that
    says what it is.
    """
    if str(path) in STDIN_NAMES:
        return _read_stdin(what, limit)
    if "\x00" in str(path):
        raise InputError(f"{str(path)!r}: a file name cannot hold a NUL character")
    name = display_name(path)
    try:
        fd = os.open(str(path), os.O_RDONLY | os.O_NONBLOCK)  # non-blocking: opening a FIFO must not hang
    except FileNotFoundError:
        raise InputError(f"{name}: no such file") from None
    except PermissionError:
        raise InputError(f"{name}: permission denied") from None
    except IsADirectoryError:
        raise InputError(f"{name}: is a directory, not {what}") from None
    except OSError as e:
        raise InputError(f"{name}: {path_problem(e) or f'cannot read ({e.strerror or e})'}") from None
    info = os.fstat(fd)
    refusal = f"{name}: is a directory, not {what}" if stat.S_ISDIR(info.st_mode) else next(
        (f"{name}: is {kind}, not {what}; give a regular file, or '-' for standard input"
         for test, kind in _KINDS if test(info.st_mode)), None)
    if refusal:
        os.close(fd)
        raise InputError(refusal)
    with os.fdopen(fd, "rb") as fh:
        try:
            if (size := info.st_size) > limit:
                raise InputError(f"{name}: {size} bytes is too large for {what} (at most {limit} bytes)")
            raw = fh.read(limit + 1)
        except OSError as e:
            raise InputError(f"{name}: cannot read ({e.strerror or e})") from None
    if len(raw) > limit:  # the file grew while it was read
        raise InputError(f"{name}: more than {limit} bytes is too large for {what}")
    return raw


def _read_stdin(what: str, limit: int) -> bytes:
    import select
    import sys

    stream = sys.stdin.buffer
    chunks, total = [], 0
    while True:
        ready, _, _ = select.select([stream], [], [], STDIN_SILENCE_S)
        if not ready:
            raise InputError(f"standard input: nothing arrived for {STDIN_SILENCE_S:g} s; "
                             f"pipe {what} in, or give a file name")
        chunk = os.read(stream.fileno(), 1 << 16)
        if not chunk:
            return b"".join(chunks)
        total += len(chunk)
        if total > limit:
            raise InputError(f"standard input: more than {limit} bytes is too large for {what}")
        chunks.append(chunk)


def read_text(path: str | os.PathLike) -> tuple[str, str]:
    """The text of a UTF-8 file and its name as messages show it (:func:`display_name`)."""
    name = display_name(path)
    raw = read_bytes(path, "a points file")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        hint = "" if b"\x00" in raw[:4096] else "; if it is text, save it as UTF-8 (Excel: 'CSV UTF-8')"
        raise InputError(f"{name}: not a text file (byte 0x{raw[e.start]:02x} at offset {e.start}){hint}") from None
    if "\x00" in text:
        raise InputError(f"{name}: not a text file (NUL byte at offset {text.index(chr(0))})")
    if not text.strip():
        raise InputError(f"{name}: the file is empty")
    return name, text


@contextlib.contextmanager
def file_points_limit(points: int | None):
    """Within the block, a points file estimated to hold more than ``points`` points is refused (None: no limit).

    Examples
    --------
    >>> with file_points_limit(5_000_000):
    ...     pass
    """
    token = _POINTS_LIMIT.set(None if points is None else int(points))
    try:
        yield
    finally:
        _POINTS_LIMIT.reset(token)


def estimate_points(text: str) -> int:
    """About how many points the text of a points file holds, counted without reading a number.

    A table holds a point a line.  JSON holds a point a list or object
    (``[x, y, z]``, ``{"x": ..}``), or, in an ``{"x": [..], "y": [..],
    "z": [[..]]}`` table, a height a value: the larger of the brackets and a
    third of the values (commas) counts either.

    >>> estimate_points("x,y,z\\n1,2,3\\n4,5,6\\n"), estimate_points("[[1, 2, 3], [4, 5, 6]]")
    (3, 3)
    """
    if text.lstrip()[:1] in ("[", "{"):
        return max(text.count("[") + text.count("{"), (text.count(",") + 1) // 3)
    return text.count("\n") or text.count("\r") or 1


def check_point_count(name: str, text: str, *, stated: int | None = None) -> None:
    """Refuse the points file ``name`` when :func:`estimate_points` says it holds more than the limit in force.

    ``stated`` is a count the file states of itself (a probing program's
    header), refused the same way before anything is made for it.
    """
    limit = _POINTS_LIMIT.get()
    count = estimate_points(text) if stated is None else stated
    if limit is not None and count > limit:
        said = f"{count:,} points stated" if stated is not None else f"about {count:,} points"
        raise InputError(f"{name}: {said}, more than the limit of {limit:,} points in one file "
                         f"(reading them would take minutes and gigabytes); thin the points, or raise the limit "
                         f"(--max-file-points, file_points_limit() in Python)")


def read_program(path: str | os.PathLike) -> str:
    """Read a part program as a control reads it: ASCII text, line endings kept as they are.

    Raises
    ------
    InputError
        For a missing or unreadable file, a directory, or a byte that is not ASCII.
    """
    name = display_name(path)
    raw = read_bytes(path, "a program")
    try:
        return raw.decode("ascii")
    except UnicodeDecodeError as e:
        raise InputError(f"{name}: byte 0x{raw[e.start]:02x} at offset {e.start} is not ASCII; "
                         f"a control reads ASCII programs") from None


class EventLog:
    """Appends a time-stamped line per event to an open log file.

    A write that fails (a full disk) is not raised in the middle of a
    transfer: the log stops, :attr:`lost` says why and after how many lines,
    and ``on_lost`` hears it once.  The command then reports the log as lost
    rather than the transfer as done.
    """

    def __init__(self, fh, path, on_lost=None):
        self.fh, self.path, self.on_lost = fh, path, on_lost
        self.lines = 0
        self.error: str | None = None  # why the first failed write failed
        self.lost: str | None = None  # that, and after how many lines

    def __call__(self, message: str) -> None:
        if self.lost is not None:
            return
        try:
            self.fh.write(f"{time.strftime('%Y-%m-%dT%H:%M:%S')} {message}\n")
            self.fh.flush()
        except OSError as e:
            self.error = str(e.strerror or e)
            self.lost = f"{self.error} after {self.lines} lines"
            if self.on_lost:
                self.on_lost(self.lost)
            return
        self.lines += 1


@contextlib.contextmanager
def event_log(path: str | os.PathLike | None, option: str = "--log", on_lost=None) -> Iterator:
    """An :class:`EventLog` on the file ``path``, opened for appending, or None without a path.

    The file is tried with a first line before anything starts, so a log
    that cannot be written (no permission, a full disk) is refused at once,
    with ``option`` and the path.
    """
    if not path:
        yield None
        return
    try:
        fh = open(path, "a", encoding="utf-8")
    except OSError as e:
        raise InputError(f"{option} {path}: cannot open the log file ({e.strerror or e})") from None
    try:
        log = EventLog(fh, path, on_lost)
        log("log opened")
        if log.lost is not None:
            raise InputError(f"{option} {path}: cannot write the log file ({log.error}); "
                             "nothing was started")
        yield log
    finally:
        try:
            fh.close()
        except OSError:
            pass  # every line was flushed as it was written; a failure is already in log.lost
