"""Large batches compiled: the arithmetic of :class:`.chebyshev.CompensatedBasis` and the contractions, fused.

NumPy runs the compensated basis as about a hundred passes over a block of
points per axis (at 5 nodes), each reading and writing memory; here every
point's basis and sum stay in registers, a block of :data:`BLOCK` points at a
time, in loops the compiler vectorizes across points.  On a grid
(:func:`product_kernel`) each output row is computed in cache from a few
basis rows and written once.  The operations on each value are those of the
NumPy engine in :mod:`.surface`, one for one and in the same order (no fused
multiply-add, no reassociation: Numba's default without ``fastmath``), so the
two give the same bits; ``tests/test_evaluate.py`` and ``tests/test_engine.py``
check it.  This module is loaded only with the compiled engine
(:mod:`.engine`: Numba's import and the cached kernels take long enough,
once per process, that a process evaluating one large batch never loads
them).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .chebyshev import SPLIT

__all__ = ["BLOCK", "COLUMNS", "basis_kernel", "factor_kernel", "hits_kernel", "points_kernel", "product_kernel"]

BLOCK = 256
"""Points per block: a block's basis values and error terms stay in the first-level cache."""

COLUMNS = 2048
"""Columns of a grid product computed at a time: four output rows of them and four basis rows stay in cache."""


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


@_inline
def _column(tx, c, b, k, out):  # pragma: no cover - compiled
    """``out[:k] = c[0, b] tx[0, :k] + c[1, b] tx[1, :k] + ...``, left to right: ``.surface._column``."""
    c0 = c[0, b]
    for i in range(k):
        out[i] = c0 * tx[0, i]
    for a in range(1, c.shape[0]):
        cab = c[a, b]
        for i in range(k):
            out[i] = out[i] + cab * tx[a, i]


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
            _column(tx, c, b, k, wb)
            if b == 0:
                for i in range(k):
                    z[i] = wb[i] * ty[0, i]
            else:
                for i in range(k):
                    z[i] = z[i] + wb[i] * ty[b, i]
        for i in range(k):
            out[start + i] = z[i]


@njit(cache=True, nogil=True, error_model="numpy")
def basis_kernel(x, axis, n, out):  # pragma: no cover - compiled
    """``out[j, i] = T_j((x[i] - offset) / scale)`` for ``j < n``: :func:`.chebyshev.chebyshev_basis`'s values.

    ``axis`` is ``(offset, scale, scale's high half, its low half)``.
    """
    w = np.empty((4 + 2 * max(n, 2), BLOCK))
    for start in range(0, x.size, BLOCK):
        k = min(BLOCK, x.size - start)
        _basis(x, start, k, axis[0], axis[1], axis[2], axis[3], n, out[:, start:start + k], w)


@njit(cache=True, nogil=True, error_model="numpy")
def factor_kernel(tx, c, out):  # pragma: no cover - compiled
    """``out[i, b] = c[0, b] tx[0, i] + c[1, b] tx[1, i] + ...``, left to right: a grid's ``W``, as points form it."""
    col = np.empty(tx.shape[1])
    for b in range(c.shape[1]):
        _column(tx, c, b, col.size, col)
        out[:, b] = col


@_inline
def _first_not_below(a, x, right):  # pragma: no cover - compiled
    """The first index of ascending ``a`` whose value is not below ``x`` (``right``: above ``x``), or ``a.size``."""
    lo, hi = 0, a.size
    while lo < hi:
        mid = (lo + hi) // 2
        if a[mid] < x or (right and a[mid] == x):
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True, nogil=True, error_model="numpy")
def hits_kernel(nodes, exact, v):  # pragma: no cover - compiled
    """Indices into ``v`` of values equal to a node (ascending) whose ``exact`` is set, and which node.

    ``nodes`` ascending.  :meth:`.surface.SurfaceEvaluator._hits` in compiled
    code: on an ascending ``v`` each node's run of equal values is found by
    bisection in ``v``, otherwise each value is looked up among the nodes.
    """
    at, which = np.empty(v.size, dtype=np.intp), np.empty(v.size, dtype=np.intp)
    count = 0
    ascending = True
    for i in range(1, v.size):
        if not v[i - 1] <= v[i]:  # NaN too
            ascending = False
            break
    if ascending:
        for k in range(nodes.size):
            if exact[k]:
                for i in range(_first_not_below(v, nodes[k], False), _first_not_below(v, nodes[k], True)):
                    at[count], which[count] = i, k
                    count += 1
    elif nodes.size:
        for i in range(v.size):
            k = min(_first_not_below(nodes, v[i], False), nodes.size - 1)
            if nodes[k] == v[i] and exact[k]:
                at[count], which[count] = i, k
                count += 1
    return at[:count].copy(), which[:count].copy()


@_inline
def _first_terms(w, ty, rows, jb, je, out, r):  # pragma: no cover - compiled
    """``out[q][jb:je]`` = the first ``r`` (1 to 5) terms of row ``rows[q]``'s sums, left to right."""
    r0, r1, r2, r3 = rows
    o0, o1, o2, o3 = out
    t0 = ty[0, jb:je]
    a0, b0, c0, d0 = w[r0, 0], w[r1, 0], w[r2, 0], w[r3, 0]
    if r == 1:
        for j in range(je - jb):
            u0 = t0[j]
            o0[j], o1[j], o2[j], o3[j] = a0 * u0, b0 * u0, c0 * u0, d0 * u0
        return
    t1 = ty[1, jb:je]
    a1, b1, c1, d1 = w[r0, 1], w[r1, 1], w[r2, 1], w[r3, 1]
    if r == 2:
        for j in range(je - jb):
            u0, u1 = t0[j], t1[j]
            o0[j], o1[j] = a0 * u0 + a1 * u1, b0 * u0 + b1 * u1
            o2[j], o3[j] = c0 * u0 + c1 * u1, d0 * u0 + d1 * u1
        return
    t2 = ty[2, jb:je]
    a2, b2, c2, d2 = w[r0, 2], w[r1, 2], w[r2, 2], w[r3, 2]
    if r == 3:
        for j in range(je - jb):
            u0, u1, u2 = t0[j], t1[j], t2[j]
            o0[j], o1[j] = (a0 * u0 + a1 * u1) + a2 * u2, (b0 * u0 + b1 * u1) + b2 * u2
            o2[j], o3[j] = (c0 * u0 + c1 * u1) + c2 * u2, (d0 * u0 + d1 * u1) + d2 * u2
        return
    t3 = ty[3, jb:je]
    a3, b3, c3, d3 = w[r0, 3], w[r1, 3], w[r2, 3], w[r3, 3]
    if r == 4:
        for j in range(je - jb):
            u0, u1, u2, u3 = t0[j], t1[j], t2[j], t3[j]
            o0[j], o1[j] = ((a0 * u0 + a1 * u1) + a2 * u2) + a3 * u3, ((b0 * u0 + b1 * u1) + b2 * u2) + b3 * u3
            o2[j], o3[j] = ((c0 * u0 + c1 * u1) + c2 * u2) + c3 * u3, ((d0 * u0 + d1 * u1) + d2 * u2) + d3 * u3
        return
    t4 = ty[4, jb:je]
    a4, b4, c4, d4 = w[r0, 4], w[r1, 4], w[r2, 4], w[r3, 4]
    for j in range(je - jb):
        u0, u1, u2, u3, u4 = t0[j], t1[j], t2[j], t3[j], t4[j]
        o0[j] = (((a0 * u0 + a1 * u1) + a2 * u2) + a3 * u3) + a4 * u4
        o1[j] = (((b0 * u0 + b1 * u1) + b2 * u2) + b3 * u3) + b4 * u4
        o2[j] = (((c0 * u0 + c1 * u1) + c2 * u2) + c3 * u3) + c4 * u4
        o3[j] = (((d0 * u0 + d1 * u1) + d2 * u2) + d3 * u3) + d4 * u4


@_inline
def _four_more_terms(w, ty, rows, b, jb, je, out):  # pragma: no cover - compiled
    """Add terms ``b`` to ``b + 3`` of row ``rows[q]``'s sums to ``out[q][jb:je]``, left to right."""
    r0, r1, r2, r3 = rows
    o0, o1, o2, o3 = out
    t0, t1, t2, t3 = ty[b, jb:je], ty[b + 1, jb:je], ty[b + 2, jb:je], ty[b + 3, jb:je]
    a0, a1, a2, a3 = w[r0, b], w[r0, b + 1], w[r0, b + 2], w[r0, b + 3]
    b0, b1, b2, b3 = w[r1, b], w[r1, b + 1], w[r1, b + 2], w[r1, b + 3]
    c0, c1, c2, c3 = w[r2, b], w[r2, b + 1], w[r2, b + 2], w[r2, b + 3]
    d0, d1, d2, d3 = w[r3, b], w[r3, b + 1], w[r3, b + 2], w[r3, b + 3]
    for j in range(je - jb):
        u0, u1, u2, u3 = t0[j], t1[j], t2[j], t3[j]
        s0 = (((o0[j] + a0 * u0) + a1 * u1) + a2 * u2) + a3 * u3
        s1 = (((o1[j] + b0 * u0) + b1 * u1) + b2 * u2) + b3 * u3
        s2 = (((o2[j] + c0 * u0) + c1 * u1) + c2 * u2) + c3 * u3
        s3 = (((o3[j] + d0 * u0) + d1 * u1) + d2 * u2) + d3 * u3
        o0[j], o1[j], o2[j], o3[j] = s0, s1, s2, s3


@njit(cache=True, nogil=True, error_model="numpy")
def product_kernel(w, ty, lo, hi, out):  # pragma: no cover - compiled
    """``out[i, j] = w[i, 0] ty[0, j] + w[i, 1] ty[1, j] + ...``, left to right, for rows ``lo <= i < hi``.

    Four rows at a time share each load of ``ty``, :data:`COLUMNS` columns
    at a time: the first one to five terms in one pass (all of them up to
    five terms), the rest four more per pass, each adding to what the pass
    before left in the output, which stays in cache.  A last group of fewer
    than four rows repeats its last row (each copy of it gets the same
    value).  Every value is formed as :meth:`.surface.SurfaceEvaluator.points`
    forms its sum, with the same roundings.
    """
    k, ny = w.shape[1], ty.shape[1]
    first = k if k < 2 else k - 4 * ((k - 2) // 4)  # 1 to 5; what is left is a multiple of four
    last = hi - 1
    for i in range(lo, hi, 4):
        rows = (i, min(i + 1, last), min(i + 2, last), min(i + 3, last))
        for jb in range(0, ny, COLUMNS):
            je = min(jb + COLUMNS, ny)
            out_rows = (out[rows[0], jb:je], out[rows[1], jb:je], out[rows[2], jb:je], out[rows[3], jb:je])
            _first_terms(w, ty, rows, jb, je, out_rows, first)
            for b in range(first, k, 4):
                _four_more_terms(w, ty, rows, b, jb, je, out_rows)
