"""The cutter path drawn over the surface it machines."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import InputError
from ..machine import Placement
from .backend import DEFAULT_WINDOW_SIZE, new_plotter
from .checks import check_points, check_window_size
from .meshes import polyline, scalar_mesh
from .style import (
    FEED_COLOR,
    RAPID_COLOR,
    SURFACE_CMAP,
    axis_labels,
    bar_args,
    fit,
    text_size,
    view,
    z_factor,
    z_note,
)
from .surface import sampled_surface

__all__ = ["toolpath_figure"]


def toolpath_figure(surface, moves_mm, *, rapid=None, placement: Placement | None = None, samples: int = 61,
                    title: str | None = None, z_exaggeration: float | None = None,
                    window_size: Sequence[int] = DEFAULT_WINDOW_SIZE, off_screen: bool | None = None):
    """The cutter path drawn over the surface, in machine millimetres (the paper's Figures 12 and 14).

    Parameters
    ----------
    surface : LagrangeSurface
        The surface, drawn half transparent over the box of its control points,
        placed on the machine by ``placement``.
    moves_mm : (N, 3) array
        Tool-tip points in machine millimetres (as a program's X, Y, Z), in
        the order the tool visits them; consecutive points are joined by
        straight moves.
    rapid : (N,) array of bool, optional
        ``rapid[k]`` is true when the move that ends at point ``k`` is a rapid
        (``rapid[0]`` is ignored).  Feed moves are drawn in orange-red, rapids
        in thicker blue.  Default: every move is a feed move.
    placement : Placement, optional
        Where the surface sits on the machine (millimetres per surface unit
        and origin), the one the program was made with.  Default: 1 mm per
        unit at the origin.
    samples : int
        Samples along each axis of the surface.
    title : str, optional
        Defaults to one giving the degree and the number of moves.
    z_exaggeration : float, optional
        Draw z this many times its true size; default as in
        :func:`~lagsym.plot.surface_figure`.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    pts = check_points(moves_mm, "moves_mm")
    if rapid is None:
        fast = np.zeros(len(pts), dtype=bool)
    else:
        fast = np.asarray(rapid)
        if fast.shape != (len(pts),) or fast.dtype != bool:
            raise InputError(f"rapid should be a boolean array of shape ({len(pts)},), got {fast.dtype} {fast.shape}")
    place = placement if placement is not None else Placement()
    xs, ys, zz = sampled_surface(surface, samples)
    xs, ys = place.to_machine(xs, ys)
    zz = place.height_mm(zz)
    w, h = check_window_size(window_size)
    p = new_plotter(window_size=(w, h), off_screen=off_screen)
    name = "z (mm)"
    p.add_mesh(scalar_mesh(xs, ys, zz, name), scalars=name, cmap=SURFACE_CMAP, smooth_shading=True, opacity=0.55,
               scalar_bar_args=bar_args(name, h))
    seg = np.arange(len(pts) - 1)
    feed, quick = seg[~fast[1:]], seg[fast[1:]]
    if feed.size:
        p.add_mesh(polyline(pts, feed), color=FEED_COLOR, line_width=2, lighting=False)
    if quick.size:
        p.add_mesh(polyline(pts, quick), color=RAPID_COLOR, line_width=4, lighting=False)
    span_z = float(max(zz.max(), pts[:, 2].max()) - min(zz.min(), pts[:, 2].min()))
    factor = z_factor(z_exaggeration, max(np.ptp(xs), np.ptp(pts[:, 0])), max(np.ptp(ys), np.ptp(pts[:, 1])), span_z)
    p.set_scale(zscale=factor)
    axis_labels(p, "mm", font_size=text_size(h, 1 / 45))
    deg = surface.degree
    text = title if title is not None else "\n".join(filter(None, [
        f"Toolpath over the Lagrange surface, degree {deg[0]} x {deg[1]}",
        f"{feed.size} feed moves (red), {quick.size} rapid{'' if quick.size == 1 else 's'} (blue)", z_note(factor)]))
    p.add_text(text, position="upper_edge", font_size=fit(text, w, largest=text_size(h, 1 / 48)), color="black")
    view(p, zoom=0.85)
    return p
