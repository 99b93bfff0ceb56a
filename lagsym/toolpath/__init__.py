"""Raster toolpaths with gouge-free cutter locations.

The pipeline follows OpenCAMLib's four steps, each its own module:

1. **path pattern** (:mod:`.pattern`, :func:`raster_pattern`): a zig-zag of
   rows along x or y over the control points' box, side step and forward step
   in millimetres;
2. **cutter locations** (:mod:`.dropcutter`, :func:`drop_cutter`): at each
   ``(x, y)`` the tool is lowered until it touches the exact surface anywhere
   under it;
3. **filtering** (:mod:`.filter`, :func:`filter_rows`): with a chordal
   tolerance, points whose removal keeps the moves within the tolerance of the
   true cutter path go; :mod:`.chordal` bounds and checks how far the true
   path rises above each move, and the moves are lifted by it;
4. the program text, in :mod:`lagsym.post`.

:mod:`.plan` puts the steps together (:func:`plan_toolpath`, :class:`Toolpath`);
:mod:`.waterline` plans contours at constant heights instead, or both split
by slope (:func:`plan_strategy`).

Terms are used as in CAM: the *cutter location* (CL) is the programmed point,
here the tool tip; the *cutter contact* (CC) point is where the tool touches
the surface.
"""

from __future__ import annotations

from .dropcutter import CL_MARGIN, drop_cutter
from .filter import filter_rows
from .pattern import raster_pattern, scallop_stepover
from .plan import Toolpath, plan_toolpath
from .waterline import STRATEGIES, plan_strategy

__all__ = [
    "Toolpath",
    "raster_pattern",
    "drop_cutter",
    "filter_rows",
    "scallop_stepover",
    "plan_toolpath",
    "plan_strategy",
    "STRATEGIES",
    "CL_MARGIN",
]
