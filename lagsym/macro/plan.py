"""The raster a macro program runs, and the points it should produce, computed on the PC.

A macro raster is the control points' box, scaled by ``scale`` and moved by
``origin_mm``, cut in rows along ``direction`` at the side step, each row
sampled at the forward step.  Rows and points are counted with integers: the
``j``-th row sits at ``r0 + j * dr`` and the ``k``-th point at ``p0 + k * dp``,
so no error accumulates; the last row and the last point, which usually
overshoot the box, are clamped to its edge.  Rows alternate in direction
(zig-zag); a reversed row visits the same positions as a forward one.

Everything here is in program units (millimetres, or inches for ``G20``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from ..errors import ToolpathError
from ..lagrange import LagrangeSurface
from ..machine import MachineSettings, RasterSpec, Tool

__all__ = ["Axis", "MacroRaster", "macro_raster", "raster_positions", "sample_positions", "planned_points",
           "points_at", "exact"]


def exact(value) -> Fraction:
    """A setting as an exact number: a float is read as the decimal it prints as (0.1 is 1/10)."""
    if isinstance(value, Fraction):
        return value
    if isinstance(value, float):
        return Fraction(repr(value))
    return Fraction(value)


@dataclass(frozen=True)
class Axis:
    """One counted axis of the raster: positions ``start + k * step`` for ``k = 0 .. count``, clamped to ``end``.

    Attributes
    ----------
    letter : str
        ``"X"`` or ``"Y"``.
    start, end, step : Fraction
        First position, the box edge, and the spacing, in program units.
    count : int
        Index of the last position (there are ``count + 1``).
    """

    letter: str
    start: Fraction
    end: Fraction
    step: Fraction
    count: int

    @property
    def clamped(self) -> bool:
        """True when ``start + count * step`` passes the edge and the last position is clamped."""
        return self.start + self.count * self.step > self.end

    def positions(self) -> np.ndarray:
        """Every position on the axis, as floats in program units."""
        k = np.arange(self.count + 1, dtype=float)
        return np.minimum(float(self.start) + k * float(self.step), float(self.end))


def _axis(letter: str, lo: Fraction, hi: Fraction, step: Fraction) -> Axis:
    length = hi - lo
    if step <= 0:
        raise ToolpathError(f"{letter} step {float(step)!r} must be positive")
    count = max(math.ceil(length / step), 1)
    if count > 10**6:
        raise ToolpathError(f"{letter} step {float(step)!r} gives {count} positions over {float(length)!r}; "
                            "use a larger step")
    return Axis(letter=letter, start=lo, end=hi, step=step, count=count)


@dataclass(frozen=True)
class MacroRaster:
    """A zig-zag raster with integer-counted rows and points.

    Attributes
    ----------
    direction : str
        ``"x"``: rows run along X, one row per Y position; ``"y"``: the reverse.
    rows : Axis
        The axis across the rows (Y for ``direction="x"``).
    points : Axis
        The axis along a row (X for ``direction="x"``).
    """

    direction: str
    rows: Axis
    points: Axis

    @property
    def size(self) -> int:
        """Number of points the raster visits."""
        return (self.rows.count + 1) * (self.points.count + 1)


def macro_raster(surface: LagrangeSurface, settings: MachineSettings, raster: RasterSpec) -> MacroRaster:
    """The raster over the scaled control-point box, in program units.

    Only a fixed side step and forward step make sense for a program whose loop
    counts are fixed: ``raster.stepover_mm`` and ``raster.step_mm`` are required.
    """
    if raster.stepover_mm is None or raster.step_mm is None:
        raise ToolpathError("a macro raster needs a fixed side step (--stepover) and forward step (--step)")
    x0, x1, y0, y1 = surface.grid.bounds
    s = exact(settings.scale) * exact(settings.unit_factor)
    ox, oy = (exact(v) * exact(settings.unit_factor) for v in settings.origin_mm[:2])
    uf = exact(settings.unit_factor)
    xa = (x0 * s + ox, x1 * s + ox)
    ya = (y0 * s + oy, y1 * s + oy)
    side, forward = exact(raster.stepover_mm) * uf, exact(raster.step_mm) * uf
    if raster.direction == "x":
        return MacroRaster("x", rows=_axis("Y", *ya, side), points=_axis("X", *xa, forward))
    return MacroRaster("y", rows=_axis("X", *xa, side), points=_axis("Y", *ya, forward))


def raster_positions(plan: MacroRaster) -> tuple[np.ndarray, np.ndarray]:
    """The (X, Y) of every raster point in the order the program visits them, in program units."""
    rows = plan.rows.positions()
    pts = plan.points.positions()
    r = np.repeat(rows, len(pts))
    p = np.concatenate([pts if j % 2 == 0 else pts[::-1] for j in range(len(rows))])
    return (p, r) if plan.direction == "x" else (r, p)


def sample_positions(plan: MacroRaster, limit: int = 401) -> tuple[np.ndarray, np.ndarray]:
    """(X, Y) of raster positions on up to ``limit`` rows by ``limit`` points, evenly spread, edges included.

    For checks over the whole raster (clearance, gouging) that must not grow
    with a fine step.
    """
    def pick(axis: Axis) -> np.ndarray:
        ks = np.unique(np.linspace(0, axis.count, min(axis.count + 1, limit)).round().astype(int))
        return np.minimum(float(axis.start) + ks * float(axis.step), float(axis.end))

    r, p = np.meshgrid(pick(plan.rows), pick(plan.points), indexing="ij")
    return (p.ravel(), r.ravel()) if plan.direction == "x" else (r.ravel(), p.ravel())


def points_at(surface: LagrangeSurface, settings: MachineSettings, tool: Tool | None, x, y) -> np.ndarray:
    """The programmed points (N, 3) for raster positions (x, y), in program units.

    Z is the surface height at each position (stable evaluation, within 1e-12
    of the exact value), scaled, plus the origin and the stock to leave.  For a
    ball-end tool with a diameter the point is the tool tip of a ball whose
    centre sits one radius (plus stock) off the surface along its normal (see
    :mod:`lagsym.macro.ballend`).
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if tool is not None and tool.shape == "ball" and tool.diameter_mm > 0:
        from .ballend import tip_points

        return tip_points(surface, settings, tool, x, y)
    s = float(settings.scale) * settings.unit_factor
    ox, oy, oz = (v * settings.unit_factor for v in settings.origin_mm)
    z = surface.evaluate((x - ox) / s, (y - oy) / s) * s + oz + settings.stock_to_leave_mm * settings.unit_factor
    return np.column_stack([x, y, z])


def planned_points(surface: LagrangeSurface, settings: MachineSettings, raster: RasterSpec,
                   tool: Tool | None = None) -> np.ndarray:
    """The points a macro program should move through, computed on the PC: an (N, 3) array in program units.

    Every raster position in the order the program visits them, through
    :func:`points_at`.  The program's first feed move (the plunge) ends at the
    first of these points.
    """
    plan = macro_raster(surface, settings, raster)
    return points_at(surface, settings, tool, *raster_positions(plan))
