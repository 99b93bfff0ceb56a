"""What a simulated touch probe touches: a surface ``z = f(x, y)`` and a ball tip of a given radius.

A probing move (Fanuc/Haas ``G31``, LinuxCNC ``G38.2``) stops where the
probe's ball tip first touches the surface.  The position a control then
reports (``#5061``-``#5063``) is that of the tip's centre, so the tip's
centre stops at the height where the ball rests on the surface::

    rest(x, y) = max over |d| <= r of  f(x + dx, y + dy) + sqrt(r**2 - |d|**2)

found here by brute force on the disk (a grid of 121 x 121 offsets, then
three finer grids around the best one, each five times finer): for a surface
whose second derivatives stay below ``k``, the height is found to within
about ``k * (r / 60 / 125)**2``, far below a micrometre for any tip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import InputError

__all__ = ["ProbeTarget", "ProbeCrash", "probe_target"]

_GRID = 121  # offsets a side on the disk
_REFINE = 3  # finer grids around the best offset
_STEPS = 400  # samples along a move that is not straight down, before the first contact is bisected


class ProbeCrash(Exception):
    """A probing move that starts with the tip on or in the surface (the simulator turns it into an alarm)."""


@dataclass(frozen=True)
class ProbeTarget:
    """A surface ``height(x, y)`` (NumPy arrays in, an array out) touched by a ball tip of ``tip_radius`` units."""

    height: Callable
    tip_radius: float = 0.0
    name: str = "surface"

    def _heights(self, x, y) -> np.ndarray:
        z = np.asarray(self.height(np.asarray(x, dtype=float), np.asarray(y, dtype=float)), dtype=float)
        if not np.all(np.isfinite(z)):
            raise InputError(f"{self.name}: no finite height near (x, y) = ({float(np.ravel(x)[0]):g}, "
                             f"{float(np.ravel(y)[0]):g})")
        return z

    def rest(self, x: float, y: float) -> float:
        """The height of the tip's centre resting on the surface above ``(x, y)``."""
        r = self.tip_radius
        if r == 0:
            return float(self._heights(np.array([x]), np.array([y]))[0])
        u = np.linspace(-r, r, _GRID)
        dx, dy = np.meshgrid(u, u, indexing="ij")
        inside = dx ** 2 + dy ** 2 <= r * r
        dx, dy = dx[inside], dy[inside]
        best, step = None, 2 * r / (_GRID - 1)
        for _ in range(_REFINE + 1):
            lift = np.sqrt(np.maximum(r * r - dx ** 2 - dy ** 2, 0.0))
            z = self._heights(x + dx, y + dy) + lift
            k = int(np.argmax(z))
            best = (float(z[k]), float(dx[k]), float(dy[k]))
            step /= 5
            v = np.arange(-5, 6) * step
            gx, gy = np.meshgrid(best[1] + v, best[2] + v, indexing="ij")
            keep = gx ** 2 + gy ** 2 <= r * r
            dx, dy = gx[keep], gy[keep]
        return best[0]

    def touch(self, start, end):
        """Where the tip's centre stops moving from ``start`` to ``end`` (x, y, z), or None without contact.

        Raises
        ------
        ProbeCrash
            When the tip is at or below the surface at the start: the move there went into the part.
        """
        (x0, y0, z0), (x1, y1, z1) = start, end
        h0 = self.rest(x0, y0)
        if z0 <= h0:
            raise ProbeCrash(f"the probe tip is already on or in the {self.name} at the start "
                             f"(z {z0:g}, the surface needs the centre at {h0:.4f}): the move there went into the part")
        if math.isclose(x0, x1, abs_tol=1e-12) and math.isclose(y0, y1, abs_tol=1e-12):
            h = self.rest(x0, y0)
            return (x0, y0, h) if z1 <= h else None

        def gap(t):
            return z0 + t * (z1 - z0) - self.rest(x0 + t * (x1 - x0), y0 + t * (y1 - y0))

        lo = 0.0
        for k in range(1, _STEPS + 1):
            t = k / _STEPS
            if gap(t) <= 0:
                hi = t
                for _ in range(50):
                    mid = (lo + hi) / 2
                    lo, hi = (lo, mid) if gap(mid) <= 0 else (mid, hi)
                return (x0 + hi * (x1 - x0), y0 + hi * (y1 - y0), z0 + hi * (z1 - z0))
            lo = t
        return None


def probe_target(height: Callable, tip_radius: float = 0.0, name: str = "surface") -> ProbeTarget:
    """A :class:`ProbeTarget`: ``height`` a vectorised ``z = f(x, y)`` (a :class:`lagsym.formula.Formula`, a
    surface's evaluator), ``tip_radius`` the probe's ball radius in program units (0: a point).

    Examples
    --------
    >>> from lagsym.formula import parse_formula
    >>> t = probe_target(parse_formula("0.1*x"), 0)
    >>> t.touch((10.0, 0.0, 5.0), (10.0, 0.0, -5.0))
    (10.0, 0.0, 1.0)
    """
    r = float(tip_radius)
    if not math.isfinite(r) or r < 0:
        raise InputError(f"probe tip radius {tip_radius!r} must be zero or more")
    return ProbeTarget(height=height, tip_radius=r, name=name)
