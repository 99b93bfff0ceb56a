"""Reading point files and writing results: every path lagsym touches passes here.

Numbers in input files are exact: the JSON number text ``1.06`` is 53/50, never
the nearest binary float, and strings may hold exact decimals or rationals
(``"1/3"``).  Writers are atomic: a file appears complete or not at all.
"""

from __future__ import annotations

import contextlib
import csv
import errno
import io
import json
import os
import re
import shutil
import stat
import tempfile
import time
from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path
from typing import IO, Any

from .errors import InputError, OutputError
from .grid import ControlGrid, CurvePoints, curve_from_points, grid_from_points, grid_from_table
from .values import MAX_EXPONENT, NotANumber, exact_number

__all__ = [
    "read_points",
    "read_curve_points",
    "read_any_points",
    "read_units",
    "read_program",
    "event_log",
    "parse_points",
    "exact_number",
    "atomic_path",
    "atomic_write",
    "write_text",
]

MAX_BYTES = 64 * 1024 * 1024


def _json_float(text: str) -> Fraction:
    try:
        return exact_number(text)
    except NotANumber as e:
        raise _JsonValueError(str(e)) from None


def _json_int(text: str) -> int:
    if len(text.lstrip("-")) > MAX_EXPONENT:
        raise _JsonValueError(f"{text[:20]}... is out of range (overflow)")
    return int(text)


def _json_constant(name: str):
    raise _JsonValueError(f"{name} is not a number lagsym can use")


class _JsonValueError(Exception):
    pass


def _value(v: Any, where: str) -> Fraction:
    if isinstance(v, bool):
        raise InputError(f"{where}: {json.dumps(v)} is a boolean, not a number")
    if isinstance(v, (int, Fraction)):
        return Fraction(v)
    if isinstance(v, str):
        try:
            return exact_number(v)
        except NotANumber as e:
            raise InputError(f"{where}: {e}") from None
    raise InputError(f"{where}: {_short(v)} is not a number")


def _short(v: Any) -> str:
    try:
        text = json.dumps(v, default=str)
    except (TypeError, ValueError, RecursionError):
        text = type(v).__name__
    return text if len(text) <= 40 else text[:37] + "..."


_KINDS = ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a pipe (FIFO)"),
          (stat.S_ISSOCK, "a socket"))
STDIN_NAMES = ("-", "/dev/stdin")
STDIN_SILENCE_S = 10.0  # standard input that sends nothing for this long is refused, not waited on forever


def _raw(path: str | os.PathLike, what: str, limit: int = MAX_BYTES) -> bytes:
    """The bytes of ``path`` (``-``: standard input), at most ``limit``; every failure is one InputError naming it.

    Only a regular file or standard input is read: a device or a named pipe
    could hand over endless bytes or none, so it is refused with a line that
    says what it is.
    """
    name = str(path)
    if name in STDIN_NAMES:
        return _read_stdin(what, limit)
    try:
        fd = os.open(name, os.O_RDONLY | os.O_NONBLOCK)  # non-blocking: opening a FIFO must not hang
    except FileNotFoundError:
        raise InputError(f"{name}: no such file") from None
    except PermissionError:
        raise InputError(f"{name}: permission denied") from None
    except IsADirectoryError:
        raise InputError(f"{name}: is a directory, not {what}") from None
    except OSError as e:
        raise InputError(f"{name}: cannot read ({e.strerror or e})") from None
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


def _read_bytes(path: str | os.PathLike) -> tuple[str, str]:
    name = str(path)
    raw = _raw(path, "a points file")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise InputError(f"{name}: not a text file (byte 0x{raw[e.start]:02x} at offset {e.start})") from None
    if "\x00" in text:
        raise InputError(f"{name}: not a text file (NUL byte at offset {text.index(chr(0))})")
    if not text.strip():
        raise InputError(f"{name}: the file is empty")
    return name, text


def _kind(name: str, text: str) -> str:
    suffix = Path(name).suffix.lower()
    if suffix in (".json", ".csv"):
        return suffix[1:]
    return "json" if text.lstrip()[:1] in "[{" else "csv"


def _load_json(name: str, text: str) -> Any:
    try:
        return json.loads(text, parse_float=_json_float, parse_int=_json_int, parse_constant=_json_constant)
    except _JsonValueError as e:
        raise InputError(f"{name}: {e}") from None
    except json.JSONDecodeError as e:
        raise InputError(f"{name}: not valid JSON: {e.msg} (line {e.lineno}, column {e.colno})") from None
    except RecursionError:
        raise InputError(f"{name}: the JSON is nested too deeply to be a points file") from None


def _point_list(name: str, data: Any, arity: int) -> list[tuple[Fraction, ...]]:
    if not isinstance(data, list):
        raise InputError(f"{name}: expected a list of points, found {_short(data)}")
    if not data:
        raise InputError(f"{name}: the list of points is empty")
    points = []
    want = "[x, y, z]" if arity == 3 else "[x, y]"
    for idx, p in enumerate(data):
        if not isinstance(p, list):
            raise InputError(f"{name}: point {idx + 1} is {_short(p)}, not a list {want}")
        if len(p) != arity:
            raise InputError(f"{name}: point {idx + 1} {_short(p)} has {len(p)} values, expected {want}")
        points.append(tuple(_value(v, f"{name}: point {idx + 1}") for v in p))
    return points


def _csv_rows(name: str, text: str, arity: int) -> list[tuple[Fraction, ...]]:
    columns = "xyz"[:arity]
    rows = list(csv.reader(io.StringIO(text)))
    order = list(range(arity))
    body: list[tuple[int, list[str]]] = []
    header_seen = False
    for lineno, row in enumerate(rows, start=1):
        cells = [c.strip() for c in row]
        if not any(cells) or cells[0].startswith("#"):
            continue
        if not header_seen and not body and all(c.lower() in "xyz" and c for c in cells):
            names = [c.lower() for c in cells]
            if sorted(names) != sorted(columns):
                raise InputError(f"{name}: line {lineno}: header {','.join(cells)} should name the columns {','.join(columns)}")
            order = [names.index(c) for c in columns]
            header_seen = True
            continue
        body.append((lineno, cells))
    if not body:
        raise InputError(f"{name}: no points in the file")
    points = []
    for lineno, cells in body:
        if len(cells) != arity:
            raise InputError(f"{name}: line {lineno} has {len(cells)} columns, expected {','.join(columns)}")
        values = []
        for c in (cells[j] for j in order):
            try:
                values.append(exact_number(c))
            except NotANumber as e:
                raise InputError(f"{name}: line {lineno}: {e}") from None
        points.append(tuple(values))
    return points


def parse_points(text: str, source: str = "<points>", kind: str = "json") -> ControlGrid:
    """Read surface control points from JSON or CSV text.

    Examples
    --------
    >>> parse_points('[[1, 2, 7], [1, 3, 10], [3, 2, 15], [3, 3, 18.5]]').z[1][1]
    Fraction(37, 2)
    """
    if kind == "csv":
        return grid_from_points(_csv_rows(source, text, 3), source=source)
    data = _load_json(source, text)
    if isinstance(data, dict):
        if "points" in data:
            return grid_from_points(_point_list(source, data["points"], 3), source=source)
        if {"x", "y", "z"} <= data.keys():
            return _grid_table(source, data)
        raise InputError(f"{source}: expected a \"points\" list or \"x\", \"y\", \"z\" keys, found keys {sorted(data)}")
    return grid_from_points(_point_list(source, data, 3), source=source)


def _grid_table(name: str, data: dict) -> ControlGrid:
    for key in ("x", "y", "z"):
        if not isinstance(data[key], list) or not data[key]:
            raise InputError(f"{name}: \"{key}\" should be a non-empty list, found {_short(data[key])}")
    xs = [_value(v, f"{name}: x[{i}]") for i, v in enumerate(data["x"])]
    ys = [_value(v, f"{name}: y[{k}]") for k, v in enumerate(data["y"])]
    z = []
    for i, row in enumerate(data["z"]):
        if not isinstance(row, list):
            raise InputError(f"{name}: z[{i}] is {_short(row)}, not a list of heights")
        z.append([_value(v, f"{name}: z[{i}][{k}]") for k, v in enumerate(row)])
    return grid_from_table(xs, ys, z, source=name)


def parse_curve_points(text: str, source: str = "<points>", kind: str = "json") -> CurvePoints:
    """Read 1-D curve points ``(x, y)`` from JSON or CSV text."""
    if kind == "csv":
        return curve_from_points(_csv_rows(source, text, 2), source=source)
    data = _load_json(source, text)
    if isinstance(data, dict):
        if "points" in data:
            data = data["points"]
        elif {"x", "y"} <= data.keys() and "z" not in data:
            xs, ys = data["x"], data["y"]
            if not isinstance(xs, list) or not isinstance(ys, list) or len(xs) != len(ys):
                raise InputError(f"{source}: \"x\" and \"y\" should be lists of the same length")
            data = [[a, b] for a, b in zip(xs, ys)]
        else:
            raise InputError(f"{source}: expected a \"points\" list, found keys {sorted(data)}")
    return curve_from_points(_point_list(source, data, 2), source=source)


def read_points(path: str | os.PathLike) -> ControlGrid:
    """Read a surface's control points from a JSON or CSV file.

    Parameters
    ----------
    path : str or path-like
        A ``.json`` file (a list of ``[x, y, z]``, ``{"points": [...]}``, or
        ``{"x": [...], "y": [...], "z": [[...]]}``) or a ``.csv`` file with
        columns x,y,z (header optional).

    Returns
    -------
    ControlGrid
        The points arranged as the paper's matrix ``p_ik``.

    Raises
    ------
    InputError
        With a one-line message naming the file and the bad value.
    """
    name, text = _read_bytes(path)
    return parse_points(text, source=name, kind=_kind(name, text))


UNITS = ("mm", "inch")


def read_units(path: str | os.PathLike, default: str = "mm") -> str:
    """The length unit a points file states (``"units": "mm"`` or ``"inch"`` in JSON), else ``default``.

    CSV files state none.

    Raises
    ------
    InputError
        For a unit other than those in :data:`UNITS`.
    """
    name, text = _read_bytes(path)
    if _kind(name, text) != "json":
        return default
    data = _load_json(name, text)
    if not isinstance(data, dict) or "units" not in data:
        return default
    if data["units"] not in UNITS:
        raise InputError(f"{name}: \"units\": {_short(data['units'])} is not one of {', '.join(UNITS)}")
    return data["units"]


def read_curve_points(path: str | os.PathLike) -> CurvePoints:
    """Read a 1-D curve's points ``[[x, y], ...]`` from a JSON or CSV file."""
    name, text = _read_bytes(path)
    return parse_curve_points(text, source=name, kind=_kind(name, text))


def read_any_points(path: str | os.PathLike) -> ControlGrid | CurvePoints:
    """Read a points file that may hold a surface or a curve, telling them apart by arity."""
    name, text = _read_bytes(path)
    kind = _kind(name, text)
    if _arity(name, text, kind) == 2:
        return parse_curve_points(text, source=name, kind=kind)
    return parse_points(text, source=name, kind=kind)


def _arity(name: str, text: str, kind: str) -> int:
    if kind == "csv":
        for row in csv.reader(io.StringIO(text)):
            cells = [c for c in row if c.strip()]
            if cells and not cells[0].strip().startswith("#"):
                return len(cells)
        return 3
    data = _load_json(name, text)
    if isinstance(data, dict):
        if "points" in data:
            data = data["points"]
        else:
            return 3 if "z" in data else 2
    if isinstance(data, list) and data and isinstance(data[0], list):
        return len(data[0])
    return 3


def read_program(path: str | os.PathLike) -> str:
    """Read a part program as a control reads it: ASCII text, line endings kept as they are.

    Raises
    ------
    InputError
        For a missing or unreadable file, a directory, or a byte that is not ASCII.
    """
    name = str(path)
    raw = _raw(path, "a program")
    try:
        return raw.decode("ascii")
    except UnicodeDecodeError as e:
        raise InputError(f"{name}: byte 0x{raw[e.start]:02x} at offset {e.start} is not ASCII; "
                         f"a control reads ASCII programs") from None


@contextlib.contextmanager
def event_log(path: str | os.PathLike | None) -> Iterator:
    """A function that appends a time-stamped line to the log file ``path``, or None without a path."""
    if not path:
        yield None
        return
    try:
        fh = open(path, "a", encoding="utf-8")
    except OSError as e:
        raise InputError(f"{path}: cannot open the log file ({e.strerror or e})") from None
    with fh:
        def log(message: str) -> None:
            fh.write(f"{time.strftime('%Y-%m-%dT%H:%M:%S')} {message}\n")
            fh.flush()

        yield log


def _write_error(path, e: OSError) -> OutputError:
    reason = (e.strerror or str(e)).lower()
    if e.errno == errno.ENOSPC:
        reason = "no space left on the device"
    return OutputError(f"{path}: cannot write ({reason}); any earlier file there is untouched")


def _is_stream(given: Path, real: Path) -> bool:
    """A target written through rather than replaced: a device, pipe or socket, or a /dev or /proc name."""
    if str(given).startswith(("/dev/", "/proc/")):
        return True
    try:
        return not stat.S_ISREG(real.stat().st_mode)
    except FileNotFoundError:
        return False


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[str]:
    """Yield a temporary file name; once the block succeeds its content becomes ``path``'s.

    For libraries that write a file by name (meshio, VTK) as much as for
    :func:`atomic_write`.  How the content arrives depends on what ``path`` is:

    - a regular file, or a new name: the temporary file sits beside it and
      replaces it in one rename, keeping an existing file's permissions (a new
      file gets ``0o666`` less the umask); a file with other hard links is
      rewritten in place instead, so the links stay one file;
    - a symbolic link: the same, for the file it points to (the link stays);
    - a device, pipe or socket (``/dev/null``, ``/dev/stdout``, a FIFO): written
      through, after the content is complete.

    A failure part-way, a full disk included, leaves any earlier file
    untouched and no partial file behind, and is one :class:`OutputError`.
    """
    given = Path(path)
    real = Path(os.path.realpath(given))
    if real.is_dir():
        raise InputError(f"{path}: is a directory")
    stream = _is_stream(given, real)
    directory = Path(tempfile.gettempdir()) if stream else real.parent
    if not directory.is_dir():
        raise InputError(f"{path}: the folder {directory} does not exist")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{real.name}.", suffix=".part" + real.suffix, dir=directory)
    except OSError as e:
        raise _write_error(path, e) from None
    os.close(fd)
    try:
        yield tmp
        if stream:
            _copy_into(tmp, given)
        else:
            _commit(tmp, real)
    except OSError as e:
        raise _write_error(path, e) from None
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)


def _copy_into(tmp: str, target: Path) -> None:
    with open(tmp, "rb") as src, open(target, "wb") as dst:
        shutil.copyfileobj(src, dst, 1 << 20)


def _commit(tmp: str, target: Path) -> None:
    try:
        old = target.stat()
    except FileNotFoundError:
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, target)
        return
    if old.st_nlink > 1:
        with open(tmp, "rb") as src, open(target, "r+b") as dst:
            shutil.copyfileobj(src, dst, 1 << 20)
            dst.truncate()
            dst.flush()
            os.fsync(dst.fileno())
        return
    os.chmod(tmp, stat.S_IMODE(old.st_mode))
    os.replace(tmp, target)


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "w", newline: str | None = None) -> Iterator[IO]:
    """Open a temporary file whose content becomes ``path``'s only if the block succeeds (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp:
        kwargs = {} if "b" in mode else {"encoding": "utf-8", "newline": newline}
        try:
            with open(tmp, mode, **kwargs) as fh:
                yield fh
                fh.flush()
                os.fsync(fh.fileno())
        except OSError as e:
            raise _write_error(path, e) from None


def write_text(path: str | os.PathLike, text: str, newline: str | None = "") -> None:
    """Write ``text`` to ``path`` atomically (no newline translation by default)."""
    with atomic_write(path, "w", newline=newline) as fh:
        fh.write(text)
