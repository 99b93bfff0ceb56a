"""IGES 5.3 files of an exact patch: entity 128 (rational B-spline surface), optionally closed by a base.

The patch is one entity 128 with all weights 1 (flagged polynomial).  With a
base, five more entities 128 close it: the four sides, each the ruled surface
between a boundary curve of the patch and its shadow in the base plane
(degree ``(p, 1)``, so exactly planar and exactly meeting the patch), and the
base, a bilinear patch.  The six surfaces bound the solid; a CAD system
sews them into one (IGES solids proper, entity 186, are rarely read the same
way twice, surfaces are).

Written as text of our own, like the STEP files, for the same reasons (see
:mod:`lagsym.export.step`).  Fixed 80-column records: start (S), global (G),
directory (D, two lines per entity), parameter data (P) and terminate (T).
"""

from __future__ import annotations

import time
import unicodedata
from fractions import Fraction
from typing import IO

from ..cad.patch import BSplinePatch
from ..cad.solid import check_base
from .cadtext import check_units, real

__all__ = ["write_iges", "closing_patches", "ascii_name"]

_UNIT_FLAGS = {"mm": (2, "MM"), "inch": (1, "INCH")}


def _hollerith(text: str) -> str:
    # IGES counts a Hollerith string in characters of its ASCII file: the text must be ASCII, so bytes are characters.
    if not text.isascii():
        raise ValueError(f"Hollerith text {text!r} is not ASCII")
    return f"{len(text)}H{text}"


def ascii_name(name: str) -> str:
    """The product name as an IGES file can hold it: ASCII (accents dropped: ``pièce`` is ``piece``), no delimiters.

    Examples
    --------
    >>> ascii_name("pièce-à-façon"), ascii_name("Ø6;,"), ascii_name("日本")
    ('piece-a-facon', '6', 'surface')
    """
    plain = unicodedata.normalize("NFKD", name).encode("ascii", "ignore").decode("ascii")
    return "".join(c for c in plain if c.isprintable() and c not in ",;") or "surface"


def _records(tokens: list[str], width: int) -> list[str]:
    """Pack parameter tokens (each ending in its delimiter) into lines of at most ``width`` columns."""
    lines, line = [], ""
    for tok in tokens:
        while len(tok) > width:  # only a very long Hollerith string; IGES lets strings run on
            room = width - len(line)
            lines.append(line + tok[:room])
            line, tok = "", tok[room:]
        if len(line) + len(tok) > width:
            lines.append(line)
            line = ""
        line += tok
    if line:
        lines.append(line)
    return lines


def _entity_128(patch: BSplinePatch) -> list[str]:
    n, m = patch.shape
    values: list = [128, n - 1, m - 1, patch.degree_u, patch.degree_v, 0, 0, 1, 0, 0]
    values += [real(k) for k in patch.knots_u] + [real(k) for k in patch.knots_v]
    values += ["1."] * (n * m)
    values += [real(c) for k in range(m) for i in range(n) for c in patch.control_points[i][k]]  # u runs fastest
    values += [real(v) for v in patch.box]
    return [f"{v}," for v in values[:-1]] + [f"{values[-1]};"]


def closing_patches(patch: BSplinePatch, base_z: Fraction) -> list[BSplinePatch]:
    """The four ruled sides and the bilinear base that close ``patch`` down to ``base_z``, exactly."""
    base_z = Fraction(base_z)
    out = []
    for side in ("v0", "u1", "v1", "u0"):
        degree, knots, points = patch.boundary(side)
        net = tuple(((p[0], p[1], base_z), p) for p in points)
        out.append(BSplinePatch(f"side {side}", degree, 1, knots, (Fraction(0),) * 2 + (Fraction(1),) * 2, net))
    x0, x1, y0, y1 = patch.xy_box
    net = (((x0, y0, base_z), (x0, y1, base_z)), ((x1, y0, base_z), (x1, y1, base_z)))
    out.append(BSplinePatch("base", 1, 1, (x0, x0, x1, x1), (y0, y0, y1, y1), net))
    return out


def _global(name: str, units: str, stamp: str, largest: float) -> list[str]:
    from .. import __version__

    flag, unit_name = _UNIT_FLAGS[units]
    resolution = "1.E-07" if units == "mm" else "4.E-09"
    values = ["1H,", "1H;", _hollerith(name), _hollerith(name + ".igs"), _hollerith("lagsym"),
              _hollerith(f"lagsym {__version__}"), "32", "38", "6", "308", "15", _hollerith(name), "1.",
              str(flag), _hollerith(unit_name), "1", "1.", _hollerith(stamp), resolution, real(largest), "", "",
              "11", "0", _hollerith(stamp)]
    return [f"{v}," for v in values[:-1]] + [f"{values[-1]};"]


def write_iges(stream: IO[str], patch: BSplinePatch, *, base_z: Fraction | None = None, units: str = "mm",
               name: str = "surface", timestamp: str | None = None, source: str = "<surface>") -> None:
    """Write ``patch`` to ``stream`` as an IGES file of entities 128, closed by a base at ``base_z`` if given.

    Parameters
    ----------
    stream : text stream
    patch : BSplinePatch
        The exact patch (:func:`lagsym.cad.cad_patch`); coordinates are lengths in ``units``.
    base_z : Fraction, optional
        The base plane's height; it must lie below the whole surface
        (:func:`lagsym.cad.check_base`), else an InputError naming ``source``.
    units : {"mm", "inch"}
    name : str
        The product name in the global section.
    timestamp : str, optional
        ``YYYYMMDD.HHNNSS`` (default: now, UTC).
    source : str
        The points file, for messages.
    """
    check_units(units)
    if base_z is not None:
        base_z = check_base(patch, base_z, source)
    name = ascii_name(name)
    surfaces = [patch] + (closing_patches(patch, base_z) if base_z is not None else [])
    stamp = timestamp or time.strftime("%Y%m%d.%H%M%S", time.gmtime())
    largest = max(abs(float(c)) for s in surfaces for row in s.control_points for p in row for c in p)
    start = [f"{patch.name} surface from lagsym, entity 128;", "exact control points rounded once to doubles"]
    glob = _records(_global(name, units, stamp, largest), 72)
    directory, params = [], []
    for s in surfaces:
        lines = _records(_entity_128(s), 64)
        de = len(directory) + 1  # the sequence number of the entity's first directory line
        label = "LAGRANGE" if s is patch and patch.name == "Lagrange" else ("SURFACE" if s is patch else "CLOSE")
        directory += [f"{128:8d}{len(params) + 1:8d}{0:8d}{0:8d}{0:8d}{0:8d}{0:8d}{0:8d}{'00000000':>8}",
                      f"{128:8d}{0:8d}{0:8d}{len(lines):8d}{0:8d}{'':8}{'':8}{label:>8}{0:8d}"]
        params += [f"{line:<64} {de:7d}" for line in lines]
    out = []
    for letter, section in (("S", start), ("G", glob), ("D", directory), ("P", params)):
        out += [f"{line:<72}{letter}{seq:7d}" for seq, line in enumerate(section, start=1)]
    counts = f"S{len(start):7d}G{len(glob):7d}D{len(directory):7d}P{len(params):7d}"
    out.append(f"{counts:<72}T{1:7d}")
    stream.write("\n".join(out) + "\n")
