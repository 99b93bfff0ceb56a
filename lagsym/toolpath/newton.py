"""Newton steps towards the highest contact of a ball: a fast start for drop-cutter's local search.

Under a ball of radius ``R`` centred over ``c`` the tip height of the tool in
contact at ``p`` is ``g(p) = F(p) + sqrt(R**2 - |p - c|**2) - R``.  Where its
maximum lies inside the box (the ball's own rim is never one: ``g`` rises
without bound inwards there), it is a zero of the gradient, and Newton's
method on ``g`` from a nearby start reaches it in a few steps, where the
pattern search of :mod:`.dropcutter` needs dozens of rounds of eight
evaluations each.  These steps only move the starts: a step is taken only
where the Hessian is negative definite, the step stays in the box and the disc
and the height rises; the pattern search then still runs from every start,
from a step small enough to settle at once where the Newton point is the
maximum and large enough to see where it is not (:func:`newton_ball`).  Every
height is still that of a real contact.
"""

from __future__ import annotations

import weakref

import numpy as np

from ..evaluate import SurfaceEvaluator
from ..evaluate.chebyshev import chebyshev_matrix_float64

__all__ = ["newton_ball", "surface_jet"]

_ROUNDS = 12  # Newton steps at most; from a lattice peak it converges in three to five
_BLOCK = 1 << 12  # points per block of the jet: its basis and partial sums stay in cache

_JETS: weakref.WeakKeyDictionary[SurfaceEvaluator, np.ndarray] = weakref.WeakKeyDictionary()


def _jet_coefficients(ev: SurfaceEvaluator) -> np.ndarray:
    """The Chebyshev coefficients of ``F, F_x, F_y, F_xx, F_xy, F_yy``, padded to one shape, stacked ``(6 m, n)``."""
    found = _JETS.get(ev)
    if found is None:
        n, m = ev.shape
        parts = []
        for dx, dy in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)):
            c = ev.partial(dx, dy) if dx or dy else np.asarray(ev.coefficients, dtype=float)
            pad = np.zeros((n, m))
            pad[:c.shape[0], :c.shape[1]] = c
            parts.append(pad.T)
        found = _JETS[ev] = np.ascontiguousarray(np.concatenate(parts, axis=0))
    return found


def surface_jet(ev: SurfaceEvaluator, x, y) -> np.ndarray:
    """``F`` and its partial derivatives up to the second at points ``x, y`` (1-D), shape ``(6, N)``.

    In the order ``F, F_x, F_y, F_xx, F_xy, F_yy``, per surface unit, with
    the float64 arithmetic of :meth:`~lagsym.evaluate.SurfaceEvaluator.fast_points`.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    coef = _jet_coefficients(ev)
    n, m = ev.shape
    s = (x - ev.x_offset) / ev.x_scale
    t = (y - ev.y_offset) / ev.y_scale
    out = np.empty((6, x.size))
    for lo in range(0, x.size, _BLOCK):
        hi = min(lo + _BLOCK, x.size)
        # Sums of products by hand, not a matrix product: the BLAS threads cost more than these few rows save.
        tx, ty = chebyshev_matrix_float64(s[lo:hi], n), chebyshev_matrix_float64(t[lo:hi], m)
        w = coef[:, :1] * tx[0]
        for i in range(1, n):
            w += coef[:, i:i + 1] * tx[i]
        w = w.reshape(6, m, hi - lo)
        acc = out[:, lo:hi]
        np.multiply(w[:, 0], ty[0], out=acc)
        for k in range(1, m):
            acc += w[:, k] * ty[k]
    return out


def _newton_step(jet, px, py, cx, cy, radius, box):
    """The projected Newton step of ``g`` at each point.

    A coordinate at a box edge with the gradient pointing out of the box is
    held there (the step runs along the edge; at a corner there is none).
    Returns the step, whether it is one (the Hessian of the free coordinates
    negative definite), that Hessian's eigenvalue nearest 0 (at a corner, the
    ball's own curvature) and the rise the quadratic model promises (half the
    Newton decrement).
    """
    f, fx, fy, fxx, fxy, fyy = jet
    x0, x1, y0, y1 = box
    dx, dy = px - cx, py - cy
    s = np.sqrt(np.maximum(radius * radius - dx * dx - dy * dy, 1e-300))
    s3 = s * s * s
    gx, gy = fx - dx / s, fy - dy / s
    hxx, hxy, hyy = fxx - 1.0 / s - dx * dx / s3, fxy - dx * dy / s3, fyy - 1.0 / s - dy * dy / s3
    hold_x = ((px <= x0) & (gx < 0)) | ((px >= x1) & (gx > 0))
    hold_y = ((py <= y0) & (gy < 0)) | ((py >= y1) & (gy > 0))
    det = hxx * hyy - hxy * hxy
    ok = np.where(hold_x, hyy < 0, np.where(hold_y, hxx < 0, (det > 0) & (hxx < 0))) | (hold_x & hold_y)
    det = np.where(ok & ~hold_x & ~hold_y, det, 1.0)
    sx, sy = -(hyy * gx - hxy * gy) / det, -(hxx * gy - hxy * gx) / det
    one_x, one_y = -gx / np.where(hxx < 0, hxx, -1.0), -gy / np.where(hyy < 0, hyy, -1.0)
    sx = np.where(hold_x, 0.0, np.where(hold_y, one_x, sx))
    sy = np.where(hold_y, 0.0, np.where(hold_x, one_y, sy))
    half = 0.5 * (hxx + hyy)
    flat = np.abs(half + np.sqrt(np.maximum(half * half - det, 0.0)))
    flat = np.where(hold_x, np.abs(hyy), np.where(hold_y, np.abs(hxx), flat))
    flat = np.where(hold_x & hold_y, 1.0 / s, flat)
    return sx, sy, ok, flat, 0.5 * (gx * sx + gy * sy)


def _contact(ev, qx, qy, cx, cy, radius):
    """The jet of the surface at ``q`` and the ball's tip height in contact there."""
    jet = surface_jet(ev, qx, qy)
    d2 = (qx - cx) ** 2 + (qy - cy) ** 2
    return jet, jet[0] + np.sqrt(np.maximum(radius * radius - d2, 0.0)) - radius


def _off_rim(ev, px, py, val, cx, cy, radius, box, spacing, r2):
    """Starts on the ball's rim moved a quarter of ``spacing`` towards the axis (into the box) where that is higher; in place."""
    on = np.flatnonzero((px - cx) ** 2 + (py - cy) ** 2 >= r2)
    if not on.size:
        return
    x0, x1, y0, y1 = box
    f = 1.0 - min(0.25 * spacing / radius, 0.5)
    qx = np.clip(cx[on] + f * (px[on] - cx[on]), x0, x1)
    qy = np.clip(cy[on] + f * (py[on] - cy[on]), y0, y1)
    _, qv = _contact(ev, qx, qy, cx[on], cy[on], radius)
    up = ((qx - cx[on]) ** 2 + (qy - cy[on]) ** 2 < r2) & (qv > val[on])
    on = on[up]
    px[on], py[on], val[on] = qx[up], qy[up], qv[up]


def newton_ball(ev, px, py, val, cx, cy, radius, box, spacing, settle):
    """Move each start towards the local maximum of the ball's contact height; in place.

    ``px, py`` are the starts (contact points), ``val`` their heights,
    ``cx, cy`` the tool axis of each.  A start on the rim first moves off
    it.  A step is taken only where it is a Newton step (Hessian negative
    definite; along a box edge where the gradient points out of the box),
    no longer than ``spacing``, ends inside the disc (the box: clipped to it)
    and raises the height; one that does not is retried a quarter as long.  Returns the step the pattern search starts from at
    each point: ``spacing`` where Newton did not converge (a saddle, a valley
    tighter than the ball), else the step over which the flattest direction
    at the point changes the height by eight times ``settle``, so the search
    does not settle before it has looked, and no more than ``spacing``.
    """
    x0, x1, y0, y1 = box
    r2 = radius * radius * (1.0 - 1e-6)
    h = np.full(px.size, spacing)
    done = np.zeros(px.size, dtype=bool)
    _off_rim(ev, px, py, val, cx, cy, radius, box, spacing, r2)
    live = np.flatnonzero((px - cx) ** 2 + (py - cy) ** 2 < r2)
    jet, _ = _contact(ev, px[live], py[live], cx[live], cy[live], radius)
    damp = np.ones(live.size)
    for _ in range(_ROUNDS):
        if not live.size:
            break
        sx, sy, ok, flat, gain = _newton_step(jet, px[live], py[live], cx[live], cy[live], radius, box)
        converged = ok & (gain <= 0.01 * settle)
        done[live[converged]] = True
        h[live[converged]] = np.minimum(spacing, np.sqrt(16.0 * settle / np.maximum(flat[converged], 1e-300)))
        keep = ok & ~converged & (damp > 1e-3)
        live, sx, sy, jet, damp = live[keep], sx[keep], sy[keep], jet[:, keep], damp[keep]
        length = np.hypot(sx, sy)
        f = damp * np.where(length > spacing, spacing / np.where(length > 0, length, 1.0), 1.0)
        qx, qy = np.clip(px[live] + f * sx, x0, x1), np.clip(py[live] + f * sy, y0, y1)
        qjet, qv = _contact(ev, qx, qy, cx[live], cy[live], radius)
        # A step out of the disc or down (clipped to the box, the step can overshoot) is retried shorter.
        up = (qv >= val[live]) & ((qx - cx[live]) ** 2 + (qy - cy[live]) ** 2 < r2)
        px[live[up]], py[live[up]], val[live[up]] = qx[up], qy[up], qv[up]
        jet[:, up] = qjet[:, up]
        damp = np.where(up, 1.0, 0.25 * damp)
    return h, done
