"""Rest finishing: a smaller ball's raster only where the earlier tools left material above what it reaches.

A finishing ball cannot reach the bottom of a hollow tighter than itself,
and its rows leave more on steep flanks than on the shallow parts.  A later
finishing operation marked ``rest = true`` plans its own raster over the box
(:func:`~lagsym.toolpath.plan.plan_toolpath`: the exact drop-cutter heights,
its stepover, step and tolerance) and keeps of each row only the runs of
cutter locations where the stock the operations before left
(:class:`~lagsym.toolpath.rest.StockMap`) stands more than ``above_mm``
(:data:`REST_ABOVE_MM` unless the job says) above the tip, measured as
:func:`~lagsym.toolpath.rest.material_under` does (the lowest tip clear of
every cell under the tool), each run with the location either side.  Runs of
a row closer than their way up and down are joined (the tool follows the
row between them).  The tool comes to each run at rapid above the block
(``top_mm``), down at rapid to ``clearance_mm`` above the higher of the run's
first tip and the stock there, at the plunge feed to the tip, cuts the run
and goes straight up at rapid.

So where the stock map shows more than that above this ball's reach, it
passes as its whole raster would and leaves what the raster leaves;
elsewhere it does not cut.  The map holds the stock at its cell centres: a
cusp between them can stand higher than it shows (docs/toolpaths.md gives
what that lets stand on the example).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import freeze_fields
from ..errors import ToolpathError
from .rest import StockMap, cut_runs, material_under
from .rough import FEED, PLUNGE, RAPID

__all__ = ["RestFinish", "rest_finish", "REST_ABOVE_MM"]

REST_ABOVE_MM = 0.02
"""A location is cut where the stock left stands more than this above its tip (a job's ``rest_above``)."""


@dataclass(frozen=True)
class RestFinish:
    """The moves of a rest finish (tip positions, machine mm, and how the tool moves into each: FEED, RAPID or
    PLUNGE of :mod:`lagsym.toolpath.rough`), its runs, and the share of the raster's locations it cuts."""

    points_mm: np.ndarray
    kinds: np.ndarray
    runs: int
    share: float

    def __post_init__(self):
        freeze_fields(self, ("points_mm", "kinds"))


def rest_finish(path, left: StockMap, top_mm: float, clearance_mm: float = 1.0,
                above_mm: float = REST_ABOVE_MM) -> RestFinish:
    """The runs of the raster ``path`` (a :class:`~lagsym.toolpath.Toolpath` of plain points) that cut what the
    stock ``left`` holds above its tips; see the module.  Refused in one line when there are none.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> from lagsym.machine import Tool
    >>> xs = np.arange(0.0, 10.5, 0.5)
    >>> heights = np.where(np.abs(xs - 5) < 1, 0.5, 0.0)[:, None] + np.zeros(5)  # a ridge left across x = 5
    >>> row = SimpleNamespace(points_mm=np.column_stack([xs, np.full(21, 1.0), np.zeros(21)]),
    ...                       rows=np.zeros(21, dtype=int), tool=Tool("ball", 1.0))
    >>> rf = rest_finish(row, StockMap(xs, np.arange(5.0), heights), 10.0, above_mm=0.05)
    >>> rf.runs, rf.points_mm[:, 0].tolist(), rf.kinds.tolist()
    (1, [4.0, 4.0, 4.0, 4.5, 5.0, 5.5, 6.0, 6.0], [1, 1, 2, 0, 0, 0, 0, 1])
    """
    p = np.asarray(path.points_mm, dtype=float)
    rows = np.asarray(path.rows)
    mat = material_under(left, p[:, 0], p[:, 1], path.tool)
    cutting = mat > p[:, 2] + above_mm
    if not cutting.any():
        most = float(np.max(mat - p[:, 2], initial=-np.inf))
        raise ToolpathError(f"nothing left for rest finishing with {path.tool.label}: the stock left stands at most "
                            f"{max(most, 0.0):.3f} mm above what it reaches (less than {above_mm:g} mm)")
    pts, kinds = [], []
    count = 0
    bounds = np.flatnonzero(np.diff(rows)) + 1
    for lo, hi in zip(np.concatenate([[0], bounds]), np.concatenate([bounds, [len(p)]])):
        along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p[lo:hi, :2], axis=0).T))])
        for a, b in cut_runs(cutting[lo:hi], along, 2 * (top_mm - float(p[lo:hi, 2].min()))):
            first, last = p[lo + a], p[lo + b]
            entry = max(float(first[2]), float(mat[lo + a])) + clearance_mm
            pts += [(first[0], first[1], top_mm)]
            kinds += [RAPID]
            if entry < top_mm:
                pts.append((first[0], first[1], entry))
                kinds.append(RAPID)
            pts += [tuple(first)] + [tuple(q) for q in p[lo + a + 1:lo + b + 1]] + [(last[0], last[1], top_mm)]
            kinds += [PLUNGE] + [FEED] * (b - a) + [RAPID]
            count += 1
    return RestFinish(np.array(pts, dtype=float), np.array(kinds, dtype=np.int8), count,
                      float(cutting.mean()))

