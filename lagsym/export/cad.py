"""Writing the exact patch to a CAD file, the format chosen by the file extension.

==================  =====================================================
extension           contents
==================  =====================================================
``.step``, ``.stp`` STEP AP214: a B-spline face, or a solid with a base
``.igs``, ``.iges`` IGES 5.3: entity 128, with a base five more closing it
``.json``           the exact rational knots and control points
==================  =====================================================

Files are written atomically: a bad base or any error leaves no partial file.
"""

from __future__ import annotations

import os
from fractions import Fraction
from pathlib import Path

from ..cad.patch import BSplinePatch
from ..errors import InputError
from ..io import atomic_write
from .iges import write_iges
from .patchjson import write_patch_json
from .step import write_step

__all__ = ["CAD_FORMATS", "cad_format_of", "write_cad"]

CAD_FORMATS = {".step": "step", ".stp": "step", ".igs": "iges", ".iges": "iges", ".json": "json"}


def cad_format_of(path: str | os.PathLike) -> str:
    """``"step"``, ``"iges"`` or ``"json"`` from the extension of ``path``.

    Examples
    --------
    >>> cad_format_of("part.STP")
    'step'
    """
    ext = Path(path).suffix.lower()
    if ext not in CAD_FORMATS:
        raise InputError(f"{path}: unknown CAD format {ext or '(no extension)'!r}; "
                         f"choose one of {', '.join(CAD_FORMATS)}")
    return CAD_FORMATS[ext]


def write_cad(path: str | os.PathLike, patch: BSplinePatch, *, base_z: Fraction | None = None,
              units: str = "mm", source: str = "<surface>", timestamp: str | None = None) -> None:
    """Write ``patch`` to ``path`` as STEP, IGES or JSON by its extension, atomically.

    Parameters
    ----------
    path : str or path-like
    patch : BSplinePatch
        From :func:`lagsym.cad.cad_patch`.
    base_z : Fraction, optional
        Close the surface down to this plane into a solid; it must lie below
        the whole surface.
    units : {"mm", "inch"}
        The length unit of the coordinates, declared in the file.
    source : str
        The points file, for messages.
    timestamp : str, optional
        For the file header (STEP: ISO 8601, IGES: ``YYYYMMDD.HHNNSS``); default now.

    Raises
    ------
    InputError
        For an unknown extension, a base at or above the surface, a missing folder.
    """
    kind = cad_format_of(path)
    name = Path(path).stem
    with atomic_write(path, "w", newline="\n") as fh:
        if kind == "json":
            write_patch_json(fh, patch, base_z=base_z, units=units, source=source)
        else:
            writer = write_step if kind == "step" else write_iges
            writer(fh, patch, base_z=base_z, units=units, name=name, timestamp=timestamp, source=source)
