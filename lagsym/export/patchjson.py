"""The exact patch as JSON: every knot and control coordinate an exact rational in a string.

::

    {"format": "lagsym-bspline-patch", "version": 1, "surface": "Lagrange", "units": "mm",
     "degree": [2, 2], "knots_u": ["1", "1", "1", "5", "5", "5"], "knots_v": [...],
     "control_points": [[["1", "2", "7"], ...], ...],
     "solid": {"base_z": "6", "volume": "320/3"}}

``control_points[i][k]`` is ``[x, y, z]`` of ``P_ik`` (``i`` along ``u``);
numbers are ``"p/q"`` or integers, exactly as :class:`fractions.Fraction`
prints them, so ``Fraction(text)`` reads them back.  ``"solid"`` is there when
the file was written with a base.
"""

from __future__ import annotations

import json
from fractions import Fraction
from typing import IO

from ..cad.patch import BSplinePatch
from ..cad.solid import check_base, volume
from ..errors import InputError
from ..polytext import fraction_text
from .cadtext import check_units

__all__ = ["FORMAT", "patch_document", "write_patch_json", "parse_patch_json"]

FORMAT = "lagsym-bspline-patch"


def patch_document(patch: BSplinePatch, *, base_z: Fraction | None = None, units: str = "mm",
                   source: str = "<surface>") -> dict:
    """The JSON document of ``patch`` as a dict of strings and lists (``base_z`` checked as for STEP)."""
    doc = {
        "format": FORMAT,
        "version": 1,
        "surface": patch.name,
        "units": check_units(units),
        "degree": [patch.degree_u, patch.degree_v],
        "knots_u": [fraction_text(k) for k in patch.knots_u],
        "knots_v": [fraction_text(k) for k in patch.knots_v],
        "control_points": [[[fraction_text(c) for c in p] for p in row] for row in patch.control_points],
    }
    if base_z is not None:
        base_z = check_base(patch, base_z, source)
        doc["solid"] = {"base_z": fraction_text(Fraction(base_z)), "volume": fraction_text(volume(patch, base_z))}
    return doc


def write_patch_json(stream: IO[str], patch: BSplinePatch, *, base_z: Fraction | None = None,
                     units: str = "mm", source: str = "<surface>") -> None:
    """Write ``patch`` (and its solid's base and exact volume, with ``base_z``) to ``stream`` as JSON."""
    doc = patch_document(patch, base_z=base_z, units=units, source=source)
    rows = ",\n  ".join(json.dumps(row) for row in doc.pop("control_points"))
    head = "".join(f" {json.dumps(k)}: {json.dumps(v)},\n" for k, v in doc.items())  # one item, one row a line
    stream.write(f"{{\n{head} \"control_points\": [\n  {rows}]\n}}\n")


def _fraction(text: str) -> Fraction:
    """``Fraction(text)`` for ``"p/q"`` or ``"p"`` of any length: Python's own text-to-int conversion stops at 4,300
    digits, python-flint's does not."""
    import flint

    num, slash, den = text.partition("/")
    if not num.lstrip("-").isdigit() or (slash and not den.isdigit()):
        raise ValueError(f"{text[:40]!r} is not an integer or a ratio of integers")
    return Fraction(int(flint.fmpz(num)), int(flint.fmpz(den)) if slash else 1)


def parse_patch_json(text: str, source: str = "<patch>") -> BSplinePatch:
    """Read a patch written by :func:`write_patch_json` back, exactly.

    Examples
    --------
    >>> import io
    >>> from lagsym.cad import cad_patch
    >>> from lagsym.grid import grid_from_table
    >>> p = cad_patch(grid_from_table([0, 1], [0, 1], [[0, 1], [1, 3]]))
    >>> buf = io.StringIO(); write_patch_json(buf, p)
    >>> parse_patch_json(buf.getvalue()) == p
    True
    """
    try:
        doc = json.loads(text)
        if doc.get("format") != FORMAT:
            raise InputError(f"{source}: not a {FORMAT} file")
        p, q = doc["degree"]
        net = tuple(tuple(tuple(_fraction(c) for c in pt) for pt in row) for row in doc["control_points"])
        return BSplinePatch(doc["surface"], p, q, tuple(_fraction(k) for k in doc["knots_u"]),
                            tuple(_fraction(k) for k in doc["knots_v"]), net)
    except (ValueError, KeyError, TypeError, AttributeError) as e:
        if isinstance(e, InputError):
            raise
        raise InputError(f"{source}: not a valid {FORMAT} file ({e})") from None
