"""The clearance of a roughing macro: how far above the surface the control puts the tool, proved enough.

At a tool position ``c`` (its centre clamped to the control points' box:
``c'``) the control computes

    b(c) = F(c') + stock + R |grad F(c')| + K

and moves the tip to ``max(level, b)``.  Why ``b`` is never below the
exact drop-cutter height plus the stock, for a flat, ball or bull-nose end
of radius ``R``:

1. *Taylor.*  The drop-cutter height is ``CL(c') = max F(p) - P(|p - c'|)``
   over the points ``p`` of the box within ``R`` of ``c'``, ``P >= 0`` the
   cutter's profile; a centre outside the box is given ``CL(c')``, which is
   never below the true height (:mod:`lagsym.toolpath.rough`).  The segment
   from ``c'`` to ``p`` lies in the box (it is convex), so with ``d = p - c'``

       F(p) = F(c') + grad F(c') . d + d' H(q) d / 2 <= F(c') + R |grad F(c')| + M R**2 / 2,

   ``M`` a bound of the largest eigenvalue of the Hessian ``H`` over the box
   (0 if the surface curves down everywhere).  For a ball ``P(d) >= d**2 / 2R``,
   so ``M`` is replaced by ``M - 1/R`` (and the term is 0 when that is below 0).
2. *Straight moves.*  Along a row ``b`` is the maximum over unit vectors
   ``e`` of ``F + R grad F . e + K``, each of which bends up by at most
   ``W = |F_pp| + R sqrt(F_ppp**2 + F_ppr**2)`` per unit squared (``p``
   along the row, ``r`` across), and so is ``max(level, b)``: between two
   samples ``h`` apart it rises above their chord by at most ``W h**2 / 8``.
   The box edges are samples of every row, so no move spans the corner
   where ``c'`` stops following ``c``; beyond them ``b`` is constant.
3. *The control.*  It moves to X and Y rounded to its resolution ``u``
   (half a unit each way: the height moves by at most ``G u / sqrt 2``, ``G``
   a bound of the slope) and rounds Z to the nearest unit (``u / 2``); its
   arithmetic error on ``b`` is predicted by running the statements in the
   control's decimal arithmetic (:mod:`.accuracy`'s way), and twice that is kept.

``K`` is the sum of those terms.  ``M``, ``W`` and ``G`` are certified: each
derivative's Chebyshev coefficients are re-expanded on 16 x 16 tiles of the
box, and on a tile a polynomial lies within ``|c_00| + sum |c_ab|`` (``|T_k|
<= 1``); a relative ``1e-9`` of the coefficients' sum covers the rounding of
the re-expansion.  So ``b >= CL + stock`` at every sample and along every
move, whatever the cutter.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import chebyshev as C

__all__ = ["Clearance", "derivative_bounds", "clearance_terms", "TILES"]

TILES = 16  # tiles a side for the certified bounds


@dataclass(frozen=True)
class Clearance:
    """The terms of ``K`` (mm) and the certified bounds they come from.

    Attributes
    ----------
    taylor_mm, sag_mm, rounding_mm, arithmetic_mm : float
        ``M R**2 / 2`` (ball: ``(M - 1/R) R**2 / 2``, not below 0), ``W h**2 / 8``,
        ``G u / sqrt 2 + u / 2`` and the control's arithmetic allowance.
    curvature_per_mm : float
        ``M``: the Hessian's largest eigenvalue over the box, bounded (0 or more).
    bend_per_mm : float
        ``W`` along the rows.
    slope : float
        ``G``: a bound of ``|grad F|`` over the box.
    """

    taylor_mm: float
    sag_mm: float
    rounding_mm: float
    arithmetic_mm: float
    curvature_per_mm: float
    bend_per_mm: float
    slope: float

    @property
    def total_mm(self) -> float:
        """``K``: what the control adds to ``F + stock + R |grad F|``."""
        return self.taylor_mm + self.sag_mm + self.rounding_mm + self.arithmetic_mm


def _tile_bounds(coefficients: np.ndarray, tiles: int) -> tuple[np.ndarray, np.ndarray]:
    """Upper bounds of ``p`` and of ``|p|`` on each of ``tiles x tiles`` tiles of ``[-1, 1]**2``.

    ``p = sum c[a, b] T_a(s) T_b(t)`` is re-expanded on each tile in the
    tile's own Chebyshev basis (interpolation at as many Chebyshev points as
    coefficients: exact for a polynomial of that degree), where it lies
    within ``|c_00| + sum of the other |c_ab|`` of ``c_00``.
    """
    c = np.asarray(coefficients, dtype=float)
    n, m = c.shape
    sn, sm = C.chebpts1(n) if n > 1 else np.zeros(1), C.chebpts1(m) if m > 1 else np.zeros(1)
    vn_inv, vm_inv = np.linalg.inv(C.chebvander(sn, n - 1)), np.linalg.inv(C.chebvander(sm, m - 1))
    edges = np.linspace(-1.0, 1.0, tiles + 1)
    mids, halves = (edges[:-1] + edges[1:]) / 2, np.diff(edges) / 2
    slack = 1e-9 * float(np.abs(c).sum())
    up, absup = np.empty((tiles, tiles)), np.empty((tiles, tiles))
    for i in range(tiles):
        xs = mids[i] + halves[i] * sn
        for j in range(tiles):
            ys = mids[j] + halves[j] * sm
            local = vn_inv @ C.chebgrid2d(xs, ys, c) @ vm_inv.T
            rest = float(np.abs(local).sum() - abs(local[0, 0]))
            up[i, j] = local[0, 0] + rest + slack
            absup[i, j] = abs(local[0, 0]) + rest + slack
    return up, absup


def derivative_bounds(ev, mm_per_unit: float, radius_mm: float, direction: str,
                      tiles: int = TILES) -> tuple[float, float, float]:
    """Certified ``(M, W, G)`` over the box, in machine mm (see the module docstring).

    ``ev`` is the surface's :class:`~lagsym.evaluate.SurfaceEvaluator`
    (derivatives per surface unit); a surface-unit derivative of order ``k``
    is ``mm_per_unit**(1 - k)`` times its millimetre one.
    """
    def part(dx, dy):
        return ev.partial(dx, dy) * mm_per_unit ** (1 - dx - dy)

    def pad(a, shape):
        out = np.zeros(shape)
        out[:a.shape[0], :a.shape[1]] = a
        return out

    fxx, fyy, fxy = part(2, 0), part(0, 2), part(1, 1)
    shape = tuple(max(a.shape[k] for a in (fxx, fyy, fxy)) for k in range(2))
    fxx, fyy, fxy = pad(fxx, shape), pad(fyy, shape), pad(fxy, shape)
    a_up, _ = _tile_bounds((fxx + fyy) / 2, tiles)
    _, d_abs = _tile_bounds((fxx - fyy) / 2, tiles)
    _, e_abs = _tile_bounds(fxy, tiles)
    curvature = max(float((a_up + np.sqrt(d_abs ** 2 + e_abs ** 2)).max()), 0.0)
    _, gx = _tile_bounds(part(1, 0), tiles)
    _, gy = _tile_bounds(part(0, 1), tiles)
    slope = float(np.sqrt(gx ** 2 + gy ** 2).max())
    pp, ppp, ppr = ((2, 0), (3, 0), (2, 1)) if direction == "x" else ((0, 2), (0, 3), (1, 2))
    _, b2 = _tile_bounds(part(*pp), tiles)
    _, b3 = _tile_bounds(part(*ppp), tiles)
    _, b3r = _tile_bounds(part(*ppr), tiles)
    bend = float((b2 + radius_mm * np.sqrt(b3 ** 2 + b3r ** 2)).max())
    return curvature, bend, slope


def clearance_terms(ev, mm_per_unit: float, tool, direction: str, step_mm: float, unit_mm: float,
                    arithmetic_mm: float) -> Clearance:
    """The terms of ``K`` for ``tool`` on rows along ``direction`` sampled ``step_mm`` apart.

    ``unit_mm`` is the program's resolution; ``arithmetic_mm`` the control's
    arithmetic allowance (already doubled).
    """
    radius = tool.radius_mm
    curvature, bend, slope = derivative_bounds(ev, mm_per_unit, radius, direction)
    up = curvature - (1.0 / radius if tool.shape == "ball" else 0.0)
    return Clearance(taylor_mm=max(up, 0.0) * radius ** 2 / 2, sag_mm=bend * step_mm ** 2 / 8,
                     rounding_mm=slope * unit_mm / math.sqrt(2) + unit_mm / 2, arithmetic_mm=arithmetic_mm,
                     curvature_per_mm=curvature, bend_per_mm=bend, slope=slope)
