"""The raster a macro program counts on the control: integer-counted rows and points over the scaled box.

A macro raster is the control points' box, scaled by ``scale`` and moved by
``origin_mm``, cut in rows along ``direction`` at the side step, each row
sampled at the forward step; the box edges are moved inward onto the
program's last decimal.  Rows and points are counted with integers: the
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
from ..machine import MachineSettings, RasterSpec
from ..values import as_exact
from ._placement import placement

__all__ = ["Axis", "MacroRaster", "macro_raster", "raster_positions", "sample_positions"]


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
    # The step is positive: RasterSpec checks it.
    length = hi - lo
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
    place = placement(settings)
    s, (ox, oy, _) = place.scale, place.origin
    unit = Fraction(1, 10 ** settings.digits)
    xa = _inward(x0 * s + ox, x1 * s + ox, unit)
    ya = _inward(y0 * s + oy, y1 * s + oy, unit)
    side = as_exact(raster.stepover_mm, "side step") * place.per_mm
    forward = as_exact(raster.step_mm, "forward step") * place.per_mm
    for what, step in (("side step", side), ("forward step", forward)):
        if step < unit:  # the control would repeat the previous block, to the program's last decimal
            raise ToolpathError(f"{what} {float(step):g} is below the program's resolution {float(unit):g} "
                                f"({settings.digits} decimals in {settings.units}): use a larger step or --decimals")
    if raster.direction == "x":
        return MacroRaster("x", rows=_axis("Y", *ya, side), points=_axis("X", *xa, forward))
    return MacroRaster("y", rows=_axis("X", *xa, side), points=_axis("Y", *ya, forward))


def _inward(lo: Fraction, hi: Fraction, unit: Fraction) -> tuple[Fraction, Fraction]:
    """The box edges on the program's resolution, moved inward: a rounded position then stays inside the box."""
    a, b = math.ceil(lo / unit) * unit, math.floor(hi / unit) * unit
    return (a, b) if a < b else (lo, hi)


def raster_positions(raster: MacroRaster) -> tuple[np.ndarray, np.ndarray]:
    """The (X, Y) of every raster point in the order the program visits them, in program units."""
    rows = raster.rows.positions()
    pts = raster.points.positions()
    r = np.repeat(rows, len(pts))
    p = np.concatenate([pts if j % 2 == 0 else pts[::-1] for j in range(len(rows))])
    return (p, r) if raster.direction == "x" else (r, p)


def sample_positions(raster: MacroRaster, limit: int = 401) -> tuple[np.ndarray, np.ndarray]:
    """(X, Y) of raster positions on up to ``limit`` rows by ``limit`` points, evenly spread, edges included.

    For checks over the whole raster (clearance, gouging) that must not grow
    with a fine step.
    """
    def pick(axis: Axis) -> np.ndarray:
        ks = np.unique(np.linspace(0, axis.count, min(axis.count + 1, limit)).round().astype(int))
        return np.minimum(float(axis.start) + ks * float(axis.step), float(axis.end))

    r, p = np.meshgrid(pick(raster.rows), pick(raster.points), indexing="ij")
    return (p.ravel(), r.ravel()) if raster.direction == "x" else (r.ravel(), p.ravel())
