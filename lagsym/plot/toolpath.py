"""The cutter path drawn over the surface it machines."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import InputError
from .backend import DEFAULT_WINDOW_SIZE, new_plotter
from .checks import check_points, check_window_size
from .meshes import polyline, scalar_mesh
from .style import FEED_COLOR, RAPID_COLOR, SURFACE_CMAP, axis_labels, bar_args, fit, units_of, view, z_scale
from .surface import sampled_surface

__all__ = ["toolpath_figure"]


def toolpath_figure(surface, moves, *, rapid=None, samples: int = 61, units: str | None = None, title: str | None = None,
                    window_size: Sequence[int] = DEFAULT_WINDOW_SIZE, off_screen: bool | None = None):
    """The cutter path drawn over the surface (the paper's Figures 12 and 14).

    Parameters
    ----------
    surface : LagrangeSurface
        The surface, drawn half transparent over the box of its control points.
    moves : (N, 3) array
        Tool-tip points in the surface's units, in the order the tool visits
        them; consecutive points are joined by straight moves.
    rapid : (N,) array of bool, optional
        ``rapid[k]`` is true when the move that ends at point ``k`` is a rapid
        (``rapid[0]`` is ignored).  Feed moves are drawn in orange-red, rapids
        in blue.  Default: every move is a feed move.
    samples : int
        Samples along each axis of the surface.
    units : str
        Length unit shown on the axes.
    title : str, optional
        Defaults to one giving the degree and the number of moves.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    pts = check_points(moves, "moves")
    if rapid is None:
        fast = np.zeros(len(pts), dtype=bool)
    else:
        fast = np.asarray(rapid)
        if fast.shape != (len(pts),) or fast.dtype != bool:
            raise InputError(f"rapid should be a boolean array of shape ({len(pts)},), got {fast.dtype} {fast.shape}")
    xs, ys, zz = sampled_surface(surface, samples)
    units = units_of(surface, units)
    w, h = check_window_size(window_size)
    p = new_plotter(window_size=(w, h), off_screen=off_screen)
    name = f"z ({units})"
    p.add_mesh(scalar_mesh(xs, ys, zz, name), scalars=name, cmap=SURFACE_CMAP, smooth_shading=True, opacity=0.55,
               scalar_bar_args=bar_args(name, h))
    seg = np.arange(len(pts) - 1)
    feed, quick = seg[~fast[1:]], seg[fast[1:]]
    if feed.size:
        p.add_mesh(polyline(pts, feed), color=FEED_COLOR, line_width=2, lighting=False)
    if quick.size:
        p.add_mesh(polyline(pts, quick), color=RAPID_COLOR, line_width=1, lighting=False)
    span_z = float(max(zz.max(), pts[:, 2].max()) - min(zz.min(), pts[:, 2].min()))
    p.set_scale(zscale=z_scale(max(np.ptp(xs), np.ptp(pts[:, 0])), max(np.ptp(ys), np.ptp(pts[:, 1])), span_z))
    axis_labels(p, units, font_size=max(8, h // 60))
    deg = surface.degree
    text = title if title is not None else (
        f"Toolpath over the Lagrange surface, degree {deg[0]} x {deg[1]}\n"
        f"{feed.size} feed moves (red), {quick.size} rapids (blue)")
    p.add_text(text, position="upper_edge", font_size=fit(text, w, largest=12), color="black")
    view(p, zoom=0.9)
    return p
