"""The stock a job's earlier operations leave, as a rest operation plans from it and a finish takes it.

The block is covered by a grid of cells, each at the block's top; every
earlier operation's moves (feeds, plunges and rapids alike) are pressed into
it with its tool's own shape (:func:`lagsym.verify.press_moves`, the
simulated cut ``lagsym verify --job`` runs).  The result is the height map a
rest operation cuts from (:class:`lagsym.toolpath.rest.StockMap`), and
what a finishing operation would take of it in one pass (:func:`engagement`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..toolpath.rest import StockMap
from ..toolpath.rough import Stock
from ..verify import height_map_axes, press_moves

__all__ = ["stock_left", "REST_CELLS", "Engagement", "engagement"]

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


@dataclass(frozen=True)
class Engagement:
    """The thickest layer of stock above the surface (less the stock to leave), normal to it, and where (mm)."""

    most_mm: float
    x_mm: float
    y_mm: float

    @property
    def stated(self) -> str:
        """``most_mm`` rounded up to the hundredth, as reports and headers state it (``'0.46'``)."""
        return f"{math.ceil(round(self.most_mm * 100, 6)) / 100:.2f}"


def engagement(left: StockMap, evaluator, placement, stock_to_leave_mm: float = 0.0) -> Engagement:
    """What a finish takes of the stock ``left`` in one pass, at most: the layer above the surface, normal to it.

    At each cell of the map over the surface's box, the stock's height less
    the surface's, times the cosine of the surface's slope there (the
    layer's thickness normal to the surface where the surface is locally
    flat), less the stock the finish leaves, plus the sine of the slope
    times the cell's size: between the cells' centres the surface may fall
    by that much under stock as high (a terrace's edge).  A ball finishing
    over it takes no more: it leaves that stock and its cusps.
    ``evaluator`` is the surface's
    (:func:`lagsym.toolpath.dropcutter.evaluator_of`), ``placement`` the
    job's.

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> from lagsym.lagrange import lagrange_surface
    >>> from lagsym.machine import Placement
    >>> from lagsym.toolpath.dropcutter import evaluator_of
    >>> ev = evaluator_of(lagrange_surface(grid_from_table([0, 10], [0, 10], [[0, 0], [10, 10]])))  # z = x
    >>> left = StockMap(np.arange(0.0, 10.5, 0.5), np.arange(0.0, 10.5, 0.5), np.full((21, 21), 6.0))
    >>> e = engagement(left, ev, Placement())
    >>> round(e.most_mm, 4), e.x_mm   # 6 mm above x = 0 on a 45 degree slope, plus 0.5 mm of its fall
    (4.5962, 0.0)
    """
    x0, x1, y0, y1 = placement.box_mm(evaluator.bounds)
    xs, ys = left.xs_mm, left.ys_mm
    i = np.flatnonzero((xs >= x0) & (xs <= x1))
    j = np.flatnonzero((ys >= y0) & (ys <= y1))
    if not len(i) or not len(j):
        return Engagement(0.0, float("nan"), float("nan"))
    gx, gy = np.meshgrid(xs[i], ys[j], indexing="ij")
    u, v = placement.to_surface(gx.ravel(), gy.ravel())
    f = placement.height_mm(evaluator.fast_points(u, v))
    g = np.hypot(evaluator.fast_points(u, v, 1, 0), evaluator.fast_points(u, v, 0, 1))
    w = np.sqrt(1.0 + g * g)
    cell = max(xs[1] - xs[0], ys[1] - ys[0])
    layer = (left.heights_mm[np.ix_(i, j)].ravel() - f) / w - stock_to_leave_mm + g / w * cell
    k = int(np.argmax(layer))
    return Engagement(max(float(layer[k]), 0.0), float(gx.ravel()[k]), float(gy.ravel()[k]))
