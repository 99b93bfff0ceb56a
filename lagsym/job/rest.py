"""The stock a job's earlier operations leave, as a rest operation plans from it.

The block is covered by a grid of cells, each at the block's top; every
earlier operation's moves (feeds, plunges and rapids alike) are pressed into
it with its tool's own shape (:func:`lagsym.verify.press_moves`, the
simulated cut ``lagsym verify --job`` runs).  The result is the height map a
rest operation cuts from (:class:`lagsym.toolpath.rest.StockMap`).
"""

from __future__ import annotations

import numpy as np

from ..toolpath.rest import StockMap
from ..toolpath.rough import Stock
from ..verify import height_map_axes, press_moves

__all__ = ["stock_left", "REST_CELLS"]

REST_CELLS = 400
"""Cells along the block's longer side of the stock map a rest operation plans from (a 0.2 mm cell for 80 mm)."""


def stock_left(operations, stock: Stock, cell_mm: float | None = None) -> StockMap:
    """The height map of ``stock`` after the planned ``operations`` (:class:`~lagsym.job.Operation`, in order).

    Examples
    --------
    >>> from lagsym.machine import Tool
    >>> from types import SimpleNamespace
    >>> slot = SimpleNamespace(points_mm=np.array([[5.0, -5.0, 8.0], [5.0, 15.0, 8.0]]),
    ...                        tool=SimpleNamespace(tool=Tool("flat", 2.0)))
    >>> left = stock_left([slot], Stock(0, 10, 0, 10, 10.0), cell_mm=0.5)
    >>> float(left.heights_mm.min()), float(left.heights_mm.max()), float(left.heights_mm[:, 0].min())
    (8.0, 10.0, 8.0)
    """
    x0, x1, y0, y1 = stock.box
    xs, ys = height_map_axes(stock.box, cell_mm or max(x1 - x0, y1 - y0) / REST_CELLS, None)
    cut = np.full((len(xs), len(ys)), stock.top_mm)
    for op in operations:
        p = np.asarray(op.points_mm, dtype=float)
        press_moves(cut, xs, ys, p[:-1], p[1:], op.tool.tool, max_contacts=None)
    return StockMap(xs, ys, cut)
