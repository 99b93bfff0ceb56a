"""The numeric (float64) evaluator of a piecewise surface (:mod:`lagsym.surfaces.piecewise`).

Each piece is kept as its 4 x 4 local power coefficients in its cell's
coordinates ``s, t`` on ``[0, 1]``; a point is evaluated from the piece whose
cell holds it.  Drop-cutter, the planners, the sampler and the simulated cut
ask this evaluator what they ask :class:`~lagsym.evaluate.SurfaceEvaluator`
of one polynomial; it also bounds each piece's second derivatives from
their Bezier control points (certified, not sampled).
"""

from __future__ import annotations

from functools import cached_property
from math import comb

import numpy as np

from .._arrays import readonly

__all__ = ["PiecewiseEvaluator"]


def _axis(breaks: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cell of each coordinate (a border: the cell after it; clipped to the first and last) and its
    position in it (0 to 1 inside)."""
    i = np.clip(np.searchsorted(breaks, v, side="right") - 1, 0, len(breaks) - 2)
    return i, (v - breaks[i]) / (breaks[i + 1] - breaks[i])


def _chebder(c: np.ndarray, cnt: int, scl) -> np.ndarray:
    """:func:`numpy.polynomial.chebyshev.chebder` along the first axis with ``scl`` an array over the others:
    the same operations in the same order, so each slice is what ``chebder`` gives it with its own ``scl``."""
    c = np.array(c, dtype=float)
    n = len(c)
    for _ in range(cnt):
        n = n - 1
        c *= scl
        der = np.empty((n,) + c.shape[1:])
        for j in range(n, 2, -1):
            der[j - 1] = (2 * j) * c[j]
            c[j - 2] += (j * c[j]) / (j - 2)
        if n > 1:
            der[1] = 4 * c[2]
        der[0] = c[1]
        c = der
    return c


def _local_derivative(a: np.ndarray, d: int) -> np.ndarray:
    """Coefficients along the last axis of ``a`` differentiated ``d`` times (the same length, zero-padded)."""
    for _ in range(d):
        k = np.arange(1, a.shape[-1])
        a = np.concatenate([a[..., 1:] * k, np.zeros(a.shape[:-1] + (1,))], axis=-1)
    return a


class PiecewiseEvaluator:
    """The numeric (float64) evaluator of a :class:`~lagsym.surfaces.piecewise.PiecewiseSurface`, as the planner
    asks one.

    ``bounds``, ``fast_points`` (values and partial derivatives at scattered
    points) and ``curvature_bound`` answer as
    :class:`~lagsym.evaluate.SurfaceEvaluator`'s do; ``piece_evaluator(i, k)``
    is a piece's own evaluator, which drop-cutter searches on.
    """

    def __init__(self, surface):
        self.surface = surface
        g = surface.grid
        self.breaks_x = readonly(np.array([float(v) for v in g.x]))
        self.breaks_y = readonly(np.array([float(v) for v in g.y]))
        self.bounds = (float(g.x[0]), float(g.x[-1]), float(g.y[0]), float(g.y[-1]))
        n, m = surface.shape
        # int / int is correctly rounded, as float(Fraction) is
        self.local = readonly(np.array([[[int(v.p) / int(v.q) for v in surface.local_entries(i, k)]
                                         for k in range(m)] for i in range(n)]).reshape(n, m, 4, 4))
        self._derivatives: dict = {}

    @cached_property
    def upper_heights(self) -> np.ndarray:
        """``[i, k]``: no point of piece ``(i, k)`` lies above this (its highest Bezier control point, rounded up).

        A Bezier patch lies in the convex hull of its control points; the
        float rounding of the conversion is covered by a relative ``1e-12``.
        """
        w = np.array([[comb(j, a) / comb(3, a) if a <= j else 0.0 for a in range(4)] for j in range(4)])
        b = np.einsum("ja,ikab,lb->ikjl", w, self.local, w)
        top = b.max(axis=(2, 3))
        return readonly(top + 1e-12 * (np.abs(b).max(axis=(2, 3)) + 1.0))

    def part_upper_heights(self, parts: int) -> np.ndarray:
        """``[i, k, p, q]``: no point of part ``(p, q)`` of piece ``(i, k)``, its cell cut in ``parts`` x ``parts``
        equal parts, lies above this (the highest Bezier control point of the piece restricted to the part).

        Closer than :attr:`upper_heights` to the piece's height over a part;
        the float rounding of the change to each part's Bezier points is
        covered by a relative ``1e-12`` of the piece's largest coefficient.
        """
        found = self._part_tops.get(parts)
        if found is None:
            w = np.array([[comb(j, a) / comb(3, a) if a <= j else 0.0 for a in range(4)] for j in range(4)])
            edges = np.linspace(0.0, 1.0, parts + 1)
            # restricted[a, u]: s**u on [lo, hi] in powers of the part's own coordinate (s = lo + (hi - lo) r)
            change = [w @ np.array([[comb(u, a) * lo ** (u - a) * (hi - lo) ** a if a <= u else 0.0 for u in range(4)]
                                    for a in range(4)]) for lo, hi in zip(edges[:-1], edges[1:])]
            pad = 1e-12 * (np.abs(self.local).max(axis=(2, 3)) + 1.0)
            found = np.empty(self.local.shape[:2] + (parts, parts))
            across = np.stack(change).transpose(0, 2, 1)  # (parts, 4, 4): [q, b, l]
            for p, cx in enumerate(change):
                nets = np.matmul(np.matmul(cx, self.local)[:, :, None], across)  # [i, k, q, j, l]: row p's parts
                found[:, :, p, :] = nets.max(axis=(3, 4)) + pad[:, :, None]
            found = self._part_tops[parts] = readonly(found)
        return found

    @cached_property
    def _part_tops(self) -> dict:
        return {}

    @property
    def shape(self) -> tuple[int, int]:
        """Coefficients of a piece in x and in y."""
        return 4, 4

    def locate(self, x, y):
        """Piece indices and cell coordinates ``(i, k, s, t)`` of points (clipped to the box)."""
        bx, by = self.breaks_x, self.breaks_y
        i = np.clip(np.searchsorted(bx, x, side="right") - 1, 0, len(bx) - 2)
        k = np.clip(np.searchsorted(by, y, side="right") - 1, 0, len(by) - 2)
        hx, hy = bx[i + 1] - bx[i], by[k + 1] - by[k]
        return i, k, (x - bx[i]) / hx, (y - by[k]) / hy, hx, hy

    def fast_points(self, x, y, dx: int = 0, dy: int = 0) -> np.ndarray:
        """``F(x, y)`` or a partial derivative at scattered points, each from the piece whose cell holds it."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        shape = x.shape
        i, k, s, t, hx, hy = self.locate(x.ravel(), y.ravel())
        a = self._derived(dx, dy)[i, k]  # (N, 4, 4): a[p, u, v] multiplies s**u t**v
        ps = np.stack([np.ones_like(s), s, s * s, s * s * s], axis=1)
        pt = np.stack([np.ones_like(t), t, t * t, t * t * t], axis=1)
        z = np.einsum("pu,puv,pv->p", ps, a, pt) / (hx ** dx * hy ** dy)
        return z.reshape(shape)

    def grid(self, xs, ys, engine=None) -> np.ndarray:
        """``Z[i, j] = F(xs[i], ys[j])`` on a grid, each point from the piece whose cell holds it.

        Each value is a bicubic in its cell's coordinates on ``[0, 1]``: 16
        terms, so its rounding error is a few units of rounding times the
        piece's coefficients, about the size of the surface.  Points outside the box take
        the nearest edge piece (extrapolation).  ``engine`` is accepted as
        :meth:`lagsym.evaluate.SurfaceEvaluator.grid` takes it (pieces always run in NumPy).
        """
        xs = np.asarray(xs, dtype=float).ravel()
        ys = np.asarray(ys, dtype=float).ravel()
        i, s = _axis(self.breaks_x, xs)
        k, t = _axis(self.breaks_y, ys)
        ps = np.stack([np.ones_like(s), s, s * s, s * s * s], axis=1)
        pt = np.stack([np.ones_like(t), t, t * t, t * t * t], axis=1)
        out = np.empty((len(xs), len(ys)))
        rows = max(1, (1 << 16) // max(len(ys), 1))
        for r0 in range(0, len(xs), rows):
            r1 = min(r0 + rows, len(xs))
            w = np.einsum("pu,pkuv->pkv", ps[r0:r1], self.local[i[r0:r1]])  # (rows, pieces in y, 4)
            out[r0:r1] = np.einsum("pqv,qv->pq", w[:, k, :], pt)
        return out

    def _derived(self, dx: int, dy: int) -> np.ndarray:
        """Every piece's local coefficients differentiated ``dx`` times in s and ``dy`` in t (made once)."""
        found = self._derivatives.get((dx, dy))
        if found is None:
            a = _local_derivative(np.swapaxes(_local_derivative(np.swapaxes(self.local, 2, 3), dx), 2, 3), dy)
            found = self._derivatives[dx, dy] = readonly(a)
        return found

    def curvature_bound(self, samples: int = 5) -> float:
        """Largest ``|F_xx|``, ``|F_yy|`` or ``|F_xy|`` seen on ``samples`` x ``samples`` points of every piece.

        Each piece is sampled on its own closed cell, so the values either side of a border (where second
        derivatives jump) are both seen.
        """
        u = np.linspace(0.0, 1.0, samples)
        powers = np.stack([np.ones_like(u), u, u * u, u * u * u], axis=1)  # (samples, 4)
        hx, hy = np.diff(self.breaks_x), np.diff(self.breaks_y)
        worst = 0.0
        for dx, dy in ((2, 0), (0, 2), (1, 1)):
            a = self._derived(dx, dy)
            d = np.einsum("su,ikuv,tv->ikst", powers, a, powers)
            d = d / (hx[:, None, None, None] ** dx * hy[None, :, None, None] ** dy)
            worst = max(worst, float(np.abs(d).max()))
        return worst

    @cached_property
    def hessian_bounds(self) -> np.ndarray:
        """``[e, lo/hi, i, k]``: bounds of ``F_xx``, ``F_yy``, ``F_xy`` (``e`` 0, 1, 2) over all of piece ``(i, k)``.

        Certified, not sampled: each second derivative of a bicubic piece is a
        polynomial of degree at most 3 in each cell coordinate, and it lies
        between the lowest and highest of its Bezier control points over the
        closed cell; the float rounding of the conversion is covered by a
        relative ``1e-9``.  The values either side of a border (where second
        derivatives jump) are both inside, each from its own piece.
        """
        w = np.array([[comb(j, a) / comb(3, a) if a <= j else 0.0 for a in range(4)] for j in range(4)])
        hx, hy = np.diff(self.breaks_x), np.diff(self.breaks_y)
        out = np.empty((3, 2) + self.local.shape[:2])
        for e, (dx, dy) in enumerate(((2, 0), (0, 2), (1, 1))):
            a = self._derived(dx, dy)
            b = np.einsum("ja,ikab,lb->ikjl", w, a, w) / (hx[:, None, None, None] ** dx * hy[None, :, None, None] ** dy)
            pad = 1e-9 * (np.abs(b).max(axis=(2, 3)) + 1e-300)
            out[e, 0], out[e, 1] = b.min(axis=(2, 3)) - pad, b.max(axis=(2, 3)) + pad
        return readonly(out)

    def curvature_limits(self) -> tuple[float, float]:
        """The largest eigenvalue of the Hessian anywhere on the surface, and the largest absolute one (per unit).

        Certified from :attr:`hessian_bounds`: the largest eigenvalue
        ``(a + c) / 2 + sqrt(((a - c) / 2)**2 + b**2)`` of ``[[a, b], [b, c]]``
        rises with ``a``, ``c`` and ``|b|``, so each piece's highest ``F_xx``,
        ``F_yy`` and ``|F_xy|`` bound it; the lowest eigenvalue likewise from
        below.  The first figure is 0 at least.
        """
        (xx_lo, xx_hi), (yy_lo, yy_hi), (xy_lo, xy_hi) = self.hessian_bounds
        b = np.maximum(np.abs(xy_lo), np.abs(xy_hi))
        top = 0.5 * (xx_hi + yy_hi) + np.sqrt(0.25 * (xx_hi - yy_hi) ** 2 + b * b)
        low = 0.5 * (xx_lo + yy_lo) - np.sqrt(0.25 * (xx_lo - yy_lo) ** 2 + b * b)
        return max(float(top.max()), 0.0), float(np.maximum(top, -low).max())

    def jets_if_made(self) -> np.ndarray | None:
        """:attr:`piece_jets` if something has made them already, else None (nothing is made here)."""
        return self.__dict__.get("piece_jets")

    @cached_property
    def piece_jets(self) -> np.ndarray:
        """``[i, k]``: piece ``(i, k)``'s Chebyshev coefficients of ``F, F_x, F_y, F_xx, F_xy, F_yy`` stacked
        ``(24, 4)``, as :func:`lagsym.toolpath.newton.jet_coefficients` gives them (bit for bit), for every piece
        at once; each piece's evaluator is made on the way (:meth:`piece_evaluator`)."""
        n, m = self.local.shape[:2]
        evs = [[self.piece_evaluator(i, k) for k in range(m)] for i in range(n)]
        c = np.array([[e.coefficients for e in row] for row in evs])  # (n, m, 4, 4)
        sx = np.array([row[0].x_scale for row in evs])[:, None, None]  # per column of cells, over (n, m, 4)
        sy = np.array([evs[0][k].y_scale for k in range(m)])[None, :, None]
        parts = []
        for dx, dy in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)):
            d = c
            if dx:
                d = np.moveaxis(_chebder(np.moveaxis(d, 2, 0), dx, 1.0 / sx), 0, 2)
            if dy:
                d = np.moveaxis(_chebder(np.moveaxis(d, 3, 0), dy, 1.0 / sy), 0, 3)
            pad = np.zeros((n, m, 4, 4))
            pad[:, :, :d.shape[2], :d.shape[3]] = d
            parts.append(np.swapaxes(pad, 2, 3))
        return readonly(np.ascontiguousarray(np.concatenate(parts, axis=2)))

    def piece_evaluator(self, i: int, k: int):
        """The :class:`~lagsym.evaluate.SurfaceEvaluator` of piece ``(i, k)``, made on first use (kept by the
        surface, :meth:`~lagsym.surfaces.piecewise.PiecewiseSurface.piece_evaluator`)."""
        return self.surface.piece_evaluator(i, k)
