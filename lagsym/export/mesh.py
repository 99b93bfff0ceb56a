"""Triangle meshes for CAD and viewers: VTK (``.vtk``, ``.vts``), STL, PLY and OBJ.

The sample grid is triangulated, each grid cell into two triangles whose
normals point up (+z).  Files are written by meshio (``.vtk``, ``.ply``,
``.obj``) and by VTK (``.stl``, whose writer streams the facets from the
shared points instead of copying each triangle; ``.vts``, a structured grid
that keeps the rows and columns); both libraries are imported inside the
functions that use them.  A mesh is built whole in memory, so its size is
limited by :data:`MESH_MAX_POINTS`; the point tables stream.
"""

from __future__ import annotations

import contextlib
import errno
import os

import numpy as np

from ..errors import InputError
from ..sampling import Sample
from ..io import atomic_path

__all__ = ["MESH_MAX_POINTS", "MESHIO_FORMATS", "triangles", "write_meshio", "write_stl", "write_vts"]

MESH_MAX_POINTS = 2049 * 2049  # meshes are built whole: about 600 MB at the peak
MESHIO_FORMATS = {".vtk": "vtk", ".ply": "ply", ".obj": "obj"}


def triangles(nx: int, ny: int) -> np.ndarray:
    """The ``(2 (nx-1) (ny-1), 3)`` triangles of an ``nx`` x ``ny`` grid whose point ``i * ny + j`` is ``(xs[i], ys[j])``.

    Counter-clockwise seen from +z, so the normals of a surface point up.

    Examples
    --------
    >>> triangles(2, 2).tolist()
    [[0, 2, 3], [0, 3, 1]]
    """
    idx = np.arange(nx * ny, dtype=np.int32).reshape(nx, ny)
    a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
    c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    tri = np.empty((2 * a.size, 3), dtype=np.int32)
    tri[0::2] = np.stack([a, b, c], axis=1)
    tri[1::2] = np.stack([a, c, d], axis=1)
    return tri


def _check_size(sample: Sample, path) -> None:
    n = sample.z.size
    if n > MESH_MAX_POINTS:
        raise InputError(
            f"{path}: a mesh of {n} points is more than {MESH_MAX_POINTS}; use a coarser grid, "
            f"or a point table (.npy, .csv), which streams any size"
        )


def write_meshio(path: str | os.PathLike, sample: Sample, file_format: str) -> None:
    """Write ``sample`` as a triangle mesh with meshio (``vtk``, ``ply`` or ``obj``), atomically."""
    import meshio

    _check_size(sample, path)
    nx, ny = sample.z.shape
    points = np.column_stack([np.asarray(sample.x).ravel(), np.asarray(sample.y).ravel(), sample.z.ravel()])
    point_data = {"z": sample.z.ravel()} if file_format == "vtk" else {}  # PLY would repeat the name z
    mesh = meshio.Mesh(points, [("triangle", triangles(nx, ny))], point_data=point_data)
    options = {"binary": True} if file_format in ("vtk", "ply") else {}
    with atomic_path(path) as tmp:
        meshio.write(tmp, mesh, file_format=file_format, **options)


def write_vts(path: str | os.PathLike, sample: Sample) -> None:
    """Write ``sample`` as a VTK XML structured grid (``.vts``), with the heights as point data ``z``."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkStructuredGrid
    from vtkmodules.vtkIOXML import vtkXMLStructuredGridWriter

    _check_size(sample, path)
    nx, ny = sample.z.shape
    # VTK runs its first index fastest: put x there so that VTK's (i, j) is the sample's (i, j).
    xyz = np.column_stack([np.asarray(sample.x).T.ravel(), np.asarray(sample.y).T.ravel(), sample.z.T.ravel()])
    pts = vtkPoints()
    pts.SetData(numpy_to_vtk(xyz, deep=True))
    grid = vtkStructuredGrid()
    grid.SetDimensions(nx, ny, 1)
    grid.SetPoints(pts)
    z = numpy_to_vtk(np.ascontiguousarray(sample.z.T.ravel()), deep=True)
    z.SetName("z")
    grid.GetPointData().AddArray(z)
    grid.GetPointData().SetActiveScalars("z")
    with atomic_path(path) as tmp:
        writer = vtkXMLStructuredGridWriter()
        writer.SetFileName(tmp)
        writer.SetInputData(grid)
        writer.SetDataModeToAppended()
        writer.EncodeAppendedDataOff()
        _vtk_write(writer, tmp, lambda size: _ends_with(tmp, b"</VTKFile>\n"))


def write_stl(path: str | os.PathLike, sample: Sample) -> None:
    """Write ``sample`` as a binary STL file (float32 facets, as STL stores them) with VTK's writer."""
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    from vtkmodules.vtkIOGeometry import vtkSTLWriter

    _check_size(sample, path)
    nx, ny = sample.z.shape
    # STL holds float32: a coordinate beyond its range would become inf in the file.
    big = max(float(np.max(np.abs(a))) for a in (sample.x, sample.y, sample.z))
    if not big <= float(np.finfo(np.float32).max):
        raise InputError(f"{path}: a coordinate of {big:.3g} does not fit STL's 32-bit floats "
                         f"(largest {float(np.finfo(np.float32).max):.3g}); write .vtk, .vts, .ply or .npy instead")
    xyz = np.empty((nx * ny, 3), dtype=np.float32)
    xyz[:, 0].reshape(nx, ny)[...] = sample.x
    xyz[:, 1].reshape(nx, ny)[...] = sample.y
    xyz[:, 2] = sample.z.ravel()
    conn = triangles(nx, ny).astype(np.int64).ravel()
    offsets = np.arange(0, conn.size + 1, 3, dtype=np.int64)
    pts = vtkPoints()
    pts.SetData(numpy_to_vtk(xyz, deep=False))
    cells = vtkCellArray()
    cells.SetData(numpy_to_vtkIdTypeArray(offsets, deep=False), numpy_to_vtkIdTypeArray(conn, deep=False))
    poly = vtkPolyData()
    poly.SetPoints(pts)
    poly.SetPolys(cells)
    facets = 2 * (nx - 1) * (ny - 1)
    with atomic_path(path) as tmp:
        writer = vtkSTLWriter()
        writer.SetFileName(tmp)
        writer.SetInputData(poly)
        writer.SetFileTypeToBinary()
        _vtk_write(writer, tmp, lambda size: size == STL_HEADER_BYTES + STL_FACET_BYTES * facets)


STL_HEADER_BYTES, STL_FACET_BYTES = 84, 50  # binary STL: 80-byte header and a count, then 50 bytes a facet


@contextlib.contextmanager
def _vtk_quiet():
    """VTK's own error and log lines kept off standard error (the failure is one line of lagsym's), then restored."""
    from vtkmodules.vtkCommonCore import vtkLogger, vtkObject

    shown, cutoff = vtkObject.GetGlobalWarningDisplay(), vtkLogger.GetCurrentVerbosityCutoff()
    vtkObject.GlobalWarningDisplayOff()
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
    try:
        yield
    finally:
        vtkLogger.SetStderrVerbosity(vtkLogger.ConvertToVerbosity(cutoff))
        vtkObject.SetGlobalWarningDisplay(shown)


def _vtk_write(writer, tmp: str, complete) -> None:
    """Run a VTK ``writer`` on ``tmp`` quietly; an OSError unless its error code is clear and ``complete(size)``.

    VTK's writers return success on a full disk (the XML writer) or delete the
    file and log a line (the STL writer), so the error code and the file
    written are checked, not the return value.
    """
    from vtkmodules.vtkCommonMisc import vtkErrorCode

    with _vtk_quiet():
        writer.Write()
    code = writer.GetErrorCode()
    if 0 < code < vtkErrorCode.FirstVTKErrorCode:  # VTK passes errno through
        raise OSError(code, os.strerror(code))
    if code == vtkErrorCode.OutOfDiskSpaceError:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    if code:
        raise OSError(errno.EIO, f"the VTK writer stopped: {vtkErrorCode.GetStringFromErrorCode(code)}")
    try:
        size = os.stat(tmp).st_size
    except FileNotFoundError:
        size = -1
    if not complete(size):
        raise OSError(errno.EIO, "the VTK writer left an incomplete file")


def _ends_with(name: str, tail: bytes) -> bool:
    """Whether the file ``name`` ends with ``tail`` (an XML file's closing tag: the writer got to its end)."""
    try:
        with open(name, "rb") as fh:
            fh.seek(0, os.SEEK_END)
            if fh.tell() < len(tail):
                return False
            fh.seek(-len(tail), os.SEEK_END)
            return fh.read() == tail
    except OSError:
        return False
