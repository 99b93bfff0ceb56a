"""How many drop-cutter points a finishing plan takes, foreseen before the plan runs, and its refusal past the limit.

A roughing path's size is its rows times samples per row times levels, a
finishing raster's its rows times the fine samples along a row; a scallop
height's rows are bounded from below before they are walked
(:func:`.scallop.scallop_levels`); waterline and steep-and-shallow count the
grid, the contour crossings (:func:`.contours.crossings_at_least`) and the
shallow part's rows.  Each figure is a lower bound, so nothing refused would
have fitted.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ToolpathError
from ..machine import RasterSpec, Tool
from . import chordal
from .contours import CROSSING_POINTS, crossings_at_least
from .scallop import TooManyRows, scallop_levels

__all__ = ["check_points", "check_size", "scallop_rows", "per_row", "too_many", "check_strategy_work", "row_samples",
           "nearest_nodes"]


def scallop_rows(ev, tool: Tool, raster: RasterSpec, reach, *, fine: float, mm_per_unit: float,
                 max_points: int | None):
    """The rows a scallop height asks for, refused (before they are walked where it can be told) past the limit."""
    along = per_row(reach, raster.direction, fine, mm_per_unit)
    try:
        return scallop_levels(ev, raster.direction, tool.radius_mm, raster.scallop_mm, mm_per_unit,
                              max_rows=None if max_points is None else max(max_points // along, 1))
    except TooManyRows as e:
        raise too_many(e.at_least, along, max_points, f"side steps down to {e.smallest_mm:.3g} mm for a scallop "
                       f"height of {raster.scallop_mm:g} mm", fine, at_least=True) from None


def per_row(bounds, direction: str, fine: float, scale: float) -> int:
    """The fine samples along one row over ``bounds``."""
    x0, x1, y0, y1 = (float(v) for v in bounds)
    return math.ceil((x1 - x0 if direction == "x" else y1 - y0) * scale / fine) + 1


def too_many(rows: int, along: int, max_points: int, steps: str, fine: float, *, at_least: bool = False):
    """The refusal of a plan of ``rows`` rows of ``along`` fine samples, more than ``max_points``."""
    some = "at least " if at_least else ""
    return ToolpathError(
        f"{some}{rows} rows of {along} fine samples is {some}{rows * along:.3g} drop-cutter points, more than the "
        f"limit of {max_points:.3g} ({steps}, sampling step {fine:g} mm); use larger steps or raise the limit "
        f"(--max-points)")


def check_size(bounds, direction: str, stepover: float, fine: float, scale: float, max_points: int | None) -> None:
    """Refuse a plan whose fine samples (rows times samples per row) would exceed ``max_points``."""
    if max_points is None:
        return
    x0, x1, y0, y1 = (float(v) for v in bounds)
    rows = math.ceil((y1 - y0 if direction == "x" else x1 - x0) * scale / stepover) + 1
    along = per_row(bounds, direction, fine, scale)
    if rows * along > max_points:
        raise too_many(rows, along, max_points, f"side step {stepover:g} mm", fine)


def check_strategy_work(f, steep, shallow, d0: float, raster: RasterSpec, *, ev, max_points: int | None,
                        strategy: str, mpu: float) -> None:
    """Refuse, before its passes are planned, a waterline or steep-and-shallow plan whose drop-cutter points
    surely exceed ``max_points``.

    ``f`` is the strategy's grid of cutter locations (``f.z``, ``f.xs``,
    ``f.ys``), ``steep`` and ``shallow`` its regions (``shallow`` None for
    waterline alone), ``d0`` the flat floor's step (mm).

    The grid's points are taken already; the contours take at least
    :data:`.contours.CROSSING_POINTS` points at each of the crossings
    :func:`.contours.crossings_at_least` counts; the raster rows are at most
    ``d0`` apart, so at least ``floor(g / d0)`` of them fall in each grid
    column ``g`` wide and sample the shallow nodes of that column at the
    row's fine step.
    """
    if max_points is None:
        return
    crossings = crossings_at_least(f, steep, d0)
    points = f.z.size + CROSSING_POINTS * crossings
    if shallow is not None:
        a_axis, c_axis = (f.xs, f.ys) if raster.direction == "x" else (f.ys, f.xs)
        region = shallow if raster.direction == "x" else shallow.T
        n_along = row_samples(a_axis, chordal.tolerance_step(ev, raster.chordal_tolerance_mm, mpu) / mpu).size
        per_column = region[nearest_nodes(a_axis, n_along), 1:-1].sum(axis=0)
        points += int(per_column.sum()) * int(math.floor((c_axis[1] - c_axis[0]) * mpu / d0))
    if points > max_points:
        raise ToolpathError(
            f"the {strategy} strategy at a scallop height of {raster.scallop_mm:g} mm takes at least {points:.3g} "
            f"drop-cutter points ({crossings} contour crossings, levels at most {d0:.3g} mm apart), more than the "
            f"limit of {max_points:.3g}; ask for a larger scallop height or raise the limit (--max-points)")


def row_samples(a_axis, fine: float) -> np.ndarray:
    """The fine samples along a raster row over ``a_axis`` (surface units, ``fine`` apart at most)."""
    return np.linspace(a_axis[0], a_axis[-1], max(int(math.ceil((a_axis[-1] - a_axis[0]) / fine)) + 1, 2))


def nearest_nodes(a_axis, n: int) -> np.ndarray:
    """The grid node along ``a_axis`` nearest each of ``n`` fine samples over it."""
    along = np.linspace(a_axis[0], a_axis[-1], n)
    return np.clip(np.rint((along - a_axis[0]) / (a_axis[1] - a_axis[0])).astype(int), 0, len(a_axis) - 1)


def check_points(stock, tool: Tool, spec, levels: int, max_points: int | None, option: str) -> None:
    """Refuse a roughing path over ``stock`` (a :class:`.rough.Stock`) of more than ``max_points`` (rows times
    samples per row, times ``levels``; ``spec`` a :class:`.rough.RoughSpec`) before making it."""
    if max_points is None:
        return
    along, cross = ((stock.x1 - stock.x0, stock.y1 - stock.y0) if spec.direction == "x"
                    else (stock.y1 - stock.y0, stock.x1 - stock.x0))
    # floats: a side step of 1e-308 mm gives a count no int conversion takes, and it is refused all the same
    rows = _whole(cross / spec.stepover_mm) + 1
    samples = _whole((along + 2 * (spec.clearance_mm + tool.radius_mm)) / spec.step_mm) + 1
    total = rows * samples * levels
    if total > max_points:
        what = f"{rows:.4g} rows of {samples:.4g} samples" + (f" at {levels} levels" if levels > 1 else "")
        raise ToolpathError(f"{what} is {total:.3g} points, more than the limit of {max_points:.3g} (side step "
                            f"{spec.stepover_mm:g} mm, step {spec.step_mm:g} mm, step-down {spec.stepdown_mm:g} mm); "
                            f"use larger steps or raise the limit ({option})")


def _whole(v: float) -> float:
    """``ceil(v)``, kept a float: an infinity stays one."""
    return float(math.ceil(v)) if math.isfinite(v) else v
