"""Figures of one surface or one curve: the shaded surface, its basis functions, the curve and its basis.

Each ``*_figure`` function takes a surface or a curve and returns a new
:class:`pyvista.Plotter`.  Samples lie on the exact lines of
:func:`lagsym.sampling.axis_lines`, so the control nodes are sampled where
they fall on a line.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..evaluate import basis_matrix, evaluate_curve, evaluate_grid
from ..sampling import axis_lines, sample_grid
from .backend import DEFAULT_WINDOW_SIZE, new_plotter
from .checks import check_samples, check_window_size
from .meshes import pointcloud, scalar_mesh, structured
from .style import (
    BAR_COLUMN,
    BASIS_CMAP,
    CYCLE,
    NET_COLOR,
    POINT_COLOR,
    SURFACE_CMAP,
    axis_labels,
    units_of,
    bar_args,
    bar_column,
    chart_text,
    fit,
    padded,
    text_size,
    title_for,
    view,
    z_factor,
    z_note,
)

__all__ = ["surface_figure", "basis_figure", "curve_figure", "curve_basis_figure", "sampled_surface"]


def sampled_surface(surface, samples: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(xs, ys, Z)``: ``samples`` lines along each axis of the control box, and the heights on them."""
    n = check_samples(samples)
    g = sample_grid(surface, n, n)
    return g.xs, g.ys, evaluate_grid(surface, g.xs, g.ys)


def surface_figure(surface, *, samples: int = 61, units: str | None = None, title: str | None = None,
                   cmap: str = SURFACE_CMAP, control_net: bool = True, scalar_bar: bool = True,
                   z_exaggeration: float | None = None, window_size: Sequence[int] = DEFAULT_WINDOW_SIZE,
                   off_screen: bool | None = None):
    """The shaded surface with its control points and control net (the paper's Figures 6-9).

    Parameters
    ----------
    surface : LagrangeSurface
        The surface to draw, over the box of its control points.
    samples : int
        Samples along each axis.
    units : str
        Length unit shown on the axes and the colour bar.
    title : str, optional
        Defaults to one naming the degree.
    cmap : str
        Colour map for z.
    control_net : bool
        Draw the control points and the net joining them.
    scalar_bar : bool
        Draw the colour bar for z.
    z_exaggeration : float, optional
        Draw z this many times its true size (the ticks still read true
        heights).  Default: chosen so the drawn height lies between a fifth of
        the larger plan side and that side (:func:`lagsym.plot.style.z_scale`);
        the title says when z is not drawn true.  Give 1 for true proportions.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    xs, ys, zz = sampled_surface(surface, samples)
    units = units_of(surface, units)
    w, h = check_window_size(window_size)
    p = new_plotter(window_size=(w, h), off_screen=off_screen)
    name = f"z ({units})"
    p.add_mesh(scalar_mesh(xs, ys, zz, name), scalars=name, cmap=cmap, smooth_shading=True,
               show_scalar_bar=scalar_bar, scalar_bar_args=bar_args(name, h))
    if control_net:
        g = surface.grid
        add_control(p, g.x_array, g.y_array, g.z_array)
    factor = z_factor(z_exaggeration, np.ptp(xs), np.ptp(ys), float(np.ptp(zz)))
    p.set_scale(zscale=factor)
    axis_labels(p, units, font_size=text_size(h, 1 / 45))
    text = title if title is not None else title_for(surface)
    if z_note(factor):
        text = f"{text}\n{z_note(factor)}" if text else z_note(factor)
    p.add_text(text, position="upper_edge", font_size=fit(text, w, largest=text_size(h, 1 / 48)), color="black")
    view(p, zoom=0.85)
    return p


def add_control(p, x, y, z, size: float = 12.0) -> None:
    """The control points ``z[i, k]`` at ``(x[i], y[k])`` as dots, and the net joining them."""
    net = structured(x, y, z)
    p.add_mesh(net.extract_all_edges(), color=NET_COLOR, line_width=2, lighting=False)
    p.add_mesh(pointcloud(np.asarray(net.points)), color=POINT_COLOR, point_size=size,
               render_points_as_spheres=True)


def curve_figure(curve, *, samples: int = 401, units: str | None = None, title: str | None = None,
                 window_size: Sequence[int] = DEFAULT_WINDOW_SIZE, off_screen: bool | None = None):
    """The 1-D interpolant with the points it passes through (the paper's Figures 2-3).

    Parameters
    ----------
    curve : LagrangeCurve
        The curve, drawn over the span of its points.
    samples : int
        Samples along x.
    units : str
        Length unit shown on the axes.
    title : str, optional
        Defaults to one naming the degree.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    import pyvista as pv

    n = check_samples(samples)
    px, py = curve.points.x_array, curve.points.y_array
    xs = axis_lines(curve.points.x[0], curve.points.x[-1], n)
    ys = evaluate_curve(curve, xs)
    p = new_plotter(window_size=window_size, off_screen=off_screen)
    units = units_of(curve, units)
    chart = pv.Chart2D(x_label=f"x ({units})", y_label=f"y ({units})")
    chart.title = title if title is not None else title_for(curve)
    chart.line(xs, ys, color="tab:blue", width=3.0, label="F(x)")
    chart.scatter(px, py, color=POINT_COLOR, size=12, style="o", label="points")
    chart.x_range = padded(xs.min(), xs.max())
    chart.y_range = padded(min(ys.min(), py.min()), max(ys.max(), py.max()))
    chart.legend.visible = False
    chart_text(chart, p.window_size[1])
    p.add_chart(chart)
    return p


def curve_basis_figure(curve, *, samples: int = 401, units: str | None = None,
                       window_size: Sequence[int] = DEFAULT_WINDOW_SIZE, off_screen: bool | None = None):
    """The basis polynomials ``L_i(x)`` of a curve's nodes, each 1 at its own node and 0 at the others.

    Parameters
    ----------
    curve : LagrangeCurve
        Supplies the nodes.
    samples : int
        Samples along x.
    units : str
        Length unit of x.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    import pyvista as pv

    n = check_samples(samples)
    nodes = curve.points.x_array
    xs = axis_lines(curve.points.x[0], curve.points.x[-1], n)
    lx = basis_matrix(nodes, xs)
    p = new_plotter(window_size=window_size, off_screen=off_screen)
    units = units_of(curve, units)
    chart = pv.Chart2D(x_label=f"x ({units})", y_label="L_i(x)")
    chart.title = f"Lagrange basis polynomials of degree {curve.degree} on {len(nodes)} nodes"
    for i in range(len(nodes)):
        color = CYCLE[i % len(CYCLE)]
        chart.line(xs, lx[:, i], color=color, width=2.5, label=f"L{i + 1}(x)")
        chart.scatter(nodes[i:i + 1], [1.0], color=color, size=10, style="o")
    chart.scatter(nodes, np.zeros_like(nodes), color="black", size=6, style="o")
    chart.x_range = padded(xs.min(), xs.max())
    chart.y_range = padded(float(lx.min()), float(lx.max()))
    chart_text(chart, p.window_size[1])
    p.add_chart(chart)
    return p


def basis_figure(surface, *, samples: int = 25, units: str | None = None, window_size: Sequence[int] = DEFAULT_WINDOW_SIZE,
                 off_screen: bool | None = None):
    """The tensor-product basis functions ``L_i(x) L_k(y)`` as small multiples (the paper's Figure 4).

    The panel in column ``i`` and row ``k`` counted from the bottom holds
    ``L_i(x) L_k(y)``, so the panels lie like the nodes in the plane seen from
    above.  All panels share one colour scale, centred on 0; a black dot marks
    the node where the function is 1 (it is 0 at every other node).

    Parameters
    ----------
    surface : LagrangeSurface
        Supplies the nodes.
    samples : int
        Samples along each axis of each panel.
    units : str
        Length unit of x and y, noted in the figure.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    n_s = check_samples(samples)
    g = surface.grid
    nx, ny = g.shape
    lines = sample_grid(g, n_s, n_s)
    xs, ys = lines.xs, lines.ys
    lx = basis_matrix(g.x_array, xs)
    ly = basis_matrix(g.y_array, ys)
    values = np.einsum("ai,bk->ikab", lx, ly)  # values[i, k] = L_i(xs) L_k(ys) on the sample grid
    bound = float(np.abs(values).max())
    scale = max(np.ptp(xs), np.ptp(ys)) / 3 / bound
    units = units_of(surface, units)
    w, h = check_window_size(window_size)
    p = new_plotter(shape=(ny, nx + 1), window_size=(w, h), off_screen=off_screen,
                    col_weights=[1.0] * nx + [BAR_COLUMN])
    font = fit("L5(x) L5(y)", w / (nx + BAR_COLUMN), largest=12)
    actor = None
    for k in range(ny):
        for i in range(nx):
            p.subplot(ny - 1 - k, i)
            actor = p.add_mesh(scalar_mesh(xs, ys, values[i, k], "L"), scalars="L", cmap=BASIS_CMAP,
                               clim=(-bound, bound), smooth_shading=True, show_scalar_bar=False)
            node = np.array([[g.x_array[i], g.y_array[k], 1.0]])
            p.add_mesh(pointcloud(node), color="black", point_size=6, render_points_as_spheres=True)
            p.add_text(f"L{i + 1}(x) L{k + 1}(y)", position="upper_left", font_size=font, color="black")
            p.set_scale(zscale=scale)
            view(p, zoom=1.0)
    p.subplot(ny - 1, 0)
    p.add_text(f"x, y in {units}", position="lower_left", font_size=max(6, font - 2), color="gray")
    bar_column(p, ny // 2, nx, actor.mapper, "L_i L_k", h)
    return p
