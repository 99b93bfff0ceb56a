"""The clearance of a roughing macro: how far above the surface the control puts the tool, proved enough.

At a tool position ``c`` (its centre clamped to the control points' box:
``c'``, in tile ``t`` of an ``n x n`` tiling of the box) the control computes

    b(c) = min(F(c') + stock + R |grad F(c')| + A[t],  B[t])

and moves the tip to ``max(level, b)``, with ``A[t] = T[t] + S[t] + E`` and
``B[t] = U[t] + stock + S[t] + E``.  Why no position and no move goes below
the exact drop-cutter height plus the stock, for a flat, ball or bull-nose
end of radius ``R``:

1. *Taylor.*  The drop-cutter height is ``CL(c') = max F(p) - P(|p - c'|)``
   over the points ``p`` of the box within ``R`` of ``c'``, ``P >= 0`` the
   cutter's profile; a centre outside the box is given ``CL(c')``, never
   below its true height (:mod:`lagsym.toolpath.rough`).  The segment from
   ``c'`` to ``p`` lies in the box (it is convex) and within ``R`` of ``c'``, so with ``d = p - c'``

       F(p) = F(c') + grad F(c') . d + d' H(q) d / 2 <= F(c') + R |grad F(c')| + M[t] R**2 / 2,

   ``M[t]`` a bound of the Hessian's largest eigenvalue (0 or more) within
   ``R`` of the tile: ``T[t] = M[t] R**2 / 2``.  For a ball ``P(d) >= d**2 / 2R``,
   so there ``T[t] = max(M[t] - 1/R, 0) R**2 / 2``.
2. *The cap.*  ``CL(c') <= max F(p) <= U[t]``, a bound of ``F`` within ``R``
   of the tile.  So both terms of the ``min`` bound ``CL + stock``, and so does ``b``.
3. *Straight moves.*  Two samples of a row are ``h`` apart (the box edges
   are samples, so none spans the corner where ``c'`` stops following
   ``c``).  Between them ``CL`` changes by at most ``L |x - x_i|``, ``L``
   the largest slope of ``F`` within ``R + h`` of either sample's tile (the
   disc under the tool moves with it), so at ``x = (1 - s) x_i + s x_(i+1)``

       CL(x) <= (1 - s) CL(x_i) + s CL(x_(i+1)) + 2 s (1 - s) L h <= chord + L h / 2:

   ``S[t] = L[t] h / 2`` at both ends keeps the move above ``CL + stock``
   (and a maximum with the level only raises a chord).
4. *The control.*  It moves to X and Y rounded to its resolution ``u``
   (the height under the tool moves by at most ``G u / sqrt 2``, ``G`` a bound of
   the slope over the box) and rounds Z to the nearest unit (``u / 2``); its
   arithmetic error on ``b`` is predicted by running the statements in the
   control's decimal arithmetic, and twice that is kept: ``E`` is the sum.

``M``, ``U``, ``L`` and ``G`` are certified: each polynomial (the Hessian's
parts, ``F``, its slopes) is re-expanded in the Chebyshev basis of each of
64 x 64 small tiles of the box, where it lies within ``|c_00| + sum |c_ab|``
of nothing (``|T_k| <= 1``), plus a relative ``1e-9`` of its coefficients'
sum for the rounding of the re-expansion; a tile's bound is the largest over
the small tiles that meet it grown by ``R`` (or ``R + h``) and 0.01 mm, so a
position the control's arithmetic puts in the next tile is still covered.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import chebyshev as C

from .._arrays import freeze_fields

__all__ = ["Clearance", "clearance_tables", "FINE"]

FINE = 64  # small tiles a side for the certified bounds
_GROW_MM = 0.01  # windows grown beyond the radius: a position the control's arithmetic puts in the next tile


@dataclass(frozen=True)
class Clearance:
    """The tables ``A`` and ``B`` (mm) of the module docstring, indexed ``[p tile, r tile]``, and their parts.

    Attributes
    ----------
    tiles : int
        ``n``: tiles a side of the box (``n = 1``: one tile, no table).
    taylor_mm, chord_mm, cap_mm : ndarray, shape (n, n)
        ``T``, ``S`` and ``U + stock`` (the cap's height, machine Z).
    curvature_per_mm : ndarray, shape (n, n)
        ``M`` of each tile.
    rounding_mm, arithmetic_mm : float
        ``G u / sqrt 2 + u / 2`` and the control's arithmetic allowance (the two make ``E``).
    slope : float
        ``G``.
    """

    tiles: int
    taylor_mm: np.ndarray
    chord_mm: np.ndarray
    cap_mm: np.ndarray
    curvature_per_mm: np.ndarray
    rounding_mm: float
    arithmetic_mm: float
    slope: float

    def __post_init__(self):
        freeze_fields(self, ("taylor_mm", "chord_mm", "cap_mm", "curvature_per_mm"))

    @property
    def extra_mm(self) -> float:
        """``E``."""
        return self.rounding_mm + self.arithmetic_mm

    @property
    def a_mm(self) -> np.ndarray:
        """``A = T + S + E``, added to ``F + stock + R |grad F|``."""
        return self.taylor_mm + self.chord_mm + self.extra_mm

    @property
    def b_mm(self) -> np.ndarray:
        """``B = U + stock + S + E``, the cap."""
        return self.cap_mm + self.chord_mm + self.extra_mm


def _tile_bounds(coefficients: np.ndarray, tiles: int) -> tuple[np.ndarray, np.ndarray]:
    """Upper bounds of ``p`` and of ``|p|`` on each of ``tiles x tiles`` tiles of ``[-1, 1]**2``.

    ``p = sum c[a, b] T_a(s) T_b(t)`` is re-expanded on each tile in the
    tile's own Chebyshev basis (interpolation at as many Chebyshev points as
    coefficients: exact for a polynomial of that degree), where it lies
    within ``sum of the |c_ab|`` other than ``c_00`` of ``c_00``.
    """
    c = np.asarray(coefficients, dtype=float)
    n, m = c.shape
    sn = C.chebpts1(n) if n > 1 else np.zeros(1)
    sm = C.chebpts1(m) if m > 1 else np.zeros(1)
    vn_inv, vm_inv = np.linalg.inv(C.chebvander(sn, n - 1)), np.linalg.inv(C.chebvander(sm, m - 1))
    edges = np.linspace(-1.0, 1.0, tiles + 1)
    mids, halves = (edges[:-1] + edges[1:]) / 2, np.diff(edges) / 2
    xs = (mids[:, None] + halves[:, None] * sn[None, :]).ravel()
    ys = (mids[:, None] + halves[:, None] * sm[None, :]).ravel()
    values = C.chebgrid2d(xs, ys, c).reshape(tiles, n, tiles, m)
    local = np.einsum("ak,ikjl,bl->ijab", vn_inv, values, vm_inv)
    rest = np.abs(local).sum(axis=(2, 3)) - np.abs(local[:, :, 0, 0])
    slack = 1e-9 * float(np.abs(c).sum())
    return local[:, :, 0, 0] + rest + slack, np.abs(local[:, :, 0, 0]) + rest + slack


def _windows(fine: np.ndarray, box, edges_x, edges_y, grow_mm: float) -> np.ndarray:
    """For each tile between ``edges_x`` and ``edges_y`` (mm), the largest ``fine`` value over the small tiles
    meeting it grown by ``grow_mm`` (machine frame: ``[x tile, y tile]``)."""
    k = fine.shape[0]
    x0, x1, y0, y1 = box

    def meeting(lo, hi, a, b):
        w = (b - a) / k
        i = np.arange(k)
        return (a + (i + 1) * w >= lo) & (a + i * w <= hi)

    out = np.empty((len(edges_x) - 1, len(edges_y) - 1))
    for i in range(out.shape[0]):
        mi = meeting(edges_x[i] - grow_mm, edges_x[i + 1] + grow_mm, x0, x1)
        for j in range(out.shape[1]):
            mj = meeting(edges_y[j] - grow_mm, edges_y[j + 1] + grow_mm, y0, y1)
            out[i, j] = fine[np.ix_(mi, mj)].max()
    return out


def _fine(ev, mm_per_unit: float) -> dict[str, np.ndarray]:
    """Certified bounds on the 64 x 64 small tiles, in machine mm: ``lam`` (Hessian's top eigenvalue,
    0 or more), ``f`` (``F`` above the Z origin) and ``g`` (``|grad F|``)."""
    def part(dx, dy):
        return ev.partial(dx, dy) * mm_per_unit ** (1 - dx - dy)

    hess = [part(2, 0), part(0, 2), part(1, 1)]
    shape = tuple(max(a.shape[k] for a in hess) for k in range(2))
    fxx, fyy, fxy = (np.pad(a, [(0, shape[0] - a.shape[0]), (0, shape[1] - a.shape[1])]) for a in hess)
    a_up, _ = _tile_bounds((fxx + fyy) / 2, FINE)
    _, d_abs = _tile_bounds((fxx - fyy) / 2, FINE)
    _, e_abs = _tile_bounds(fxy, FINE)
    f_up, _ = _tile_bounds(np.asarray(ev.coefficients) * mm_per_unit, FINE)
    _, gx = _tile_bounds(part(1, 0), FINE)
    _, gy = _tile_bounds(part(0, 1), FINE)
    return {"lam": np.maximum(a_up + np.sqrt(d_abs ** 2 + e_abs ** 2), 0.0), "f": f_up,
            "g": np.sqrt(gx ** 2 + gy ** 2)}


def clearance_tables(ev, place, tool, step_mm: float, stock_mm: float, *, edges_x, edges_y, unit_mm: float,
                     arithmetic_mm: float, direction: str = "x") -> Clearance:
    """The tables for ``tool`` with row samples ``step_mm`` apart, over the tiles between ``edges_x`` and
    ``edges_y`` (machine mm, the box's edges first and last).

    ``place`` is the machine placement; ``unit_mm`` the program's resolution;
    ``arithmetic_mm`` the control's arithmetic allowance (already doubled);
    the tables are indexed along the rows (``direction``) first.
    """
    radius = tool.radius_mm
    fine = _fine(ev, place.mm_per_unit)
    box = place.box_mm(ev.bounds)
    lam = _windows(fine["lam"], box, edges_x, edges_y, radius + _GROW_MM)
    cap = _windows(fine["f"], box, edges_x, edges_y, radius + _GROW_MM) + place.origin_mm[2] + stock_mm
    slope = _windows(fine["g"], box, edges_x, edges_y, radius + step_mm + _GROW_MM)
    up = lam - tool.curvature_per_mm
    taylor, chord = np.maximum(up, 0.0) * radius ** 2 / 2, slope * step_mm / 2
    if direction == "y":
        lam, cap, taylor, chord = lam.T, cap.T, taylor.T, chord.T
    g = float(fine["g"].max())
    return Clearance(tiles=lam.shape[0], taylor_mm=taylor, chord_mm=chord, cap_mm=cap, curvature_per_mm=lam,
                     rounding_mm=g * unit_mm / math.sqrt(2) + unit_mm / 2, arithmetic_mm=arithmetic_mm, slope=g)
