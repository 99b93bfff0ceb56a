"""Point files: JSON in several layouts and tables (CSV, TSV, ``.xyz``), read into exact control grids.

Numbers are exact: the JSON number text ``1.06`` is 53/50, never the nearest
binary float, and strings may hold exact decimals or rationals (``"1/3"``).
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass, replace
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..errors import InputError
from ..grid import ControlGrid, CurvePoints, SnapReport, curve_from_points, grid_from_points, grid_from_table, snap_points
from ..values import MAX_EXPONENT, NotANumber, choice, exact_number
from .decimals import DecimalPoints, first_repeat, grid_of_columns
from .files import check_point_count, read_text
from .table import UNIT_NAMES, parse_columns, read_table

__all__ = ["PointsFile", "read_point_file", "surface_file", "SURFACE_FORMAT", "ScatteredPoints",
           "read_scattered_points", "read_points", "read_curve_points", "read_any_points", "parse_points",
           "parse_curve_points", "TABLE_SUFFIXES"]

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


def _json_object(pairs: list[tuple[str, Any]]) -> dict:
    """A JSON object whose keys are all different: with a key twice, which one was meant is unknown."""
    doc = dict(pairs)
    if len(doc) != len(pairs):
        seen: set[str] = set()
        twice = next(k for k, _ in pairs if k in seen or seen.add(k))
        raise _JsonValueError(f"the key {twice!r} appears twice in one object; keep one")
    return doc


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



TABLE_SUFFIXES = (".csv", ".tsv", ".txt", ".xyz", ".dat", ".asc")
SURFACE_FORMAT = "lagsym-surface"
PIECEWISE_FORMAT = "lagsym-piecewise"  # read by :mod:`lagsym.export.piecewisejson`, refused here
_INTEGER_RATIO = re.compile(r"^[+-]?\d+(/\d+)?$")
_SURFACE_DIGITS = 1_000_000  # an exact fit's coefficients run to thousands of digits; a million is no coefficient


def _big(v: Any, where: str) -> Fraction:
    """An exact number of a surface file, where a rational may have far more digits than a measured value."""
    if isinstance(v, str) and _INTEGER_RATIO.match(v):
        if len(v) > _SURFACE_DIGITS:
            raise InputError(f"{where}: a number of {len(v)} characters is too long")
        import flint  # Python's own text-to-int conversion stops at 4,300 digits; flint's does not

        num, _, den = v.partition("/")
        d = int(flint.fmpz(den or "1"))
        if d == 0:
            raise InputError(f"{where}: {v[:20]!r} divides by zero")
        return Fraction(int(flint.fmpz(num.lstrip("+"))), d)
    return _value(v, where)


def _table_of(name: str, data: dict, key: str, depth: int) -> list:
    value = data.get(key)
    if not isinstance(value, list) or not value or (depth == 2 and not all(isinstance(r, list) and r for r in value)):
        shape = "a list of rows of numbers" if depth == 2 else "a list of numbers"
        raise InputError(f"{name}: \"{key}\" should be {shape}, found {_short(value)}")
    if depth == 1:
        return [_big(v, f"{name}: {key}[{i}]") for i, v in enumerate(value)]
    return [[_big(v, f"{name}: {key}[{i}][{k}]") for k, v in enumerate(row)] for i, row in enumerate(value)]


def surface_file(name: str, data: dict) -> ControlGrid:
    """The grid of a ``lagsym-surface`` document (:mod:`lagsym.export.surfacejson`), checked exactly.

    Every height must be the value of the file's polynomial at its node, so
    the Lagrange surface through the grid is that polynomial; a file whose
    heights and coefficients disagree (edited by hand) is refused, naming the
    first node that differs.
    """
    if data.get("format") != SURFACE_FORMAT:
        raise InputError(f"{name}: \"format\": {_short(data.get('format'))} is not one lagsym reads as points "
                         f"(a {SURFACE_FORMAT!r} file, or a list of points)")
    if data.get("version") != 1:
        raise InputError(f"{name}: {SURFACE_FORMAT} version {_short(data.get('version'))} is not 1")
    coeffs = _table_of(name, data, "coefficients", 2)
    if len({len(r) for r in coeffs}) != 1:
        raise InputError(f"{name}: the rows of \"coefficients\" differ in length")
    xs, ys, z = (_table_of(name, data, k, d) for k, d in (("x", 1), ("y", 1), ("z", 2)))
    p, q = len(coeffs) - 1, len(coeffs[0]) - 1
    if data.get("degree") != [p, q]:
        raise InputError(f"{name}: \"degree\": {_short(data.get('degree'))} does not match the coefficients "
                         f"(degree {p}x{q})")
    if len(xs) <= p or len(ys) <= q:
        raise InputError(f"{name}: {len(xs)} x {len(ys)} nodes cannot hold a polynomial of degree {p}x{q}; "
                         f"it needs at least {p + 1} x {q + 1}")
    grid = grid_from_table(xs, ys, z, source=name, units=_units(name, data))
    amp = data.get("amplification")
    if amp is not None:
        if isinstance(amp, bool) or not isinstance(amp, (int, Fraction)) or not 1 <= amp < 10 ** 300:
            raise InputError(f"{name}: \"amplification\": {_short(amp)} should be a number of at least 1")
        grid = replace(grid, amplification=float(amp))
    # One exact matrix product gives every node's value: V_x C V_y^T.
    import flint

    def fq(v: Fraction):
        return flint.fmpq(v.numerator, v.denominator)

    vx = flint.fmpq_mat(len(grid.x), p + 1, [fq(v ** a) for v in grid.x for a in range(p + 1)])
    vy = flint.fmpq_mat(len(grid.y), q + 1, [fq(v ** b) for v in grid.y for b in range(q + 1)])
    values = vx * flint.fmpq_mat(p + 1, q + 1, [fq(c) for row in coeffs for c in row]) * vy.transpose()
    for i, xi in enumerate(grid.x):
        for k, yk in enumerate(grid.y):
            v = values[i, k]
            if Fraction(int(v.p), int(v.q)) != grid.z[i][k]:
                raise InputError(f"{name}: the height at (x, y) = ({float(xi):.6g}, {float(yk):.6g}) is not the "
                                 f"polynomial's value there (the file was changed after it was written); "
                                 f"write it again with 'lagsym fit'")
    return grid


def _kind(name: str, text: str) -> str:
    suffix = Path(name).suffix.lower()
    if suffix == ".json":
        return "json"
    if suffix in TABLE_SUFFIXES:
        return "csv"
    return "json" if text.lstrip()[:1] in "[{" else "csv"


def _load_json(name: str, text: str) -> Any:
    try:
        return json.loads(text, parse_float=_json_float, parse_int=_json_int, parse_constant=_json_constant,
                          object_pairs_hook=_json_object)
    except _JsonValueError as e:
        raise InputError(f"{name}: {e}") from None
    except json.JSONDecodeError as e:
        raise InputError(f"{name}: not valid JSON: {e.msg} (line {e.lineno}, column {e.colno})") from None
    except RecursionError:
        raise InputError(f"{name}: the JSON is nested too deeply to be a points file") from None


def _point(name: str, idx: int, p: Any, arity: int) -> tuple[Fraction, ...]:
    want = "[x, y, z]" if arity == 3 else "[x, y]"
    if isinstance(p, dict):
        keys, names = {str(k).lower(): v for k, v in p.items()}, ", ".join("xyz"[:arity])
        if len(keys) < len(p) or not all(c in keys for c in "xyz"[:arity]):  # "x" and "X" are one key: twice
            raise InputError(f"{name}: point {idx + 1} {_short(p)} should have keys {names} once each")
        return tuple(_value(keys[c], f"{name}: point {idx + 1} {c}") for c in "xyz"[:arity])
    if not isinstance(p, list):
        raise InputError(f"{name}: point {idx + 1} is {_short(p)}, not a list {want}")
    if len(p) != arity:
        raise InputError(f"{name}: point {idx + 1} {_short(p)} has {len(p)} values, expected {want}")
    return tuple(_value(v, f"{name}: point {idx + 1}") for v in p)


def _point_list(name: str, data: Any, arity: int) -> list[tuple[Fraction, ...]]:
    if not isinstance(data, list):
        raise InputError(f"{name}: expected a list of points, found {_short(data)}")
    if not data:
        raise InputError(f"{name}: the list of points is empty")
    return [_point(name, idx, p, arity) for idx, p in enumerate(data)]


def _units(name: str, data: Any) -> str | None:
    if not isinstance(data, dict) or "units" not in data:
        return None
    unit = data["units"]
    if not isinstance(unit, str) or unit.strip().lower() not in UNIT_NAMES:
        raise InputError(f"{name}: \"units\": {_short(unit)} is not one lagsym knows (\"mm\" or \"inch\")")
    return UNIT_NAMES[unit.strip().lower()]


@dataclass(frozen=True)
class PointsFile:
    """A points file as read: the points, how they were laid out, and what ``snap`` moved.

    Attributes
    ----------
    points : ControlGrid or CurvePoints
        The points, with the file's units where it says them.
    layout : str
        How the file was read, in words (separator, decimal mark, header, columns, units).
    plain : bool
        True for the layouts that need no saying: JSON, or a comma-separated x,y,z table.
    snapped : SnapReport or None
        What ``snap`` moved, when it was given.
    """

    points: ControlGrid | CurvePoints
    layout: str
    plain: bool = True
    snapped: SnapReport | None = None


def _json_points(name: str, text: str, arity: int | None):
    """(points or table, arity, layout, units) from JSON text."""
    data = _load_json(name, text)
    units = _units(name, data)
    if isinstance(data, dict):
        if "format" in data:
            if data["format"] == PIECEWISE_FORMAT:
                raise InputError(f"{name}: a {PIECEWISE_FORMAT} file holds many polynomial pieces; this command needs "
                                 f"one polynomial (toolpath and export take pieces): give it the points, or a "
                                 f"'lagsym fit' surface")
            if arity == 2:
                raise InputError(f"{name}: a {data['format']!r} file holds a surface, not curve points")
            return surface_file(name, data), 3, f"{SURFACE_FORMAT} file", units
        if "points" in data:
            data = data["points"]
        elif {"x", "y", "z"} <= data.keys() and arity != 2:
            return _grid_table(name, data), 3, "JSON x, y, z table", units
        elif {"x", "y"} <= data.keys() and "z" not in data and arity != 3:
            xs, ys = data["x"], data["y"]
            if not isinstance(xs, list) or not isinstance(ys, list) or len(xs) != len(ys):
                raise InputError(f"{name}: \"x\" and \"y\" should be lists of the same length")
            data = [[a, b] for a, b in zip(xs, ys)]
        else:
            keys = "\"x\", \"y\", \"z\"" if arity != 2 else "\"x\", \"y\""
            raise InputError(f"{name}: expected a \"points\" list or {keys} keys, found keys {sorted(data)}")
    if arity is None:
        first = data[0] if isinstance(data, list) and data else None
        arity = (3 if "z" in {str(k).lower() for k in first} else 2) if isinstance(first, dict) else (
            len(first) if isinstance(first, list) and len(first) in (2, 3) else 3)
    points = _point_list(name, data, arity)
    objects = isinstance(data[0], dict)
    layout = f"JSON list of {{{', '.join('xyz'[:arity])}}} objects" if objects else "JSON list of points"
    return points, arity, layout, units


def _shown(value) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def read_point_file(path: str | os.PathLike, what: str = "surface", columns=None, snap=None) -> PointsFile:
    """Read a points file of any accepted layout; say how it was read and what ``snap`` moved.

    Parameters
    ----------
    path : str or path-like
        JSON (see :func:`read_points`) or a table: comma-, semicolon-, tab- or
        whitespace-separated, decimal points or commas, with or without a header.
    what : {"surface", "curve", "any"}
        What the file should hold; ``"any"`` tells a curve from a surface by its columns.
    columns : str, optional
        Which columns of a table are x, y (z): names of every column in order
        (``"id,x,y,z"``) or 1-based numbers (``"2,3,4"``); see
        :func:`lagsym.io.table.parse_columns`.
    snap : number or str, optional
        Take node coordinates that differ by at most this as one node
        (measured grids); see :func:`lagsym.grid.snap_points`.
    """
    choice(what, ("surface", "curve", "any"), "what")
    arity = {"surface": 3, "curve": 2, "any": None}[what]
    if not isinstance(path, (str, os.PathLike)):
        maker = "curve_from_points" if what == "curve" else "grid_from_points"
        raise InputError(f"a points file's path, not {type(path).__name__} {_shown(path)}: for points in memory "
                         f"use lagsym.{maker}(points)")
    name, text = read_text(path)
    check_point_count(name, text)
    cols = parse_columns(columns, arity) if columns else None
    if _kind(name, text) == "json":
        if cols:
            raise InputError(f"{name}: --columns is for tables (CSV, TSV, .xyz); a JSON file names its values")
        points, arity, layout, units = _json_points(name, text, arity)
        plain = True
    else:
        points, table = read_table(name, text, arity, cols)
        arity, layout, units, plain = len(table.columns), table.describe(), table.units, table.plain
    if isinstance(points, ControlGrid):
        report = snap_points([], snap, source=name)[1] if snap is not None else None
        return PointsFile(points, layout, plain, report)
    report = None
    if snap is not None:
        points, report = snap_points(points, snap, axes=arity - 1, source=name)
    build = grid_from_points if arity == 3 else curve_from_points
    made = grid_of_columns(points, name, units) if arity == 3 and isinstance(points, DecimalPoints) else None
    return PointsFile(made or build(points, source=name, units=units), layout, plain, report)


@dataclass(frozen=True)
class ScatteredPoints:
    """Points ``(x, y, z)`` as a file lists them, in no grid (for :func:`lagsym.fit.fit_surface`).

    Attributes
    ----------
    points : sequence of (Fraction, Fraction, Fraction)
        The points in the file's order (a grid file's x-major); a table of plain decimals gives a DecimalPoints.
    source : str
        The file name.
    units : str or None
        The units where the file says them.
    layout : str
        How the file was read, in words.
    plain : bool
        True for the layouts that need no saying.
    """

    points: Sequence[tuple[Fraction, Fraction, Fraction]]
    source: str
    units: str | None
    layout: str
    plain: bool = True


def read_scattered_points(path: str | os.PathLike, columns=None) -> ScatteredPoints:
    """Read surface points that need not form a grid: scattered, or a grid with points missing.

    The layouts are those of :func:`read_points`; a repeated ``(x, y)`` is
    refused (two heights for one place are two measurements to average
    first, or a mistake).
    """
    name, text = read_text(path)
    check_point_count(name, text)
    cols = parse_columns(columns, 3) if columns else None
    if _kind(name, text) == "json":
        if cols:
            raise InputError(f"{name}: --columns is for tables (CSV, TSV, .xyz); a JSON file names its values")
        points, _, layout, units = _json_points(name, text, 3)
        plain = True
    else:
        points, table = read_table(name, text, 3, cols)
        layout, units, plain = table.describe(), table.units, table.plain
    if isinstance(points, ControlGrid):
        units = units or points.units
        points = points.points()
    points = points if isinstance(points, DecimalPoints) else tuple(tuple(pt) for pt in points)
    if (repeat := first_repeat(points)) is not None:
        i, j = repeat
        raise InputError(f"{name}: points {i + 1} and {j + 1} are both at (x, y) = "
                         f"({float(points[j][0]):g}, {float(points[j][1]):g}); average them or drop one")
    return ScatteredPoints(points, name, units, layout, plain)


def parse_points(text: str, source: str = "<points>", kind: str = "json") -> ControlGrid:
    """Read surface control points from JSON or table text.

    Examples
    --------
    >>> parse_points('[[1, 2, 7], [1, 3, 10], [3, 2, 15], [3, 3, 18.5]]').z[1][1]
    Fraction(37, 2)
    """
    if kind == "csv":
        points, table = read_table(source, text, 3)
        return grid_from_points(points, source=source, units=table.units)
    points, _, _, units = _json_points(source, text, 3)
    return points if isinstance(points, ControlGrid) else grid_from_points(points, source=source, units=units)


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
    return grid_from_table(xs, ys, z, source=name, units=_units(name, data))


def parse_curve_points(text: str, source: str = "<points>", kind: str = "json") -> CurvePoints:
    """Read 1-D curve points ``(x, y)`` from JSON or table text."""
    if kind == "csv":
        points, table = read_table(source, text, 2)
        return curve_from_points(points, source=source, units=table.units)
    points, _, _, units = _json_points(source, text, 2)
    return curve_from_points(points, source=source, units=units)


def read_points(path: str | os.PathLike, columns=None, snap=None) -> ControlGrid:
    """Read a surface's control points from a JSON file or a table.

    Parameters
    ----------
    path : str or path-like
        A ``.json`` file (a list of ``[x, y, z]`` or of ``{"x": .., "y": ..,
        "z": ..}`` objects, ``{"points": [...]}``, or ``{"x": [...], "y": [...],
        "z": [[...]]}``, each with an optional ``"units"``: ``"mm"`` or
        ``"inch"``), or a table (``.csv``, ``.tsv``, ``.txt``, ``.xyz``):
        comma-, semicolon-, tab- or whitespace-separated, with or without a
        header such as ``X (mm),Y (mm),Z (mm)``, decimal points or commas.
    columns, snap
        As for :func:`read_point_file`.

    Returns
    -------
    ControlGrid
        The points arranged as the paper's matrix ``p_ik``.

    Raises
    ------
    InputError
        With a one-line message naming the file and the bad value.
    """
    return read_point_file(path, "surface", columns, snap).points


def read_curve_points(path: str | os.PathLike, columns=None, snap=None) -> CurvePoints:
    """Read a 1-D curve's points ``[[x, y], ...]`` from a JSON file or a table (as :func:`read_points`)."""
    return read_point_file(path, "curve", columns, snap).points


def read_any_points(path: str | os.PathLike, columns=None, snap=None) -> ControlGrid | CurvePoints:
    """Read a points file that may hold a surface or a curve, telling them apart by arity."""
    return read_point_file(path, "any", columns, snap).points
