"""Point tables as spreadsheets, CMM software and scanners write them: the layout found, and said.

A table is read in three steps, each stated in :meth:`Layout.describe`:

1. the separator: tab, semicolon, comma or runs of whitespace, the first
   that splits every data line into the same number of cells (a comma inside
   a cell, as LibreOffice writes ``"1,5"``, is a decimal comma);
2. the header: a first line that is not all numbers names the columns, ``x``,
   ``y``, ``z`` with units in any of the usual spellings (``X (mm)``,
   ``y [mm]``, ``Z_mm``, ``x/in``); other columns (a point id, a label) are
   left out and named in the description;
3. the columns: from the header, or from ``columns`` (``"id,x,y,z"`` names
   every column in order; ``"2,3,4"`` gives the 1-based columns of x, y, z);
   without either the file must have exactly the columns wanted.  A column
   empty on every line (a trailing separator) is dropped.

Numbers stay exact: ``2,5`` with a decimal comma is 5/2.
"""

from __future__ import annotations

import csv
import re
from collections import Counter
from dataclasses import dataclass
from fractions import Fraction

from ..errors import InputError
from ..values import NotANumber, exact_number
from .decimals import DecimalPoints, parse_plain

__all__ = ["Layout", "read_table", "parse_columns", "UNIT_NAMES"]

UNIT_NAMES = {"mm": "mm", "millimeter": "mm", "millimeters": "mm", "millimetre": "mm", "millimetres": "mm",
              "in": "inch", "inch": "inch", "inches": "inch", '"': "inch"}
SEPARATORS = {"\t": "tab", ";": "semicolon", ",": "comma", " ": "whitespace"}
_HEADER = re.compile(r"^\s*([A-Za-z#][\w #.]*?)\s*(?:[(\[]\s*([^)\]]*?)\s*[)\]]|[_/]\s*([A-Za-z\"]+))?\s*$")
_NUMBER = re.compile(r"^[+-]?((\d+[.,]?\d*|[.,]\d+)([eE][+-]?\d+)?|\d+\s*/\s*\d+)$")


@dataclass(frozen=True)
class Layout:
    """What was found in a point table.

    Attributes
    ----------
    separator : str
        ``"\\t"``, ``";"``, ``","`` or ``" "`` (runs of whitespace).
    decimal : str
        ``"."`` or ``","``.
    header : tuple of str
        The header cells as written, or empty without a header.
    columns : tuple of int
        The 0-based columns read as x, y (and z).
    ignored : tuple of str
        The columns left out, by header name or 1-based number.
    units : str or None
        ``"mm"`` or ``"inch"`` where the header says.
    """

    separator: str
    decimal: str
    header: tuple[str, ...]
    columns: tuple[int, ...]
    ignored: tuple[str, ...] = ()
    units: str | None = None

    @property
    def plain(self) -> bool:
        """Comma-separated, decimal points, exactly the columns wanted in order (or named by a plain header)."""
        return (self.separator == "," and self.decimal == "." and not self.ignored and self.units is None
                and all(c.strip().lower() in "xyz" for c in self.header))

    def describe(self) -> str:
        """One phrase: separator, decimal mark, header, columns, units."""
        names = "xyz"[:len(self.columns)]
        parts = [f"{SEPARATORS[self.separator]}-separated", "decimal comma" if self.decimal == "," else "decimal point"]
        parts.append(f"header {clip(self.separator.join(self.header))}" if self.header else "no header")
        parts.append(", ".join(f"{n} from column {c + 1}" for n, c in zip(names, self.columns)))
        if self.ignored:
            more = len(self.ignored) - SHOWN_NAMES
            shown = ", ".join(clip(c, 20)[1:-1] if len(c) <= 20 else clip(c, 20) for c in self.ignored[:SHOWN_NAMES])
            parts.append(f"ignoring column(s) {shown}" + (f" and {more:,} more" if more > 0 else ""))
        if self.units:
            parts.append(f"units {self.units}")
        return "; ".join(parts)


def parse_columns(text: str, arity: int | None = None) -> tuple[str, ...] | tuple[int, ...]:
    """Read a ``--columns`` value: names of every column (``id,x,y,z``) or 1-based numbers of x, y, z (``2,3,4``).

    Examples
    --------
    >>> parse_columns("id,X,y,z"), parse_columns("2, 3, 4")
    (('id', 'x', 'y', 'z'), (1, 2, 3))
    """
    cells = [c.strip().lower() for c in text.split(",")]
    if cells and all(c.isdigit() for c in cells):
        if any(int(c) < 1 for c in cells) or len(set(cells)) != len(cells):
            raise InputError(f"--columns {text!r}: column numbers count from 1 and may not repeat")
        if arity is not None and len(cells) != arity:
            raise InputError(f"--columns {text!r}: give {arity} column numbers, for {','.join('xyz'[:arity])}")
        if len(cells) not in (2, 3):
            raise InputError(f"--columns {text!r}: give the column numbers of x,y (a curve) or x,y,z (a surface)")
        return tuple(int(c) - 1 for c in cells)
    wanted = [c for c in cells if c in ("x", "y", "z")]
    if len(set(wanted)) != len(wanted) or not {"x", "y"} <= set(wanted) or (arity and len(wanted) != arity):
        need = ",".join("xyz"[:arity]) if arity else "x,y or x,y,z"
        raise InputError(f"--columns {text!r}: name every column of the file in order, {need} once each and any other "
                         f"name for a column to leave out (e.g. id,x,y,z), or give column numbers (e.g. 2,3,4)")
    return tuple(cells)


MAX_CELL = 10_000  # characters in one cell: a number of 300 digits fits many times over
SHOWN = 60  # characters of a header or cell a message quotes: a prefix, so a message stays short
SHOWN_NAMES = 5  # names of ignored columns a description lists


def clip(text: str, limit: int = SHOWN) -> str:
    """``text`` quoted as a message shows a piece of a file: at most ``limit`` characters, then how many more.

    Examples
    --------
    >>> clip("x,y,z"), clip("x,y,z" + ",w" * 100, 9)
    ("'x,y,z'", "'x,y,z,w,w'... (196 more characters)")
    """
    if len(text) <= limit:
        return repr(text)
    return f"{text[:limit]!r}... ({len(text) - limit:,} more characters)"


def _split(text: str, sep: str) -> list[tuple[int, list[str]]]:
    # Lines first, at any line ending (LF, CRLF, or CR alone as old Mac software writes); a cell is
    # never a line long, so no quoted cell spans lines.
    lines = text.splitlines()
    for lineno, line in enumerate(lines, start=1):
        if len(line) > MAX_CELL and max(len(c) for c in line.split(sep if sep != " " else None)) > MAX_CELL:
            raise InputError(f"line {lineno} has a cell of more than {MAX_CELL} characters, which is no number")
    if sep == " ":
        rows = [_join_units(line.split()) for line in lines]
    elif '"' not in text:  # no quoting anywhere: the csv module would split exactly here, at a fraction of the cost
        rows = [line.split(sep) for line in lines]
    else:
        rows = [next(csv.reader([line], delimiter=sep), []) for line in lines]
    out = []
    for lineno, row in enumerate(rows, start=1):
        cells = [c.strip() for c in row]
        if any(cells) and not cells[0].startswith("#"):
            out.append((lineno, cells))
    return out


def _join_units(tokens: list[str]) -> list[str]:
    """``X (mm)`` split at the space is one header cell: a unit in brackets joins the name before it."""
    out: list[str] = []
    for t in tokens:
        if out and t[:1] in "([" and not _numeric(out[-1]):
            out[-1] += " " + t
        else:
            out.append(t)
    return out


def _numeric(cell: str) -> bool:
    """Looks like a number (decimal point or comma, exponent, rational); its range is checked when it is read."""
    return bool(_NUMBER.match(cell))


def _is_header(cells: list[str]) -> bool:
    return any(c and not _numeric(c) for c in cells)


def _separator(text: str) -> tuple[str, list[tuple[int, list[str]]]]:
    """The first separator that gives every data line the same number of (numeric or empty) cells."""
    for sep in ("\t", ";", ",", " "):
        if sep != " " and sep not in text:
            continue
        rows = _split(text, sep)
        body = rows[1:] if rows and _is_header(rows[0][1]) else rows
        if (body and len({len(c) for _, c in body}) == 1 and len(body[0][1]) > 1
                and all(not c or _numeric(c) for _, cells in body for c in cells)):
            return sep, rows
    # Nothing splits cleanly: keep the most likely and let the line-by-line check name the bad line.
    sep = next((s for s in ("\t", ";", ",") if s in text), " ")
    return sep, _split(text, sep)


def _header_names(name: str, header: list[str]) -> tuple[list[str], str | None]:
    names, units = [], set()
    for cell in header:
        m = _HEADER.match(cell)
        label = (m.group(1) if m else cell).strip().lower()
        unit = (m.group(2) or m.group(3)) if m else None
        if unit and label in ("x", "y", "z"):
            if unit.lower() not in UNIT_NAMES:
                raise InputError(f"{name}: header {clip(cell)}: unit {clip(unit)} is not one lagsym knows (mm or inch); "
                                 f"convert the column or leave the unit out")
            units.add(UNIT_NAMES[unit.lower()])
        names.append(label)
    if len(units) > 1:
        raise InputError(f"{name}: the header mixes units ({', '.join(sorted(units))}); use one unit for x, y and z")
    return names, units.pop() if units else None


def _choose(name: str, names: list[str] | None, width: int, columns, arity: int | None) -> tuple[int, ...]:
    """The 0-based columns of x, y (and z)."""
    if columns and isinstance(columns[0], int):
        if max(columns) >= width:
            raise InputError(f"{name}: --columns asks for column {max(columns) + 1} but the lines have {width}")
        return tuple(columns)
    labels = list(columns) if columns else names
    if columns and len(columns) != width:
        raise InputError(f"{name}: --columns names {len(columns)} columns but the lines have {width}")
    if labels is not None:
        want = "xyz" if "z" in labels else "xy"
        if arity is not None:
            want = "xyz"[:arity]
        found = [labels.index(c) for c in want if labels.count(c) == 1]
        if len(found) == len(want):
            return tuple(found)
        if columns is None and all(c in ("x", "y", "z") for c in labels):
            raise InputError(f"{name}: line 1: header {clip(','.join(names))[1:-1]} should name the columns "
                             f"{','.join(want)}")
    if labels is None and (arity is None or width == arity) and width in (2, 3):
        return tuple(range(width))
    want = ",".join("xyz"[:arity]) if arity else "x,y,z"
    example = ",".join(["id"] + list("xyz"[:arity or 3]))
    raise InputError(f"{name}: the lines have {width} columns and lagsym cannot tell which are {want}: "
                     f"name them in a header or with --columns (e.g. --columns {example} or --columns 2,3,4)")


def _check_header(name: str, sep: str, header: list[str], line: int, rows: list[tuple[int, list[str]]]) -> None:
    """A header naming as many columns as the data lines have (empty cells at either end aside)."""
    named = len(header)
    while named and not header[named - 1]:
        named -= 1
    width = len(rows[0][1])
    used = max((j + 1 for _, cells in rows for j in range(width) if cells[j]), default=0)
    if named <= width and used <= named:
        return
    raise InputError(f"{name}: the header (line {line}) has {named:,} columns but the data lines have {width:,} "
                     f"(line {rows[0][0]}): header {clip(sep.join(header[:named]))}; the header should name each column of the lines below it once")


def read_table(name: str, text: str, arity: int | None, columns=None) -> tuple[list[tuple[Fraction, ...]], Layout]:
    """The points of a delimited table and the layout found; ``arity`` None means 2 or 3 as the table says.

    Examples
    --------
    >>> pts, layout = read_table("p.csv", "Nr;X (mm);Y (mm);Z (mm)\\r\\n1;0;0;1,25\\r\\n", 3)
    >>> pts, layout.describe()
    ([(Fraction(0, 1), Fraction(0, 1), Fraction(5, 4))], "semicolon-separated; decimal comma; header 'Nr;X (mm);Y (mm);Z (mm)'; x from column 2, y from column 3, z from column 4; ignoring column(s) Nr; units mm")
    """
    plain = _plain_table(name, text, arity, columns)
    if plain is not None:
        return plain
    try:
        sep, rows = _separator(text)
    except InputError as e:
        raise InputError(f"{name}: {e}") from None
    if not rows:
        raise InputError(f"{name}: no points in the file")
    header: list[str] = []
    names, units = None, None
    if _is_header(rows[0][1]):
        header_line, header = rows[0]
        rows = rows[1:]
    if not rows:
        raise InputError(f"{name}: no points in the file, only the header")
    # The width most lines have: one odd line (a trailing separator) is the one named, even if it comes first.
    counts = Counter(len(cells) for _, cells in rows)
    width = max(counts, key=lambda w: (counts[w], w == len(rows[0][1])))
    like = next(lineno for lineno, cells in rows if len(cells) == width)
    for lineno, cells in rows:
        if len(cells) != width:
            raise InputError(f"{name}: line {lineno} has {len(cells)} columns, expected {width} like line {like}")
    if header:
        _check_header(name, sep, header, header_line, rows)
        names, units = _header_names(name, header)
    # A trailing separator on every line (Excel after a deleted column) leaves a column with nothing in it.
    empty = [j for j in range(width) if all(not c[j] for _, c in rows) and (j >= len(header) or not header[j])]
    keep = [j for j in range(width) if j not in empty]
    rows = [(lineno, [cells[j] for j in keep]) for lineno, cells in rows]
    if names is not None:
        names = [names[j] for j in keep if j < len(names)] + [""] * max(0, len(keep) - len(names))
    chosen = _choose(name, names, len(keep), columns, arity)
    decimal = "," if any("," in c for _, cells in rows for c in cells) else "."
    if decimal == "," and any("." in c for _, cells in rows for c in cells):
        raise InputError(f"{name}: the numbers mix decimal commas and decimal points; use one decimal mark")
    points = []
    for lineno, cells in rows:
        values = []
        for j in chosen:
            cell = cells[j].replace(",", ".") if decimal == "," else cells[j]
            try:
                values.append(exact_number(cell))
            except NotANumber as e:
                raise InputError(f"{name}: line {lineno}: {e}") from None
        points.append(tuple(values))
    ignored = tuple((header[keep[j]] if header and keep[j] < len(header) else f"{keep[j] + 1}")
                    for j in range(len(keep)) if j not in chosen)
    return points, Layout(separator=sep, decimal=decimal, header=tuple(header),
                          columns=tuple(keep[j] for j in chosen), ignored=ignored, units=units)


def _plain_table(name: str, text: str, arity: int | None, columns) -> tuple[DecimalPoints, Layout] | None:
    """The table read in whole columns (:mod:`.decimals`) where, after an optional header line, every line is the
    same number of plain decimals split by one separator; else None, and the table is read cell by cell.

    Such a table has one layout for the steps above: its one separator, the first line a header if it is not all
    numbers, decimal points, no empty column.  The header and the columns are found by the same code.
    """
    if not text.isascii() or '"' in text:
        return None
    if "\r" in text:
        if text.count("\r") != text.count("\r\n"):
            return None
        text = text.replace("\r\n", "\n")
    newline = text.find("\n")
    first = text if newline < 0 else text[:newline]
    rest = "" if newline < 0 else text[newline + 1:]
    found = [s for s in SEPARATORS if s in (rest or first)]
    if len(found) != 1 or len(first.splitlines()) != 1 or first.lstrip().startswith("#") or len(first) > MAX_CELL:
        return None
    sep = found[0]
    cells = _join_units(first.split()) if sep == " " else [c.strip() for c in first.split(sep)]
    header, body, lineno = (cells, rest, 2) if _is_header(cells) else ([], text, 1)
    width = body.find("\n")
    width = len(body[:width if width >= 0 else len(body)].split(sep))
    if width < 2:
        return None
    parsed = parse_plain(body, sep, width)
    if parsed is None:
        return None
    names, units = None, None
    if header:
        _check_header(name, sep, header, 1, [(lineno, ["0"] * width)])  # no data cell is empty
        names, units = _header_names(name, header)
        names = names[:width] + [""] * max(0, width - len(names))
    chosen = _choose(name, names, width, columns, arity)
    values, exponents = parsed
    points = DecimalPoints([values[j] for j in chosen], [exponents[j] for j in chosen])
    ignored = tuple((header[j] if j < len(header) else f"{j + 1}") for j in range(width) if j not in chosen)
    return points, Layout(separator=sep, decimal=".", header=tuple(header), columns=tuple(chosen), ignored=ignored,
                          units=units)
