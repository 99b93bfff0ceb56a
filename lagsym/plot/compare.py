"""Figures that set surfaces side by side: the comparison of methods and the deviation maps.

Both take plain arrays sampled on shared axes, ``Z[i, j]`` at ``(x[i], y[j])``,
so any method's surface, or a measurement, can be drawn.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..errors import InputError
from .backend import DEFAULT_WINDOW_SIZE, new_plotter
from .checks import check_axis, check_heights, check_points, check_window_size
from .meshes import outline, pointcloud, scalar_mesh
from .style import (
    BAR_COLUMN,
    DEVIATION_CMAP,
    POINT_COLOR,
    SURFACE_CMAP,
    bar_column,
    fit,
    plan_axes,
    plan_view,
    text_size,
    view,
    z_factor,
    z_note,
)

__all__ = ["compare_figure", "deviation_figure", "DEVIATION_WINDOW_SIZE"]

DEVIATION_WINDOW_SIZE = (1280, 480)  # one row of square maps


def compare_figure(x, y, surfaces: Mapping[str, np.ndarray], *, reference: str = "Lagrange", units: str = "mm",
                   control_points=None, z_exaggeration: float | None = None,
                   window_size: Sequence[int] = DEFAULT_WINDOW_SIZE, off_screen: bool | None = None):
    """Surfaces side by side, with the deviation of each from a reference below it (the paper's Figure 10).

    Top row: every surface, on one colour scale for z.  Bottom row: for each
    surface but the reference, the deviation ``d = z_f - z_a`` (the paper's
    sign, as ``lagsym compare`` prints it: reference minus that surface) seen
    from above with x and y axes, on one colour scale symmetric about 0; under
    the reference, the plan of the control points.  Red is where the surface
    lies below the reference.

    Parameters
    ----------
    x, y : 1-D array
        Strictly increasing sample axes, shared by every surface.
    surfaces : mapping of str to 2-D array
        Method name to heights ``Z[i, j]`` at ``(x[i], y[j])``, in drawing order.
    reference : str
        The key the others are measured against (``z_f``).
    units : str
        Length unit of x, y and z.
    control_points : (K, 3) array, optional
        Points marked on every surface.
    z_exaggeration : float, optional
        Draw z this many times its true size in the top row; default as in
        :func:`~lagsym.plot.surface_figure`.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    x, y = check_axis(x, "x"), check_axis(y, "y")
    if not surfaces:
        raise InputError("no surfaces to compare")
    if reference not in surfaces:
        raise InputError(f"reference {reference!r} is not among the surfaces: {', '.join(map(repr, surfaces))}")
    zs = {name: check_heights(z, (x.size, y.size), f"surface {name!r}") for name, z in surfaces.items()}
    pts = check_points(control_points, "control_points") if control_points is not None else None
    ref = zs[reference]
    zlo = min(float(z.min()) for z in zs.values())
    zhi = max(float(z.max()) for z in zs.values())
    dmax = max((float(np.abs(ref - z).max()) for z in zs.values()), default=0.0) or 1.0
    factor = z_factor(z_exaggeration, np.ptp(x), np.ptp(y), zhi - zlo)
    names = list(zs)
    n = len(names)
    w, h = check_window_size(window_size)
    p = new_plotter(shape=(2, n + 1), window_size=(w, h), off_screen=off_screen, col_weights=[1.0] * n + [BAR_COLUMN])
    panel = w / (n + BAR_COLUMN)
    zname, dname = f"z ({units})", f"d ({units})"
    top = fit("\n".join([*names, z_note(factor)]), panel, largest=text_size(h, 1 / 60))
    bottom = fit("\n".join(f"d = {reference} - {name}" for name in names), panel, largest=text_size(h, 1 / 48))
    ticks = text_size(h, 1 / 50)
    z_actor = d_actor = None
    for col, name in enumerate(names):
        p.subplot(0, col)
        z_actor = p.add_mesh(scalar_mesh(x, y, zs[name], zname), scalars=zname, cmap=SURFACE_CMAP,
                             clim=(zlo, zhi), smooth_shading=True, show_scalar_bar=False)
        if pts is not None:
            p.add_mesh(pointcloud(pts), color=POINT_COLOR, point_size=8, render_points_as_spheres=True)
        p.add_text(name if col or not z_note(factor) else f"{name}\n{z_note(factor)}", position="upper_edge",
                   font_size=top, color="black")
        p.set_scale(zscale=factor)
        view(p, zoom=1.0)
        p.subplot(1, col)
        if name == reference:
            _add_plan(p, x, y, pts, f"{name}\n(reference z_f)", bottom)
        else:
            d_actor = _add_deviation(p, x, y, ref - zs[name], name=f"d = {reference} - {name}", units=units,
                                     dmax=dmax, font=bottom)
        plan_axes(p, units, ticks)
        plan_view(p, zoom=0.6)
    bar_column(p, 0, n, z_actor.mapper, zname, h)
    if d_actor is not None:
        bar_column(p, 1, n, d_actor.mapper, dname, h)
    return p


def _add_deviation(p, x, y, d, *, name: str, units: str, dmax: float, font: int):
    """One deviation map on the current panel, titled with ``name`` and its largest ``|d|``; returns the actor."""
    dname = f"d ({units})"
    actor = p.add_mesh(scalar_mesh(x, y, np.zeros_like(d), dname, d), scalars=dname, cmap=DEVIATION_CMAP,
                       clim=(-dmax, dmax), lighting=False, show_scalar_bar=False)
    p.add_mesh(outline(x, y), color="black", line_width=1, lighting=False)
    p.add_text(f"{name}\nlargest {np.abs(d).max():.3g} {units}", position="upper_edge", font_size=font,
               color="black")
    return actor


def _add_plan(p, x, y, pts, text: str, font: int) -> None:
    p.add_mesh(outline(x, y), color="gray", line_width=1, lighting=False)
    if pts is not None:
        p.add_mesh(pointcloud(np.c_[pts[:, :2], np.zeros(len(pts))]), color=POINT_COLOR, point_size=8,
                   render_points_as_spheres=True)
    p.add_text(text, position="upper_edge", font_size=font, color="black")


def deviation_figure(x, y, deviations: Mapping[str, np.ndarray], *, reference: str = "z_f", units: str = "mm",
                     window_size: Sequence[int] = DEVIATION_WINDOW_SIZE, off_screen: bool | None = None):
    """One deviation colour map per method, seen from above with x and y axes, on one scale symmetric about 0.

    The deviations are ``d = z_f - z_a`` (reference minus method), as
    :attr:`lagsym.compare.Comparison.deviations` holds them and as the
    bottom row of :func:`compare_figure` draws them: red where the method lies
    below the reference.

    Parameters
    ----------
    x, y : 1-D array
        Strictly increasing sample axes.
    deviations : mapping of str to 2-D array
        Method name to deviations ``D[i, j] = z_f - z_a`` at ``(x[i], y[j])``.
    reference : str
        What ``z_f`` is called in the panel titles ("Lagrange - Hermite").
    units : str
        Length unit of x, y and the deviations.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    x, y = check_axis(x, "x"), check_axis(y, "y")
    if not deviations:
        raise InputError("no deviations to draw")
    ds = {name: check_heights(d, (x.size, y.size), f"deviations {name!r}") for name, d in deviations.items()}
    dmax = max(float(np.abs(d).max()) for d in ds.values()) or 1.0
    n = len(ds)
    w, h = check_window_size(window_size)
    p = new_plotter(shape=(1, n + 1), window_size=(w, h), off_screen=off_screen, col_weights=[1.0] * n + [BAR_COLUMN])
    panel = w / (n + BAR_COLUMN)
    titles = {name: f"d = {reference} - {name}" for name in ds}
    font = fit("\n".join([*titles.values(), f"largest 0.000 {units}"]), panel, largest=text_size(h, 1 / 16))
    ticks = text_size(h, 1 / 20)
    actor = None
    for col, (name, d) in enumerate(ds.items()):
        p.subplot(0, col)
        actor = _add_deviation(p, x, y, d, name=titles[name], units=units, dmax=dmax, font=font)
        plan_axes(p, units, ticks)
        plan_view(p, zoom=0.75)
    bar_column(p, 0, n, actor.mapper, f"d ({units})", 2 * h)
    return p
