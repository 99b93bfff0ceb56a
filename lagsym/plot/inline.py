"""The rich display of a surface or a curve in Jupyter: its equation and a small static figure.

:func:`rich_html` is the ``text/html`` formatter that ``import lagsym``
registers with a running IPython shell (or ``%load_ext lagsym`` does later).
It returns the equation ``_repr_latex_`` gives, as display math (Jupyter
typesets ``$$...$$`` in HTML output), followed by a PNG thumbnail rendered
offscreen and embedded in the HTML, so the picture needs no kernel to be seen
again.  This module is imported only when a value is first displayed.

Where nothing can render (no OpenGL, no Xvfb), :func:`rich_html` returns None
and Jupyter falls back to the LaTeX alone: a display must never put a
traceback into a notebook.  ``plot.surface_figure(surface).show()`` then
raises the error that says what to install.
"""

from __future__ import annotations

import base64
import functools
import html
import io
import re
from collections.abc import Sequence

import numpy as np

from ..errors import RenderError
from ..lagrange import LagrangeCurve, LagrangeSurface
from .backend import new_plotter, rendering_backend
from .checks import check_window_size
from .meshes import scalar_mesh
from .style import SURFACE_CMAP, bar_args, title_for, units_of, view, z_factor, z_note
from .surface import add_control, curve_figure, sampled_surface

__all__ = ["THUMBNAIL_SIZE", "surface_thumbnail", "curve_thumbnail", "thumbnail_png", "can_render", "rich_html"]

THUMBNAIL_SIZE = (320, 240)  # beside the equation, about the size of a figure in a paper's column
_SAMPLES = 41  # enough for a smooth shading at this size, quick to evaluate for any degree


def surface_thumbnail(surface, *, window_size: Sequence[int] = THUMBNAIL_SIZE):
    """A small shaded picture of ``surface`` with its control net, for the rich display.

    No axes grid (its ticks pile up at this size): a colour bar reads the
    heights, and one line names the box of the control points and, when z is
    drawn stretched or squeezed, by how much.

    Returns
    -------
    pyvista.Plotter
        Offscreen, :data:`THUMBNAIL_SIZE` by default.
    """
    w, h = check_window_size(window_size)
    xs, ys, zz = sampled_surface(surface, _SAMPLES)
    units = units_of(surface, None)
    p = new_plotter(window_size=(w, h), off_screen=True)
    name = f"z ({units})"
    bar = bar_args(name, h, title_font_size=11, label_font_size=10, position_x=0.82, width=0.08, n_labels=3)
    p.add_mesh(scalar_mesh(xs, ys, zz, name), scalars=name, cmap=SURFACE_CMAP, smooth_shading=True,
               scalar_bar_args=bar)
    g = surface.grid
    add_control(p, g.x_array, g.y_array, g.z_array, size=7.0)
    factor = z_factor(None, np.ptp(xs), np.ptp(ys), float(np.ptp(zz)))
    p.set_scale(zscale=factor)
    note = f"x {xs[0]:.3g} to {xs[-1]:.3g}, y {ys[0]:.3g} to {ys[-1]:.3g} {units}"
    if z_note(factor):
        note = f"{note}\n{z_note(factor)}"
    p.add_text(note, position="upper_left", font_size=9, color="black")
    view(p, zoom=1.0)
    return p


def curve_thumbnail(curve, *, window_size: Sequence[int] = THUMBNAIL_SIZE):
    """A small line plot of ``curve`` through its points (:func:`~lagsym.plot.curve_figure`, untitled)."""
    return curve_figure(curve, title="", window_size=window_size, off_screen=True)


def thumbnail_png(value, *, window_size: Sequence[int] = THUMBNAIL_SIZE) -> bytes:
    """The thumbnail of a surface or a curve, rendered offscreen, as PNG bytes.

    Raises
    ------
    RenderError
        When nothing here can render.
    """
    from PIL import Image

    draw = surface_thumbnail if isinstance(value, LagrangeSurface) else curve_thumbnail
    plotter = draw(value, window_size=window_size)
    try:
        img = plotter.screenshot(return_img=True)
    finally:
        plotter.close()
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(img[..., :3])).save(buf, format="png", optimize=True)
    return buf.getvalue()


@functools.cache
def can_render() -> bool:
    """Whether this process can render a figure, asked once (a failed choice of backend costs seconds)."""
    try:
        rendering_backend()
    except RenderError:
        return False
    return True


def _equation_html(latex: str) -> str:
    """``_repr_latex_``'s text as HTML: its formula as display math, a summary's note as text."""
    # "$z = ...$" or, past lagsym.lagrange.LATEX_TERMS terms, "$z = F$ (degree ..., N terms: ``.expr`` ...)".
    formula, _, note = latex[1:].partition("$")
    out = f'<div style="overflow-x: auto">$${html.escape(formula, quote=False)}$$</div>'
    if note.strip():
        text = re.sub(r"``(.+?)``", r"<code>\1</code>", html.escape(note.strip(), quote=False))
        out += f"\n<p>{text}</p>"
    return out


def rich_html(value) -> str | None:
    """The ``text/html`` display of a :class:`LagrangeSurface` or :class:`LagrangeCurve`.

    Returns
    -------
    str or None
        The equation as ``$$...$$`` and a PNG thumbnail in an ``<img>`` tag;
        None (Jupyter shows the LaTeX alone) for any other value and when the
        thumbnail cannot be rendered; where no backend can render, that is
        found once per process, not at every display.
    """
    if not isinstance(value, (LagrangeSurface, LagrangeCurve)) or not can_render():
        return None
    try:
        png = thumbnail_png(value)
    except Exception:  # noqa: BLE001 - a display hook must not fail: IPython would print the traceback
        return None
    w, h = THUMBNAIL_SIZE
    src = base64.b64encode(png).decode("ascii")
    alt = html.escape(title_for(value))
    return (f'<div class="lagsym-display">\n{_equation_html(value._repr_latex_())}\n'
            f'<img src="data:image/png;base64,{src}" width="{w}" height="{h}" alt="{alt}">\n</div>')
