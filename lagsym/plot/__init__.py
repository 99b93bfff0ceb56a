"""Pictures of curves, surfaces, basis functions, comparisons and toolpaths (pyvista).

This is the only package that imports pyvista, and it does so inside the
functions that draw, so importing :mod:`lagsym` (or this package) never loads
VTK.  Each ``*_figure`` function takes values (a surface, a curve, plain
arrays) and returns a new :class:`pyvista.Plotter`; nothing here touches
pyvista's global theme.  :func:`save_figure` renders a plotter to an image
file atomically, and :func:`deviation_map` draws and saves in one call.

Rendering needs no display.  Where there is none (no ``DISPLAY`` on Linux),
:func:`rendering_backend` picks a way to render offscreen once per process:
VTK's EGL window on Mesa, else OSMesa, else a private Xvfb server that lives
as long as the process.

Every figure is offscreen when there is no display, and shows in Jupyter as a
static image (the ``static`` backend), which also works when a notebook is run
headless.

Array conventions follow :func:`lagsym.evaluate.evaluate_grid`: a height array
``Z`` sampled on the axes ``x`` and ``y`` has ``Z[i, j] = F(x[i], y[j])``.

The modules, one concern each:

- :mod:`~lagsym.plot.backend`: the render backend (display, EGL, OSMesa or
  Xvfb) and the one factory of plotters;
- :mod:`~lagsym.plot.surface`: a surface, a curve and their basis functions;
- :mod:`~lagsym.plot.compare`: methods side by side, and deviation maps;
- :mod:`~lagsym.plot.growth`: the deviation against the degree (Figure 11);
- :mod:`~lagsym.plot.toolpath`: a cutter path over its surface;
- :mod:`~lagsym.plot.residuals`: a fitted surface and its residuals;
- :mod:`~lagsym.plot.machined`: the block after each stage of a job, coloured
  by the material left;
- :mod:`~lagsym.plot.output`: image formats and writing images;
- :mod:`~lagsym.plot.inline`: the rich display of a surface or a curve in
  Jupyter (imported on the first display, not here);
- :mod:`~lagsym.plot.style`, :mod:`~lagsym.plot.meshes` and
  :mod:`~lagsym.plot.checks`: the look, the pyvista data and the argument
  checks the figures share.
"""

from __future__ import annotations

from .backend import DEFAULT_WINDOW_SIZE, rendering_backend
from .compare import DEVIATION_WINDOW_SIZE, compare_figure, deviation_figure
from .growth import DegreeGrowth, degree_growth, growth_figure
from .machined import machined_figure
from .output import IMAGE_FORMATS, deviation_map, image_format, save_figure
from .style import BASIS_CMAP, DEVIATION_CMAP, FEED_COLOR, NET_COLOR, POINT_COLOR, RAPID_COLOR, SURFACE_CMAP
from .residuals import residuals_figure
from .surface import basis_figure, curve_basis_figure, curve_figure, surface_figure
from .toolpath import toolpath_figure

__all__ = [
    "surface_figure",
    "curve_figure",
    "basis_figure",
    "compare_figure",
    "toolpath_figure",
    "machined_figure",
    "residuals_figure",
    "deviation_figure",
    "deviation_map",
    "curve_basis_figure",
    "growth_figure",
    "degree_growth",
    "DegreeGrowth",
    "save_figure",
    "image_format",
    "rendering_backend",
    "IMAGE_FORMATS",
    "DEFAULT_WINDOW_SIZE",
    "DEVIATION_WINDOW_SIZE",
    "SURFACE_CMAP",
    "DEVIATION_CMAP",
    "BASIS_CMAP",
    "POINT_COLOR",
    "NET_COLOR",
    "FEED_COLOR",
    "RAPID_COLOR",
]
