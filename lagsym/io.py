"""Reading point files and writing results: every path lagsym touches passes here.

Numbers in input files are exact: the JSON number text ``1.06`` is 53/50, never
the nearest binary float, and strings may hold exact decimals or rationals
(``"1/3"``).  Writers are atomic: a file appears complete or not at all.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import os
import re
import tempfile
import time
from collections.abc import Iterator
from decimal import Decimal
from fractions import Fraction
from pathlib import Path
from typing import IO, Any

from .errors import InputError
from .grid import ControlGrid, CurvePoints, curve_from_points, grid_from_points, grid_from_table

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
_MAX_EXPONENT = 300  # beyond this a coordinate has no use and no float to go with it
_RATIONAL = re.compile(r"^\s*([+-]?\d+)\s*/\s*(\d+)\s*$")
_DECIMAL = re.compile(r"^\s*[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?\s*$")


class _Bad(Exception):
    """A value that is not an exact number, with a reason."""


def exact_number(text: str) -> Fraction:
    """Read an exact decimal or rational from text.

    Examples
    --------
    >>> exact_number("1.06"), exact_number("-1/3"), exact_number("2e3")
    (Fraction(53, 50), Fraction(-1, 3), Fraction(2000, 1))
    """
    m = _RATIONAL.match(text)
    if m:
        num, den = m.groups()
        if len(num) > _MAX_EXPONENT or len(den) > _MAX_EXPONENT:
            raise _Bad(f"{text!r} is too large")
        if int(den) == 0:
            raise _Bad(f"{text!r} divides by zero")
        return Fraction(int(num), int(den))
    if not _DECIMAL.match(text):
        raise _Bad(f"{text.strip()!r} is not a number")
    d = Decimal(text.strip())
    if len(d.as_tuple().digits) > _MAX_EXPONENT or abs(d.adjusted()) > _MAX_EXPONENT:
        raise _Bad(f"{text.strip()!r} is out of range (overflow)")
    return Fraction(d)


def _json_float(text: str) -> Fraction:
    try:
        return exact_number(text)
    except _Bad as e:
        raise _JsonValueError(str(e)) from None


def _json_int(text: str) -> int:
    if len(text.lstrip("-")) > _MAX_EXPONENT:
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
        except _Bad as e:
            raise InputError(f"{where}: {e}") from None
    raise InputError(f"{where}: {_short(v)} is not a number")


def _short(v: Any) -> str:
    try:
        text = json.dumps(v, default=str)
    except (TypeError, ValueError, RecursionError):
        text = type(v).__name__
    return text if len(text) <= 40 else text[:37] + "..."


def _raw(path: str | os.PathLike, what: str, limit: int | None = None) -> bytes:
    """The bytes of ``path``; every way reading can fail becomes one InputError naming the file."""
    p = Path(path)
    name = str(path)
    try:
        if p.is_dir():
            raise InputError(f"{name}: is a directory, not {what}")
        if limit is not None and (size := p.stat().st_size) > limit:
            raise InputError(f"{name}: {size} bytes is too large for {what}")
        return p.read_bytes()
    except FileNotFoundError:
        raise InputError(f"{name}: no such file") from None
    except PermissionError:
        raise InputError(f"{name}: permission denied") from None
    except IsADirectoryError:
        raise InputError(f"{name}: is a directory, not {what}") from None
    except OSError as e:
        raise InputError(f"{name}: cannot read ({e.strerror or e})") from None


def _read_bytes(path: str | os.PathLike) -> tuple[str, str]:
    name = str(path)
    raw = _raw(path, "a points file", MAX_BYTES)
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
            except _Bad as e:
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


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[str]:
    """Yield a temporary file name beside ``path``; it replaces ``path`` only if the block succeeds.

    For libraries that write a file by name (meshio, VTK) as much as for
    :func:`atomic_write`: a failure part-way leaves any earlier file at
    ``path`` untouched and no partial file behind.  The finished file gets the
    permissions a newly created file would (``0o666`` less the umask).
    """
    target = Path(path)
    directory = target.parent if str(target.parent) else Path(".")
    if not directory.is_dir():
        raise InputError(f"{path}: the folder {directory} does not exist")
    if target.is_dir():
        raise InputError(f"{path}: is a directory")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part" + target.suffix, dir=directory)
    os.close(fd)
    try:
        yield tmp
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "w", newline: str | None = None) -> Iterator[IO]:
    """Open a temporary file beside ``path``; it replaces ``path`` only if the block succeeds.

    A failure part-way leaves any earlier file at ``path`` untouched and no
    partial file behind.
    """
    with atomic_path(path) as tmp:
        kwargs = {} if "b" in mode else {"encoding": "utf-8", "newline": newline}
        with open(tmp, mode, **kwargs) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())


def write_text(path: str | os.PathLike, text: str, newline: str | None = "") -> None:
    """Write ``text`` to ``path`` atomically (no newline translation by default)."""
    with atomic_write(path, "w", newline=newline) as fh:
        fh.write(text)
