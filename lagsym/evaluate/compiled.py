"""Scattered points compiled: the arithmetic of :class:`.chebyshev.CompensatedBasis` and the contraction, fused.

NumPy runs the compensated basis as about a hundred passes over a block of
points per axis (at 5 nodes), each reading and writing memory; here every
point's basis and sum stay in registers, a block of :data:`BLOCK` points at a
time, in loops the compiler vectorizes across points.  The operations on each point are those of
the NumPy engine in :meth:`.surface.SurfaceEvaluator.points`, one for one and
in the same order (no fused multiply-add, no reassociation: Numba's default
without ``fastmath``), so the two give the same bits; ``tests/test_evaluate.py``
checks it.  This module is loaded only for a large batch (Numba's import and
the cached kernel take about 0.5 s, once per process).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .chebyshev import SPLIT

__all__ = ["BLOCK", "points_kernel"]

BLOCK = 256
"""Points per block: a block's basis values and error terms stay in the first-level cache."""


_inline = njit(cache=True, inline="always", error_model="numpy")  # copied into each caller


@_inline
def _split(v):  # pragma: no cover - compiled
    """``v = hi + lo``, Veltkamp's split: CompensatedBasis._split."""
    c = v * SPLIT
    hi = c - (c - v)
    return hi, v - hi


@_inline
def _product_error(ahi, alo, bhi, blo, p):  # pragma: no cover - compiled
    """``a b - p`` exactly for ``p = fl(a b)``, Dekker's product: CompensatedBasis._product_error."""
    return (((ahi * bhi - p) + ahi * blo) + alo * bhi) + alo * blo


@_inline
def _basis(x, start, k, o, h, hhi, hlo, n, out, w):  # pragma: no cover - compiled
    """``T_j((x - o) / h)`` for ``j < n`` at ``x[start:start + k]`` into ``out[:, :k]``: CompensatedBasis.basis."""
    sh, shi, slo, sl = w[0], w[1], w[2], w[3]
    u, e = w[4:4 + n], w[4 + n:4 + 2 * n]
    for i in range(k):
        xi = x[start + i]
        d = xi - o
        b = d - xi
        dl = ((-o) - b) + (xi - (d - b))
        s = d / h
        hi, lo = _split(s)
        p = s * h
        pe = _product_error(hi, lo, hhi, hlo, p)
        sh[i], shi[i], slo[i] = s, hi, lo
        sl[i] = (((d - p) - pe) + dl) / h
        out[0, i] = 1.0
    if n < 2:
        return
    for i in range(k):
        out[1, i] = sh[i] + sl[i]
        u[0, i], e[0, i], u[1, i], e[1, i] = 1.0, 0.0, sh[i], sl[i]
    for j in range(2, n):
        for i in range(k):
            cu, ce, pu = u[j - 1, i], e[j - 1, i], u[j - 2, i]
            p = cu * sh[i]
            uhi, ulo = _split(cu)
            pe = _product_error(shi[i], slo[i], uhi, ulo, p)
            a = p + p
            nu = a - pu
            b = nu - a
            sigma = (a - (nu - b)) - (pu + b)
            t = (sh[i] * ce + sl[i] * cu) + pe
            t = t + t
            ne = sigma + (t - e[j - 2, i])
            u[j, i], e[j, i] = nu, ne
            out[j, i] = nu + ne


@njit(cache=True, nogil=True, error_model="numpy")
def points_kernel(x, y, lo, hi, c, xa, ya, out):  # pragma: no cover - compiled
    """``out[lo:hi] = sum_ab c[a, b] T_a(s(x)) T_b(t(y))``, unsnapped: the NumPy engine's values.

    ``xa`` and ``ya`` are ``(offset, scale, scale's high half, its low half)``
    of each axis.  ``w_b = c[0, b] T_0 + c[1, b] T_1 + ...`` and then
    ``z = w_0 Ty_0 + w_1 Ty_1 + ...``, left to right.
    """
    n, m = c.shape
    tx, ty = np.empty((n, BLOCK)), np.empty((m, BLOCK))
    w = np.empty((4 + 2 * max(n, m, 2), BLOCK))
    wb, z = np.empty(BLOCK), np.empty(BLOCK)
    for start in range(lo, hi, BLOCK):
        k = min(BLOCK, hi - start)
        _basis(x, start, k, xa[0], xa[1], xa[2], xa[3], n, tx, w)
        _basis(y, start, k, ya[0], ya[1], ya[2], ya[3], m, ty, w)
        for b in range(m):
            for i in range(k):
                wb[i] = c[0, b] * tx[0, i]
            for a in range(1, n):
                cab = c[a, b]
                for i in range(k):
                    wb[i] = wb[i] + cab * tx[a, i]
            if b == 0:
                for i in range(k):
                    z[i] = wb[i] * ty[0, i]
            else:
                for i in range(k):
                    z[i] = z[i] + wb[i] * ty[b, i]
        for i in range(k):
            out[start + i] = z[i]
