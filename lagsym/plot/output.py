"""Writing a figure to an image file: the formats, and the atomic write."""

from __future__ import annotations

import io
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io import atomic_write
from .compare import DEVIATION_WINDOW_SIZE, deviation_figure

__all__ = ["IMAGE_FORMATS", "image_format", "save_figure", "deviation_map"]

IMAGE_FORMATS = ("png", "jpg", "jpeg", "tif", "tiff", "bmp")


def image_format(path: str | os.PathLike) -> str:
    """The image format for ``path``, from its suffix (one of :data:`IMAGE_FORMATS`).

    Examples
    --------
    >>> image_format("surface.PNG"), image_format("a/b.jpg")
    ('png', 'jpeg')
    """
    path = Path(path)
    suffix = path.suffix.lower().lstrip(".")
    if suffix not in IMAGE_FORMATS:
        raise InputError(f"{path}: cannot tell the image format from {path.suffix or 'no suffix'!r}; "
                         f"use one of: {', '.join('.' + f for f in IMAGE_FORMATS)}")
    return {"jpg": "jpeg", "tif": "tiff"}.get(suffix, suffix)


def save_figure(plotter, path: str | os.PathLike, *, close: bool = True) -> Path:
    """Render ``plotter`` and write the image to ``path`` atomically.

    The format follows the file's suffix, one of :data:`IMAGE_FORMATS`.

    Parameters
    ----------
    plotter : pyvista.Plotter
        A plotter from one of the ``*_figure`` functions.
    path : str or path-like
        Where to write.
    close : bool
        Close the plotter afterwards (it cannot render again).

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    from PIL import Image

    path = Path(path)
    fmt = image_format(path)
    img = plotter.screenshot(return_img=True)
    if close:
        plotter.close()
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(img)).save(buf, format=fmt)
    with atomic_write(path, "wb") as f:
        f.write(buf.getvalue())
    return path


def deviation_map(x, y, deviations: Mapping[str, np.ndarray], path: str | os.PathLike, *, reference: str = "z_f",
                  units: str = "mm", window_size: Sequence[int] = DEVIATION_WINDOW_SIZE) -> Path:
    """Draw :func:`deviation_figure` (``d = z_f - z_a``) offscreen and write it to ``path``; returns ``path``."""
    figure = deviation_figure(x, y, deviations, reference=reference, units=units, window_size=window_size,
                              off_screen=True)
    return save_figure(figure, path)
