"""The lowest point a tool reaches over a cell centre as it moves along a straight segment, in closed form.

A move from ``A`` to ``B`` (tip positions, mm) is turned so that it rises,
``B_z >= A_z``, and seen from a cell centre ``c`` in its own horizontal frame:
``a`` is how far along the move's horizontal direction ``c`` lies from ``A``,
``e`` how far beside it, ``L`` the move's horizontal length and ``m`` its
rise per unit of horizontal travel.  With the tip at horizontal travel ``tau``
the tool's lower surface over ``c`` is at

    g(tau) = A_z + m tau + P(d),   d^2 = (a - tau)^2 + e^2,   0 <= tau <= L, d <= R,

``P`` the tool's profile (:func:`lagsym.cutter.cutter_profile`).  ``P`` is
convex and increasing in ``d`` and ``d`` convex in ``tau``, so ``g`` is convex,
and its lowest value over the move is one of:

* **ball** (radius ``R``): where ``g' = 0`` on the whole line,
  ``a - tau = m sqrt(R^2 - e^2) / sqrt(1 + m^2)``, clamped to the move;
* **flat end**: the lowest ``tau`` over which ``c`` is under the tool,
  ``max(0, a - sqrt(R^2 - e^2))`` (the move rises);
* **bull nose** (flat of radius ``R - r``, corner ``r``): ``g' = 0`` has no
  closed form (a quartic), so it is bracketed by bisection on the sign of
  ``g'`` until the bracket is ``2**-BISECTIONS`` of the move, and the lower end
  ``lo`` of the bracket counts: with the lowest point ``tau*`` in the bracket,
  ``g(lo) - g(tau*) <= P(d(lo)) - P(d(tau*))`` (the move rises), and ``P``
  rises by at most ``sqrt(2 r w)`` over a distance ``w`` (at its rim), so the
  bull nose sweeps at most that much lower than returned (:func:`bull_resolution`).

Called with NumPy's invalid-value warnings off (NaN marks the cells beside a
segment).  Every height returned is ``g`` at a real position on the move (rounding
apart), so a cut is never invented; for the ball and the flat end it is the
lowest there is.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["lowest_ball", "lowest_flat", "lowest_bull", "bull_resolution", "lowest_along", "move_frames",
           "lowest_in_frame", "BISECTIONS"]

BISECTIONS = 30


def lowest_ball(a, e, seg, r):
    """Lowest height of a ball's lower surface over the cells at ``(a, e)`` of the segments ``seg``; NaN where none.

    ``seg`` is ``(az, az + r, length, m, k)`` per segment, ``k = m / sqrt(1 + m**2)``; broadcast with ``a``, ``e``.
    """
    _, azr, length, m, k = seg
    e2 = e * e
    tau = np.sqrt(r * r - e2)  # NaN beside the tool's path: the cell is never under it
    tau *= k
    np.subtract(a, tau, out=tau)
    np.maximum(tau, 0.0, out=tau)
    np.minimum(tau, length, out=tau)
    s = a - tau
    s *= s
    s += e2
    np.subtract(r * r, s, out=s)
    np.sqrt(s, out=s)
    tau *= m
    tau += azr
    tau -= s
    return tau


def lowest_flat(a, e, seg, r):
    """Lowest height of a flat end's bottom over the cells at ``(a, e)``; NaN where it never covers them.

    ``seg`` as for :func:`lowest_ball`.
    """
    az, _, length, m, _ = seg
    half = np.sqrt(r * r - e * e)
    tau = np.maximum(a - half, 0.0)
    ok = (tau <= length) & (a + half >= 0.0)
    return np.where(ok, az + m * tau, np.nan)


def lowest_bull(a, e, seg, r, corner, *, steps: int = BISECTIONS, above=None):
    """Lowest height of a bull nose's lower surface over the cells at ``(a, e)`` (by bisection); NaN where none.

    ``above``, if given (broadcast with ``a``), are the cells' heights so
    far: where the tool cannot come below them (its height at the first
    position over the cell, plus the profile at the nearest the axis passes,
    is already as high) the answer is NaN and no bisection is spent.
    """
    az, _, length, m, _ = seg
    flat = r - corner
    shape = np.broadcast_shapes(np.shape(a), np.shape(e), *(np.shape(v) for v in (az, length, m)))
    a, e, az, length, m = (np.broadcast_to(v, shape) for v in (a, e, az, length, m))
    e2 = e * e
    half = np.sqrt(r * r - e2)
    lo = np.maximum(a - half, 0.0)
    ok = lo <= np.minimum(a + half, length)
    if above is not None:
        q = np.minimum(np.maximum(np.abs(e) - flat, 0.0), corner)
        ok &= az + m * lo + (corner - np.sqrt(corner * corner - q * q)) < np.broadcast_to(above, shape)
    out = np.full(shape, np.nan)
    if not ok.any():
        return out
    a, e2, az, length, m, lo, half = (v[ok] for v in (a, e2, az, length, m, lo, half))
    hi = np.minimum(a + half, length)
    m2 = m * m
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        s = a - mid
        d2 = s * s + e2
        d = np.sqrt(d2)
        q = np.maximum(d - flat, 0.0)
        q2 = q * q
        # g'(mid) >= 0: m + P'(d) (mid - a) / d >= 0 with P'(d) = q / sqrt(corner^2 - q^2).
        rising = (s <= 0.0) | (q2 * s * s <= m2 * d2 * (corner * corner - q2))
        hi = np.where(rising, mid, hi)
        lo = np.where(rising, lo, mid)
    s = a - lo
    q = np.minimum(np.maximum(np.sqrt(s * s + e2) - flat, 0.0), corner)
    out[ok] = az + m * lo + corner - np.sqrt(corner * corner - q * q)
    return out


def bull_resolution(corner: float, longest_mm: float, steps: int = BISECTIONS) -> float:
    """How much lower than :func:`lowest_bull` a bull nose can sweep along moves up to ``longest_mm`` sideways."""
    w = min(longest_mm, 1.0e300) / 2.0**steps
    return math.sqrt(max(2.0 * corner * w - w * w, 0.0))


def move_frames(a, b):
    """The moves ``a -> b`` (``(..., 3)`` tip positions) turned to rise, in their own horizontal frames.

    Returns ``(ax, ay, ux, uy, seg)``: the start, the unit direction and
    ``seg`` as :func:`lowest_ball` takes it, less the tool radius
    (``seg[1]`` is the start's height until :func:`lowest_in_frame` adds it).
    """
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    up = (b[..., 2] >= a[..., 2])[..., None]
    a, b = np.where(up, a, b), np.where(up, b, a)
    d = b - a
    length = np.hypot(d[..., 0], d[..., 1])
    moving = length > 0.0
    safe = np.where(moving, length, 1.0)
    ux, uy = np.where(moving, d[..., 0] / safe, 1.0), np.where(moving, d[..., 1] / safe, 0.0)
    m = np.where(moving, d[..., 2] / safe, 0.0)
    return a[..., 0], a[..., 1], ux, uy, (a[..., 2], a[..., 2], length, m, m / np.sqrt(1.0 + m * m))


def lowest_in_frame(frame, px, py, r, corner):
    """Lowest height of the tool's lower surface over ``(px, py)`` along moves in :func:`move_frames`; NaN where none.

    ``r`` and ``corner`` are the tool's radius and corner radius (``r`` for a ball, 0 for a flat end).
    """
    ax, ay, ux, uy, (az, _, length, m, k) = frame
    seg = (az, az + r, length, m, k)
    wx, wy = px - ax, py - ay
    with np.errstate(invalid="ignore"):
        ca, ce = wx * ux + wy * uy, wy * ux - wx * uy
        if corner <= 0.0:
            return lowest_flat(ca, ce, seg, r)
        if corner >= r:
            return lowest_ball(ca, ce, seg, r)
        return lowest_bull(ca, ce, seg, r, corner)


def lowest_along(a, b, px, py, r, corner):
    """Lowest height of the tool's lower surface over ``(px, py)`` along the moves ``a -> b``; NaN where none.

    ``a`` and ``b`` are ``(..., 3)`` tip positions broadcast with ``px`` and
    ``py``; ``r`` and ``corner`` as :func:`lowest_in_frame` takes them.
    """
    return lowest_in_frame(move_frames(a, b), px, py, r, corner)
