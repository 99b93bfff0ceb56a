"""The part after each stage of a job: the simulated height map of the block, coloured by material left."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import InputError
from .backend import DEFAULT_WINDOW_SIZE, new_plotter
from .checks import check_window_size
from .meshes import scalar_mesh
from .style import BAR_COLUMN, axis_labels, bar_column, fit, text_size, view, z_factor, z_note

__all__ = ["machined_figure", "LEFT_CMAP", "MAX_DRAWN_CELLS"]

LEFT_CMAP = "plasma"
MAX_DRAWN_CELLS = 250  # cells drawn along each side at most: a finer height map is drawn every k-th cell


def machined_figure(part, *, stages: Sequence[int] | None = None, left_max_mm: float | None = None,
                    z_exaggeration: float | None = None, title: str | None = None,
                    window_size: Sequence[int] = DEFAULT_WINDOW_SIZE, off_screen: bool | None = None):
    """The block after each stage of a simulated job, coloured by the material left above the exact surface.

    The counterpart of the paper's photographs of machined parts (its Figures
    13 and 15).  Each panel is the height map after one stage
    (:class:`lagsym.machined.MachinedPart`), one colour scale for all: dark
    where the part is finished, bright where material stands above it; the
    block beyond the box of the control points, where no part lies, is grey.

    Parameters
    ----------
    part : MachinedPart
        A job simulated from its block (:func:`lagsym.machined.machine_part`).
    stages : sequence of int, optional
        Which stages to draw (default all), in order.
    left_max_mm : float, optional
        Top of the colour scale (default: the most material left after the
        first stage drawn, at least 0.1 mm), so the last stage's fine
        differences are not lost in the first's large ones; clipped above.
    z_exaggeration : float, optional
        Draw z this many times its true size; default as in
        :func:`~lagsym.plot.surface_figure`.
    title : str, optional
        Defaults to one naming each stage's tool.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    chosen = list(range(len(part.stages))) if stages is None else [int(k) for k in stages]
    if not chosen or any(not 0 <= k < len(part.stages) for k in chosen):
        raise InputError(f"stages {chosen!r}: the job has stages 0 to {len(part.stages) - 1}")
    xs, ys = np.asarray(part.xs_mm), np.asarray(part.ys_mm)
    kx, ky = max(1, -(-len(xs) // MAX_DRAWN_CELLS)), max(1, -(-len(ys) // MAX_DRAWN_CELLS))
    xs, ys = xs[::kx], ys[::ky]
    surf = np.asarray(part.surface_mm)[::kx, ::ky]
    maps = [np.asarray(part.stages[k].cut_mm)[::kx, ::ky] for k in chosen]
    lefts = [np.where(np.isfinite(surf), m - surf, np.nan) for m in maps]
    top = left_max_mm if left_max_mm is not None else max(float(np.nanmax(lefts[0])), 0.1)
    factor = z_factor(z_exaggeration, np.ptp(xs), np.ptp(ys), float(part.top_mm - min(np.min(m) for m in maps)))
    n = len(chosen)
    w, h = check_window_size(window_size)
    p = new_plotter(shape=(1, n + 1), window_size=(w, h), off_screen=off_screen, col_weights=[1.0] * n + [BAR_COLUMN])
    panel = w / (n + BAR_COLUMN)
    name = "left (mm)"
    labels = [f"after T{part.stages[k].tool_number} {part.stages[k].tool.label}\n"
              f"{part.stages[k].left_mm:.3g} mm left at most" for k in chosen]
    font = fit("\n".join(labels + [z_note(factor)]), panel, largest=text_size(h, 1 / 40))
    actor = None
    for col, (m, left, label) in enumerate(zip(maps, lefts, labels)):
        p.subplot(0, col)
        actor = p.add_mesh(scalar_mesh(xs, ys, m, name, np.clip(left, 0.0, top)), scalars=name, cmap=LEFT_CMAP,
                           clim=(0.0, top), nan_color="lightgrey", smooth_shading=True, show_scalar_bar=False)
        p.set_scale(zscale=factor)
        axis_labels(p, "mm", font_size=text_size(h, 1 / 60))
        p.add_text(label if title is None or col else f"{title}\n{label}", position="upper_edge", font_size=font,
                   color="black")
        view(p, zoom=0.75)
    bar_column(p, 0, n, actor.mapper, name, h)
    return p
