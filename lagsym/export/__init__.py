"""Writing sampled surfaces to files, the format chosen by the file extension.

=============  ==========================================  =========
extension      contents                                    streamed
=============  ==========================================  =========
``.csv``       header ``x,y,z``, one point a line          yes
``.npy``       float64 array of shape ``(nx * ny, 3)``     yes
``.vtk``       legacy VTK triangle mesh, point data ``z``  no
``.vts``       VTK XML structured grid, point data ``z``   no
``.stl``       binary STL triangles                        no
``.ply``       binary PLY triangles                        no
``.obj``       Wavefront OBJ triangles                     no
=============  ==========================================  =========

Points are x-major (see :mod:`lagsym.sampling`).  Streamed formats go through
a temporary file beside the target, renamed at the end; every format is
written atomically: a file appears complete or not at all.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from ..errors import InputError
from ..io import atomic_write
from ..sampling import BLOCK_POINTS, SampleGrid, iter_blocks, sample
from .mesh import MESH_MAX_POINTS, MESHIO_FORMATS, write_meshio, write_stl, write_vts
from .table import write_csv, write_npy

__all__ = ["FORMATS", "STREAMED", "MESH_MAX_POINTS", "format_of", "write_sample", "write_csv", "write_npy"]

FORMATS = (".csv", ".npy", ".vtk", ".vts", ".stl", ".ply", ".obj")
STREAMED = (".csv", ".npy")


def format_of(path: str | os.PathLike) -> str:
    """The output format of ``path``, from its extension (lower case, with the dot).

    Examples
    --------
    >>> format_of("part.STL")
    '.stl'
    """
    ext = Path(path).suffix.lower()
    if ext not in FORMATS:
        raise InputError(f"{path}: unknown output format {ext or '(no extension)'!r}; "
                         f"choose one of {', '.join(FORMATS)}")
    return ext


def write_sample(
    path: str | os.PathLike,
    surface,
    grid: SampleGrid,
    progress: Callable[[int], None] | None = None,
    block_points: int = BLOCK_POINTS,
) -> None:
    """Sample ``surface`` on ``grid`` and write the points to ``path`` in the format its extension names.

    Parameters
    ----------
    path : str or path-like
        The output file; see the module docstring for the formats.
    surface : LagrangeSurface
        The surface to sample.
    grid : SampleGrid
        Where to sample it (:func:`lagsym.sampling.sample_grid`).
    progress : callable, optional
        Called with the number of points written so far.
    block_points : int
        Points per streamed block (``.csv``, ``.npy``).

    Raises
    ------
    InputError
        For an unknown extension, a missing folder, or a mesh larger than
        :data:`MESH_MAX_POINTS`.
    """
    _write(path, format_of(path), surface, grid, progress, block_points)


def _write(path, ext: str, surface, grid: SampleGrid, progress, block_points: int) -> None:
    if ext == ".csv":
        with atomic_write(path, "w", newline="") as fh:
            write_csv(fh, iter_blocks(surface, grid, block_points), progress)
        return
    if ext == ".npy":
        with atomic_write(path, "wb") as fh:
            write_npy(fh, iter_blocks(surface, grid, block_points), grid.size, progress)
        return
    if grid.size > MESH_MAX_POINTS:
        raise InputError(
            f"{path}: a mesh of {grid.nx} x {grid.ny} = {grid.size} points is more than {MESH_MAX_POINTS}; "
            f"use a coarser grid, or a point table (.npy, .csv), which streams any size"
        )
    s = sample(surface, grid=grid)
    if ext == ".vts":
        write_vts(path, s)
    elif ext == ".stl":
        write_stl(path, s)
    else:
        write_meshio(path, s, MESHIO_FORMATS[ext])
    if progress is not None:
        progress(grid.size)
