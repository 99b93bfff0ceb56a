"""The exact piecewise surface file: the control grid with the slopes and twists its pieces share.

::

    {"format": "lagsym-piecewise", "version": 1, "units": "mm",
     "pieces": "bicubic Hermite", "continuity": "C1", "slopes": "3-point Lagrange",
     "x": ["0", "2", ...], "y": [...],
     "z": [["12.01", ...], ...], "zx": [...], "zy": [...], "zxy": [...]}

Every number is an exact rational in a string (``"p/q"``, an integer or a
decimal).  ``z[i][k]`` is the height at ``(x[i], y[k])``; ``zx``, ``zy`` and
``zxy`` the slopes and twist there; piece ``(i, k)`` over
``[x[i], x[i+1]] x [y[k], y[k+1]]`` is the bicubic Hermite patch of its four
corners (:mod:`lagsym.surfaces.piecewise`).  The reader rebuilds the surface
from ``x``, ``y`` and ``z`` and refuses a file whose slopes differ from the
rule's, naming the first node, so a file edited by hand never gives pieces
that do not join.
"""

from __future__ import annotations

import json
from typing import IO

from ..errors import InputError
from ..grid import grid_from_table
from ..surfaces.piecewise import CONTINUITY, PiecewiseSurface, piecewise_surface
from ..values import as_exact

__all__ = ["FORMAT", "piecewise_document", "write_piecewise_json", "parse_piecewise_json", "read_piecewise_file"]

FORMAT = "lagsym-piecewise"


def piecewise_document(surface: PiecewiseSurface) -> dict:
    """The JSON document of ``surface`` as a dict of strings and lists."""
    g = surface.grid
    doc = {"format": FORMAT, "version": 1}
    if g.units:
        doc["units"] = g.units
    doc.update({"pieces": "bicubic Hermite", "continuity": CONTINUITY, "slopes": "3-point Lagrange",
                "x": [str(v) for v in g.x], "y": [str(v) for v in g.y]})
    for key, table in (("z", g.z), ("zx", surface.zx), ("zy", surface.zy), ("zxy", surface.zxy)):
        doc[key] = [[str(v) for v in row] for row in table]
    return doc


def write_piecewise_json(stream: IO[str], surface: PiecewiseSurface) -> None:
    """Write ``surface`` to ``stream`` as a ``lagsym-piecewise`` document, one row of numbers a line."""
    lines = []
    for key, value in piecewise_document(surface).items():
        if key in ("z", "zx", "zy", "zxy"):
            rows = ",\n  ".join(json.dumps(row) for row in value)
            lines.append(f" {json.dumps(key)}: [\n  {rows}]")
        else:
            lines.append(f" {json.dumps(key)}: {json.dumps(value)}")
    stream.write("{\n" + ",\n".join(lines) + "\n}\n")


def read_piecewise_file(path) -> PiecewiseSurface | None:
    """The surface of the file ``path`` when it is a ``lagsym-piecewise`` document, else None (a points file).

    Standard input (``"-"``) is read once, as points, so it gives None.
    """
    from ..io import read_text

    if str(path) == "-":
        return None
    name, text = read_text(path)
    head = text.lstrip()[:400]
    if not head.startswith("{") or f'"{FORMAT}"' not in head:
        return None
    return parse_piecewise_json(text, name)


def parse_piecewise_json(text: str, source: str = "<piecewise>") -> PiecewiseSurface:
    """Read a surface written by :func:`write_piecewise_json` back, exactly, and check its slopes.

    Examples
    --------
    >>> import io
    >>> g = grid_from_table([0, 1, 2], [0, 1, 2], [[0, 1, 2], [1, 3, 4], [2, 4, 7]])
    >>> buf = io.StringIO(); write_piecewise_json(buf, piecewise_surface(g))
    >>> parse_piecewise_json(buf.getvalue()) == piecewise_surface(g)
    True
    """
    try:
        doc = json.loads(text)
    except ValueError as e:
        raise InputError(f"{source}: not a valid {FORMAT} file ({e})") from None
    return piecewise_from_document(doc, source)


def piecewise_from_document(doc, source: str = "<piecewise>") -> PiecewiseSurface:
    """The surface of a parsed ``lagsym-piecewise`` document (see :func:`parse_piecewise_json`)."""
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise InputError(f"{source}: not a {FORMAT} file")
    if doc.get("version") != 1:
        raise InputError(f"{source}: {FORMAT} version {doc.get('version')!r} is not 1")
    def numbers(key):
        value = doc.get(key)
        if not isinstance(value, list) or not value:
            raise InputError(f"{source}: \"{key}\" should be a list, found {type(value).__name__}")
        return value

    xs = [as_exact(v, f"{source}: x[{i}]") for i, v in enumerate(numbers("x"))]
    ys = [as_exact(v, f"{source}: y[{i}]") for i, v in enumerate(numbers("y"))]
    tables = {}
    for key in ("z", "zx", "zy", "zxy"):
        rows = numbers(key)
        if not all(isinstance(r, list) for r in rows):
            raise InputError(f"{source}: \"{key}\" should be a list of rows of numbers")
        tables[key] = [[as_exact(v, f"{source}: {key}[{i}][{k}]") for k, v in enumerate(r)] for i, r in enumerate(rows)]
    units = doc.get("units")
    if units is not None and units not in ("mm", "inch"):
        raise InputError(f"{source}: \"units\": {units!r} is not one of mm, inch")
    surface = piecewise_surface(grid_from_table(xs, ys, tables["z"], source=source, units=units))
    for key in ("zx", "zy", "zxy"):
        want = getattr(surface, key)
        got = tables[key]
        if len(got) != len(want) or any(len(r) != len(w) for r, w in zip(got, want)):
            raise InputError(f"{source}: \"{key}\" should be {len(want)} rows of {len(want[0])} numbers")
        for i, (r, w) in enumerate(zip(got, want)):
            for k, (a, b) in enumerate(zip(r, w)):
                if a != b:
                    raise InputError(f"{source}: {key}[{i}][{k}] = {a} is not the 3-point Lagrange slope {b} of "
                                     f"the heights: the pieces would not join C1 (edited by hand?)")
    return surface
