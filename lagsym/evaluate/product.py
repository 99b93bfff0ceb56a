"""Grid products ``W @ Ty`` whose every value is the sum a point forms, in NumPy or compiled.

A grid's heights are ``Z = W @ Ty``: ``W`` (one row per x grid line) holds
the surface's coefficients already contracted with the x basis, ``Ty`` the y
basis.  Each value here is added left to right, as
:meth:`.surface.SurfaceEvaluator.points` adds its terms at a point, not in
the order a BLAS product chooses (which differs between kernels by the last
bit), so a grid and the same points give the same bits.
"""

from __future__ import annotations

import numpy as np

from .engine import Engine, current_engine
from .threads import block_items

__all__ = ["PRODUCT_BLOCK", "aligned_empty", "grid_product", "readonly_view"]

PRODUCT_BLOCK = 1 << 15  # values of a grid product NumPy computes at a time: the block and its scratch stay in cache


def aligned_empty(n: int, m: int) -> np.ndarray:
    """An uninitialised ``(n, m)`` array whose first value starts a 64-byte cache line.

    With a multiple of eight values a row, every row does, and no store of a
    row straddles two lines.
    """
    buf = np.empty(n * m + 8)
    k = (-buf.ctypes.data % 64) // 8
    return buf[k:k + n * m].reshape(n, m)


def readonly_view(a: np.ndarray) -> np.ndarray:
    """``a`` seen read-only, so the compiled kernel has one version whatever the caller's arrays."""
    v = a.view()
    v.flags.writeable = False
    return v


def grid_product(w: np.ndarray, ty: np.ndarray, out: np.ndarray | None = None,
                 compiled: bool | None = None, engine: Engine | None = None) -> np.ndarray:
    """``out = w @ ty`` for a tall ``w`` and a wide ``ty`` with a short inner dimension, its terms added left to right.

    ``out[i, j] = w[i, 0] ty[0, j] + w[i, 1] ty[1, j] + ...``, each product
    rounded and then added in that order: the sum :meth:`.surface.SurfaceEvaluator.points`
    forms at a point, so a grid and the same points give the same bits.
    ``compiled`` (by default as ``engine`` rules for the size: an
    :class:`.engine.Engine`, the :func:`.engine.current_engine` by default)
    runs :func:`.compiled.product_kernel`, which writes each output row once
    from cache; NumPy computes blocks of :data:`PRODUCT_BLOCK` values, with
    the same bits.  A large grid's blocks of rows are shared among the
    threads of the engine's pool (:meth:`.threads.HelperPool.run_blocks`).
    """
    n, m = w.shape[0], ty.shape[1]
    out = aligned_empty(n, m) if out is None else out
    if w.shape[1] == 0:
        out[...] = 0.0
        return out
    engine = current_engine() if engine is None else engine
    if compiled is None:
        with engine.choose(n * m) as compiled:
            return grid_product(w, ty, out, compiled, engine)
    if compiled:
        from .compiled import product_kernel  # Numba loads with the compiled engine, not with lagsym

        target = out if out.flags.c_contiguous and out.flags.aligned else np.empty((n, m))
        wv, tv = (readonly_view(np.ascontiguousarray(a, dtype=float)) for a in (w, ty))
        engine.pool.run_blocks(lambda lo, hi: product_kernel(wv, tv, lo, hi, target), n, block_items(m, 4), m)
        if target is not out:
            out[...] = target
        return out
    rows = max(1, PRODUCT_BLOCK // max(m, 1))

    def work(lo, hi):
        term = np.empty((min(rows, hi - lo), m))
        for r in range(lo, hi, rows):
            e = min(r + rows, hi)
            z, t = out[r:e], term[:e - r]
            np.multiply(w[r:e, :1], ty[0], out=z)
            for b in range(1, w.shape[1]):
                np.multiply(w[r:e, b:b + 1], ty[b], out=t)
                z += t

    engine.pool.run_blocks(work, n, block_items(m, rows), m)
    return out
