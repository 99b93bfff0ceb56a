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

__all__ = ["newton_ball", "surface_jet", "jet_coefficients", "kernel_geometry"]

_BLOCK = 1 << 12  # points per block of the jet: its basis and partial sums stay in cache

_JETS: weakref.WeakKeyDictionary[SurfaceEvaluator, np.ndarray] = weakref.WeakKeyDictionary()


def jet_coefficients(ev: SurfaceEvaluator) -> np.ndarray:
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


def kernel_geometry(ev: SurfaceEvaluator, box, radius: float, corner: float, spacing: float,
                    settle: float) -> np.ndarray:
    """The compiled kernel's geometry array for the evaluator ``ev``, the ``box`` and the tool (:mod:`.kernel`)."""
    return np.array([ev.x_offset, ev.x_scale, ev.y_offset, ev.y_scale, *box, radius, corner, spacing, settle], float)


def surface_jet(ev: SurfaceEvaluator, x, y) -> np.ndarray:
    """``F`` and its partial derivatives up to the second at points ``x, y`` (1-D), shape ``(6, N)``.

    In the order ``F, F_x, F_y, F_xx, F_xy, F_yy``, per surface unit, with
    the float64 arithmetic of :meth:`~lagsym.evaluate.SurfaceEvaluator.fast_points`.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    coef = jet_coefficients(ev)
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


def newton_ball(ev, px, py, val, cx, cy, *, radius, box, spacing, settle):
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
    does not settle before it has looked, and no more than ``spacing``; and
    whether Newton converged.  The steps are compiled (:func:`.kernel.newton_starts`).
    """
    from .kernel import newton_starts

    geo = kernel_geometry(ev, box, radius, radius, spacing, settle)
    h, done = np.empty(px.size), np.zeros(px.size, dtype=bool)
    cx, cy = (np.ascontiguousarray(np.broadcast_to(v, px.shape), dtype=float) for v in (cx, cy))
    newton_starts(jet_coefficients(ev), ev.shape[1], geo, px, py, val, cx, cy, h, done)
    return h, done
