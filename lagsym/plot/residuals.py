"""A fitted surface and its residuals: each measured point on a stem from the surface, coloured by its residual.

The residual of point ``k`` is ``r_k = z_k - p(x_k, y_k)`` of the exact fit
(:attr:`lagsym.fit.SurfaceFit.float_residuals`), drawn in floats.  A stem runs
from the surface at ``(x_k, y_k)`` to the point; residuals of a fit to measured
points are far smaller than the part, so the stems are drawn
``residual_exaggeration`` times their length (by default so that the longest
is a quarter of the surface's height span), which the title states.  Points
above the surface are red, below it blue (the deviation colour map, centred on
zero).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..evaluate import evaluate_grid, evaluate_points
from .backend import DEFAULT_WINDOW_SIZE, new_plotter
from .checks import check_samples, check_window_size
from .meshes import pointcloud, scalar_mesh
from .style import DEVIATION_CMAP, axis_labels, bar_args, fit, text_size, view, z_factor, z_note

__all__ = ["residuals_figure", "residual_exaggeration"]

SURFACE_COLOR = "lightgray"


def residual_exaggeration(residuals, z_span: float) -> float:
    """The factor that draws the largest residual a quarter of ``z_span`` long (1 when every residual is 0).

    Examples
    --------
    >>> residual_exaggeration([0.02, -0.01], 10.0)
    125.0
    """
    largest = float(np.abs(np.asarray(residuals, dtype=float)).max(initial=0.0))
    return 0.25 * z_span / largest if largest > 0 and z_span > 0 else 1.0


def residuals_figure(fit_result, *, samples: int = 61, units: str | None = None, title: str | None = None,
                     exaggeration: float | None = None, z_exaggeration: float | None = None,
                     window_size: Sequence[int] = DEFAULT_WINDOW_SIZE, off_screen: bool | None = None):
    """The fitted surface, and every measured point on a stem from it coloured by its residual.

    Parameters
    ----------
    fit_result : SurfaceFit
        A fit (:func:`lagsym.fit.fit_surface`): its surface, points and exact residuals.
    samples : int
        Samples of the surface along each axis of the points' box.
    units : str, optional
        Length unit of the axes and the colour bar (default: the fit's, else mm).
    title : str, optional
        Defaults to the degree, the number of points, the largest residual and the stems' exaggeration.
    exaggeration : float, optional
        Draw the stems this many times their length (default: :func:`residual_exaggeration`).
    z_exaggeration : float, optional
        Draw z this many times its true size, as :func:`lagsym.plot.surface_figure` does.
    window_size : (int, int)
    off_screen : bool, optional

    Returns
    -------
    pyvista.Plotter
    """
    import pyvista as pv

    n = check_samples(samples)
    w, h = check_window_size(window_size)
    pts = np.array([[float(v) for v in p] for p in fit_result.points])
    res = np.array(fit_result.float_residuals)
    xs = np.linspace(pts[:, 0].min(), pts[:, 0].max(), n)
    ys = np.linspace(pts[:, 1].min(), pts[:, 1].max(), n)
    surface = fit_result.surface
    zz = evaluate_grid(surface, xs, ys)
    base = evaluate_points(surface, pts[:, 0], pts[:, 1])
    span = float(np.ptp(zz))
    k = residual_exaggeration(res, span) if exaggeration is None else float(exaggeration)
    units = units or surface.grid.units or "mm"
    p = new_plotter(window_size=(w, h), off_screen=off_screen)
    p.add_mesh(scalar_mesh(xs, ys, zz, "z"), color=SURFACE_COLOR, smooth_shading=True, opacity=0.85)
    tips = np.column_stack([pts[:, 0], pts[:, 1], base + k * res])
    feet = np.column_stack([pts[:, 0], pts[:, 1], base])
    name = f"residual ({units})"
    top = float(np.abs(res).max(initial=0.0)) or 1.0
    stems = pv.PolyData(np.vstack([feet, tips]))
    count = len(pts)
    stems.lines = np.column_stack([np.full(count, 2), np.arange(count), np.arange(count) + count]).ravel()
    stems.point_data[name] = np.concatenate([res, res])
    p.add_mesh(stems, scalars=name, cmap=DEVIATION_CMAP, clim=(-top, top), line_width=2, lighting=False,
               show_scalar_bar=False)
    cloud = pointcloud(tips)
    cloud.point_data[name] = res
    p.add_mesh(cloud, scalars=name, cmap=DEVIATION_CMAP, clim=(-top, top), point_size=10,
               render_points_as_spheres=True, scalar_bar_args=bar_args(name, h))
    factor = z_factor(z_exaggeration, np.ptp(xs), np.ptp(ys), span)
    p.set_scale(zscale=factor)
    axis_labels(p, units, font_size=text_size(h, 1 / 45))
    if title is None:
        a, b = fit_result.degree
        title = (f"fit of degree {a} x {b} through {count} points: largest residual {top:.3g} {units}, "
                 f"stems drawn {k:.3g} times their length")
    if z_note(factor):
        title = f"{title}\n{z_note(factor)}"
    p.add_text(title, position="upper_edge", font_size=fit(title, w, largest=text_size(h, 1 / 48)), color="black")
    view(p, zoom=0.85)
    return p
