"""pyvista data built from plain arrays: sampled surfaces, outlines, point clouds and polylines.

Array conventions follow :func:`lagsym.evaluate.evaluate_grid`: a height array
``z`` sampled on the axes ``x`` and ``y`` has ``z[i, j] = F(x[i], y[j])``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["structured", "scalar_mesh", "outline", "pointcloud", "polyline"]


def structured(x: np.ndarray, y: np.ndarray, z: np.ndarray):
    """The surface ``z`` over the axes ``x`` and ``y`` as a :class:`pyvista.StructuredGrid`."""
    import pyvista as pv

    xx, yy = np.meshgrid(x, y, indexing="ij")
    return pv.StructuredGrid(xx, yy, np.asarray(z, dtype=float))


def scalar_mesh(x: np.ndarray, y: np.ndarray, z: np.ndarray, name: str, values: np.ndarray | None = None):
    """The surface ``z`` over ``x`` x ``y`` carrying the point array ``name`` (``z`` itself unless ``values``)."""
    mesh = structured(x, y, z)
    mesh.point_data[name] = np.asarray(z if values is None else values, dtype=float).ravel(order="F")
    return mesh


def outline(x: np.ndarray, y: np.ndarray):
    """The edges of the box ``x[0]..x[-1]`` x ``y[0]..y[-1]`` at z = 0."""
    return structured(np.array([x[0], x[-1]]), np.array([y[0], y[-1]]), np.zeros((2, 2))).extract_all_edges()


def pointcloud(pts: np.ndarray):
    """The points ``pts`` (an ``(N, 3)`` array) as vertices."""
    import pyvista as pv

    return pv.PolyData(pts)


def polyline(points: np.ndarray, segments: np.ndarray):
    """Line segments ``points[s] -> points[s + 1]`` for each index ``s`` in ``segments``."""
    import pyvista as pv

    lines = np.column_stack([np.full(len(segments), 2), segments, segments + 1]).ravel()
    return pv.PolyData(points, lines=lines)
