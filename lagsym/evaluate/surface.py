"""Surfaces in the Chebyshev basis of normalized coordinates: values on grids and at points, derivatives, bounds.

``F(x, y) = sum_ab C[a, b] T_a(s(x)) T_b(t(y))`` with ``s`` and ``t`` mapping
the control box onto ``[-1, 1]**2``.  On a grid this is the tensor product
``Z = Tx.T @ C @ Ty`` of two small Chebyshev basis matrices; at scattered
points it is a row-wise contraction.  Sampling (:meth:`SurfaceEvaluator.grid`,
:meth:`SurfaceEvaluator.points`) runs the compensated basis recurrence, each
value rounded once, and passes through the control points exactly; a large
batch of scattered points runs it compiled (:mod:`.compiled`), with the same
bits; a search that evaluates many small
batches (drop-cutter) uses :meth:`SurfaceEvaluator.fast_points`, float64
throughout, and :meth:`SurfaceEvaluator.curvature_bound`.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import flint
import numpy as np
from numpy.polynomial import chebyshev as C

from .._arrays import readonly as _readonly
from ..errors import ConditioningError
from ..exactsize import ExactClock, stepped_product
from .bounds import chebyshev_error_bound
from .cache import ObjectCache
from .engine import COMPILED_POINTS, Engine, current_engine
from .product import grid_product, readonly_view
from .threads import block_items
from .chebyshev import (
    CompensatedBasis,
    chebyshev_basis,
    chebyshev_matrix_float64,
    chebyshev_transform,
    data_range,
    fmpq,
    split,
)

__all__ = ["CHUNK_POINTS", "COMPILED_POINTS", "FAST_CHUNK_POINTS", "SurfaceEvaluator", "surface_evaluator",
           "grid_product", "load_compiled"]

CHUNK_POINTS = 1 << 13  # NumPy evaluates scattered points in blocks of this many: their scratch stays in cache
FAST_CHUNK_POINTS = 1 << 14  # the float64 path's blocks: its basis matrices stay in cache


def _column(tx: np.ndarray, c: np.ndarray, b: int, out: np.ndarray, term: np.ndarray) -> np.ndarray:
    """``out = c[0, b] tx[0] + c[1, b] tx[1] + ...``, left to right: column ``b`` of ``W``, as grids and points form it."""
    np.multiply(tx[0], c[0, b], out=out)
    for a in range(1, c.shape[0]):
        np.multiply(tx[a], c[a, b], out=term)
        out += term
    return out


def load_compiled() -> None:
    """Load the compiled kernels now, so that every large batch after runs compiled (:mod:`.engine`).

    For a process that will evaluate many large batches (a notebook, a
    benchmark), which would otherwise first spend :data:`.engine.LOAD_SECONDS`
    in NumPy; under an ``"auto"`` :class:`.engine.Engine` every large batch
    after runs compiled.  The values are the same either way.
    """
    nodes, exact = _readonly(np.array([-1.0, 0.0, 1.0])), _readonly([True] * 3, bool)
    ev = SurfaceEvaluator(0.0, 1.0, 0.0, 1.0, _readonly(np.eye(3)), 1.0, (-1.0, 1.0, -1.0, 1.0), nodes, nodes,
                          exact, exact, _readonly(np.eye(3)))  # a small surface: its evaluation loads every kernel
    xs = np.linspace(-1.0, 1.0, 5)
    grid_product(ev.x_factor(xs, True), ev.y_basis(xs, True), compiled=True)
    ev._grid_hits(xs, xs, True)
    ev._compiled_into(np.empty(5), xs, xs, 0, 5, CHUNK_POINTS)


@dataclass(frozen=True, eq=False)
class SurfaceEvaluator:
    """A surface in the Chebyshev basis of normalized coordinates, ready for fast float evaluation.

    Build one with :func:`surface_evaluator`.

    Attributes
    ----------
    x_offset, x_scale, y_offset, y_scale : float
        ``s = (x - x_offset) / x_scale`` and ``t = (y - y_offset) / y_scale``
        map the control box onto about ``[-1, 1]**2``.
    coefficients : numpy.ndarray
        Read-only ``(n, m)``; ``coefficients[a, b]`` multiplies
        ``T_a(s) T_b(t)``.  Each is the exact coefficient rounded once.
    data_range : float
        Spread of the control heights (``max z - min z``, or ``max |z|`` or 1
        for a flat grid): the scale errors are measured against.
    bounds : tuple of float
        ``(x0, x1, y0, y1)``, the control box.
    x_nodes, y_nodes : numpy.ndarray
        The nodes as floats.
    x_exact, y_exact : numpy.ndarray
        Which nodes are floats exactly (``1/3`` is not).
    node_values : numpy.ndarray
        The control heights rounded once: the value wherever a sample point
        is a node exactly, so a sample passes through the control points.
    """

    x_offset: float
    x_scale: float
    y_offset: float
    y_scale: float
    coefficients: np.ndarray
    data_range: float
    bounds: tuple[float, float, float, float]
    x_nodes: np.ndarray
    y_nodes: np.ndarray
    x_exact: np.ndarray
    y_exact: np.ndarray
    node_values: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """Number of coefficients in x and in y (nodes of the control grid)."""
        return self.coefficients.shape

    def x_factor(self, xs, compiled: bool = False) -> np.ndarray:
        """``W = Tx.T @ C`` for the grid lines ``xs``: shape ``(len(xs), m)``.

        A grid is then ``grid_product(W, self.y_basis(ys))``, which lets a
        sampler compute the small factor once and stream blocks of rows.
        ``W[i, b] = C[0, b] Tx[0, i] + C[1, b] Tx[1, i] + ...``, left to right,
        as :meth:`points` forms it.  ``compiled`` runs the compiled kernels
        (for a large grid, where Numba is loaded anyway), with the same bits.
        """
        xs = np.asarray(xs, dtype=float).ravel()
        c = self.coefficients
        n, m = c.shape
        tx = self._basis(xs, self._axes()[0], n, compiled)
        w = np.empty((xs.size, m))
        if compiled:
            from .compiled import factor_kernel

            factor_kernel(readonly_view(tx), c, w)
            return w
        col, term = np.empty(xs.size), np.empty(xs.size)
        for b in range(m):
            w[:, b] = _column(tx, c, b, col, term)
        return w

    def y_basis(self, ys, compiled: bool = False) -> np.ndarray:
        """``Ty``: the Chebyshev basis of the grid lines ``ys``, shape ``(m, len(ys))``; ``compiled`` as :meth:`x_factor`."""
        return self._basis(np.asarray(ys, dtype=float).ravel(), self._axes()[1], self.shape[1], compiled)

    @staticmethod
    def _basis(v: np.ndarray, axis: tuple[float, ...], n: int, compiled: bool) -> np.ndarray:
        """:func:`.chebyshev.chebyshev_basis` of ``v`` on ``axis`` (``(offset, scale, ...)``), NumPy or compiled."""
        if not compiled:
            return chebyshev_basis(v, axis[0], axis[1], n)
        from .compiled import basis_kernel  # Numba loads with the compiled engine, not with lagsym

        out = np.empty((n, v.size))
        basis_kernel(readonly_view(v), np.array(axis), n, out)
        return out

    def grid(self, xs, ys, *, engine: Engine | None = None) -> np.ndarray:
        """``Z[i, j] = F(xs[i], ys[j])`` on the grid ``xs`` x ``ys``: the bits :meth:`points` gives at each.

        A grid of :data:`COMPILED_POINTS` values or more may run compiled, as
        ``engine`` rules (an :class:`.engine.Engine`; the
        :func:`.engine.current_engine` by default), with the same bits.

        Examples
        --------
        >>> from lagsym.grid import grid_from_points
        >>> from lagsym.lagrange import lagrange_surface
        >>> pts = [(1, 2, 7), (1, 3, 10), (1, 4, 13), (3, 2, 15), (3, 3, 18), (3, 4, 21),
        ...        (5, 2, 31), (5, 3, 34), (5, 4, 37)]
        >>> ev = surface_evaluator(lagrange_surface(grid_from_points(pts)))
        >>> ev.grid([1.0, 2.0], [2.0, 2.5]).tolist()
        [[7.0, 8.5], [10.0, 11.5]]
        """
        xs = np.asarray(xs, dtype=float).ravel()
        ys = np.asarray(ys, dtype=float).ravel()
        engine = current_engine() if engine is None else engine
        with engine.choose(xs.size * ys.size) as compiled:
            at, heights = self._grid_hits(xs, ys, compiled)  # while the small arrays are in cache, before the grid
            z = grid_product(self.x_factor(xs, compiled), self.y_basis(ys, compiled), compiled=compiled,
                             engine=engine)
        if heights is not None:
            z[at] = heights
        return z

    @staticmethod
    def _hits(nodes: np.ndarray, exact: np.ndarray, v: np.ndarray,
              compiled: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Indices into ``v`` of values that are a node exactly (ascending), and which node.

        Where ``v`` is a sorted axis many times longer than the nodes (a
        grid's lines), each node's run of equal values is found by bisection
        instead of looking up every value.  ``compiled`` looks up each value
        in one compiled pass (:func:`.compiled.hits_kernel`), with the same result.
        """
        if compiled:
            from .compiled import hits_kernel  # Numba loads with the compiled engine, not with lagsym

            return hits_kernel(readonly_view(nodes), readonly_view(exact), readonly_view(v))
        if v.size > 8 * nodes.size and np.all(v[:-1] <= v[1:]):
            lo, hi = np.searchsorted(v, nodes, "left"), np.searchsorted(v, nodes, "right")
            found = np.flatnonzero((hi > lo) & exact)
            if not found.size:
                return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
            return (np.concatenate([np.arange(lo[k], hi[k]) for k in found]),
                    np.repeat(found, hi[found] - lo[found]))
        k = np.minimum(np.searchsorted(nodes, v), len(nodes) - 1)
        hit = (nodes[k] == v) & exact[k]
        return np.flatnonzero(hit), k[hit]

    def _grid_hits(self, xs: np.ndarray, ys: np.ndarray, compiled: bool = False) -> tuple:
        """``(index, heights)``: the grid nodes ``(xs[i], ys[j])`` that are control points exactly, and their heights.

        ``(None, None)`` where there are none; ``compiled`` as :meth:`_hits`.
        """
        ix, kx = self._hits(self.x_nodes, self.x_exact, xs, compiled)
        if ix.size:
            iy, ky = self._hits(self.y_nodes, self.y_exact, ys, compiled)
            if iy.size:
                return np.ix_(ix, iy), self.node_values[np.ix_(kx, ky)]
        return None, None

    def snap_grid(self, z: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        """Set ``z[i, j]`` to the control height where ``(xs[i], ys[j])`` is a control point exactly; in place."""
        at, heights = self._grid_hits(xs, ys)
        if heights is not None:
            z[at] = heights
        return z

    def points(self, x, y, chunk: int = CHUNK_POINTS, *, engine: Engine | None = None) -> np.ndarray:
        """``F(x, y)`` at scattered points; ``x`` and ``y`` broadcast together.

        Each point's basis values come from the compensated recurrence of
        :func:`.chebyshev.chebyshev_basis`, rounded once, and the contraction
        ``sum_b (sum_a C[a, b] Tx[a]) Ty[b]`` adds its terms left to right, so
        :meth:`error_bound` holds; where ``(x, y)`` is a control point exactly
        its height is returned exactly.  A batch of :data:`COMPILED_POINTS` or
        more may run the compiled kernel of :mod:`.compiled`, as ``engine``
        rules (an :class:`.engine.Engine`; the :func:`.engine.current_engine`
        by default); otherwise the same operations run in NumPy, in blocks of
        ``chunk`` points whose scratch stays in cache.  The two give the same
        bits, and many points are shared among the engine's threads (:mod:`.threads`), so
        the values do not depend on the engine, the batch, the block or the
        threads.
        """
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        shape = x.shape
        xf, yf = x.ravel(), y.ravel()  # contiguous: copies of broadcast or strided inputs
        out = np.empty(xf.size)
        engine = current_engine() if engine is None else engine
        with engine.choose(xf.size) as compiled:
            into = self._compiled_into if compiled else self._numpy_into
            engine.pool.run_blocks(lambda lo, hi: into(out, xf, yf, lo, hi, chunk), xf.size, block_items(1, chunk))
        return out.reshape(shape)

    def _axes(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """Each axis's ``(offset, scale, scale's high half, its low half)``, as the kernels take them."""
        return ((self.x_offset, self.x_scale, *split(self.x_scale)),
                (self.y_offset, self.y_scale, *split(self.y_scale)))

    def _compiled_into(self, out, xf, yf, start: int, stop: int, chunk: int) -> None:
        """:meth:`points` of ``xf[start:stop], yf[start:stop]`` into ``out`` by the compiled kernel."""
        from .compiled import points_kernel  # Numba loads with the compiled engine, not with lagsym

        xa, ya = (np.array(a) for a in self._axes())
        points_kernel(readonly_view(xf), readonly_view(yf), start, stop, self.coefficients, xa, ya, out)
        self._snap_points(out[start:stop], xf[start:stop], yf[start:stop])

    def _numpy_into(self, out, xf, yf, start: int, stop: int, chunk: int) -> None:
        """:meth:`points` of ``xf[start:stop], yf[start:stop]`` into ``out``, in blocks of ``chunk`` from ``start``.

        The operations of :func:`.compiled.points_kernel`, a block at a time.
        """
        n, m = self.shape
        c = self.coefficients
        size = min(chunk, stop - start)
        work = CompensatedBasis(size, max(n, m))
        tx, ty = np.empty((n, size)), np.empty((m, size))
        wb, term = np.empty(size), np.empty(size)
        for lo in range(start, stop, chunk):
            hi = min(lo + chunk, stop)
            k = hi - lo
            bx = work.basis(xf[lo:hi], self.x_offset, self.x_scale, n, tx)
            by = work.basis(yf[lo:hi], self.y_offset, self.y_scale, m, ty)
            z, w, t = out[lo:hi], wb[:k], term[:k]
            for b in range(m):
                _column(bx, c, b, w, t)
                if b == 0:
                    np.multiply(w, by[0], out=z)
                else:
                    np.multiply(w, by[b], out=t)
                    z += t
            self._snap_points(z, xf[lo:hi], yf[lo:hi])

    def _snap_points(self, out: np.ndarray, x: np.ndarray, y: np.ndarray) -> None:
        """Set ``out`` to the control height where ``(x, y)`` is a control point exactly; in place."""
        hit = np.zeros(x.size, dtype=bool)
        for v in self.x_nodes[self.x_exact]:
            hit |= x == v
        if not hit.any():
            return
        px = np.flatnonzero(hit)
        kx = np.searchsorted(self.x_nodes, x[px])
        py, ky = self._hits(self.y_nodes, self.y_exact, y[px])
        out[px[py]] = self.node_values[kx[py], ky]

    def partial(self, dx: int = 0, dy: int = 0) -> np.ndarray:
        """Chebyshev coefficients of ``d**(dx+dy) F / dx**dx dy**dy``, per surface unit, in the same basis.

        Differentiated from the rounded :attr:`coefficients` (a few units of
        rounding more); the shape shrinks by the orders, to no less than 1.
        """
        c = np.asarray(self.coefficients, dtype=float)
        if dx:
            c = C.chebder(c, dx, scl=1.0 / self.x_scale, axis=0)
        if dy:
            c = C.chebder(c, dy, scl=1.0 / self.y_scale, axis=1)
        return c

    def fast_points(self, x, y, dx: int = 0, dy: int = 0) -> np.ndarray:
        """``F(x, y)``, or a partial derivative, at scattered points, in float64 throughout.

        For the many small evaluations of a search (drop-cutter): the basis
        recurrence runs in float64, so at degree ``k`` it adds up to ``k**2``
        units of float64 rounding where :meth:`points` adds long-double ones,
        and control points are not snapped to their heights.  Blocks of :data:`FAST_CHUNK_POINTS`
        keep the basis matrices in cache.  ``x`` and ``y`` broadcast together.

        Examples
        --------
        >>> from lagsym.grid import grid_from_points
        >>> from lagsym.lagrange import lagrange_surface
        >>> ev = surface_evaluator(lagrange_surface(grid_from_points([(0, 0, 0), (0, 2, 4), (2, 0, 2), (2, 2, 6)])))
        >>> ev.fast_points([1.0, 2.0], 1.0).round(12).tolist(), float(ev.fast_points(1.0, 1.0, dx=1))
        ([3.0, 4.0], 1.0)
        """
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        shape = x.shape
        s = (x.ravel() - self.x_offset) / self.x_scale
        t = (y.ravel() - self.y_offset) / self.y_scale
        c = (self.partial(dx, dy) if dx or dy else self.coefficients).T  # (m, n)
        m, n = c.shape
        out = np.empty(s.size)
        for lo in range(0, s.size, FAST_CHUNK_POINTS):
            hi = min(lo + FAST_CHUNK_POINTS, s.size)
            w = c @ chebyshev_matrix_float64(s[lo:hi], n)
            w *= chebyshev_matrix_float64(t[lo:hi], m)
            w.sum(axis=0, out=out[lo:hi])
        return out.reshape(shape)

    def curvature_bound(self, samples: int = 41) -> float:
        """Largest ``|F_xx|``, ``|F_yy|`` or ``|F_xy|`` seen on a ``samples`` x ``samples`` grid over the box (per surface unit).

        A sampled maximum, not a proof: the planners use it for the sag of a
        path between samples, whose own checks cover what it misses.
        """
        u = np.linspace(-1.0, 1.0, samples)
        out = 0.0
        for dx, dy in ((2, 0), (0, 2), (1, 1)):
            c = self.partial(dx, dy)
            tu, tv = chebyshev_matrix_float64(u, c.shape[0]), chebyshev_matrix_float64(u, c.shape[1])
            out = max(out, float(np.abs(tu.T @ c @ tv).max()))
        return out

    def error_bound(self, box: tuple[float, float, float, float] | None = None) -> float:
        """A bound on the absolute rounding error of :meth:`grid` and :meth:`points` over ``box``.

        Parameters
        ----------
        box : tuple of float, optional
            ``(x0, x1, y0, y1)``; the control box by default.  Beyond the
            control box (extrapolation) the Chebyshev polynomials grow and the
            bound with them.

        Returns
        -------
        float
            Against the exact value of the polynomial at the given float
            coordinates: ``sum |C[a, b]| |T_a| |T_b|`` times ``n + m + 2``
            units of float64 rounding (the coefficients, the basis values and
            the two matrix products) plus ``a**2 + b**2`` units of
            :data:`.bounds.EPS_BASIS` for the basis's own rounding (recurrence
            and normalization), which the compensated recurrence keeps far
            below that.
        """
        x0, x1, y0, y1 = self.bounds if box is None else box
        sx = max(abs((x0 - self.x_offset) / self.x_scale), abs((x1 - self.x_offset) / self.x_scale))
        sy = max(abs((y0 - self.y_offset) / self.y_scale), abs((y1 - self.y_offset) / self.y_scale))
        return chebyshev_error_bound(self.coefficients, sx, sy)

    def relative_error_bound(self, box: tuple[float, float, float, float] | None = None) -> float:
        """:meth:`error_bound` as a fraction of :attr:`data_range`."""
        return self.error_bound(box) / self.data_range



def _exact_floats(nodes) -> np.ndarray:
    a = np.array([Fraction(float(v)) == v for v in nodes])
    a.setflags(write=False)
    return a


def surface_evaluator(surface) -> SurfaceEvaluator:
    """The :class:`SurfaceEvaluator` of a :class:`~lagsym.lagrange.LagrangeSurface`.

    The exact change of basis is done once per surface object and remembered
    while the object lives (:class:`.cache.ObjectCache`: never handed to
    another object, even one at the same address).
    """
    return _SURFACES.get(surface)


def _make_evaluator(surface) -> SurfaceEvaluator:
    """The exact change of basis of ``surface``, rounded once to floats."""
    g = surface.grid
    xo, xh, ax = chebyshev_transform(g.x)
    yo, yh, ay = chebyshev_transform(g.y)
    n, m = g.shape
    power = flint.fmpq_mat(n, m, [fmpq(c) for row in surface.coefficients for c in row])
    clock = ExactClock(f"change of basis of the surface through {n} x {m} nodes (for its numeric evaluation)",
                       g.source)
    cheb = stepped_product(stepped_product(ax, power, clock=clock, products_after=1), ay.transpose(), clock=clock)
    try:
        # int / int is correctly rounded, as float(Fraction) is, without reducing a Fraction first
        coeffs = np.array([[int(cheb[a, b].p) / int(cheb[a, b].q) for b in range(m)] for a in range(n)])
    except OverflowError:
        digits = max(len(str(abs(int(cheb[a, b].p)) // int(cheb[a, b].q))) for a in range(n) for b in range(m))
        raise ConditioningError(
            f"{g.source}: the surface through {n} x {m} nodes has a coefficient of {digits} digits in the Chebyshev "
            f"basis of its box, beyond any float (at most 309 digits): it cannot be evaluated numerically; give "
            f"fewer nodes, fit lower degrees ('lagsym fit') or make a piecewise surface ('lagsym piecewise')") from None
    return SurfaceEvaluator(
        x_offset=xo, x_scale=xh, y_offset=yo, y_scale=yh,
        coefficients=_readonly(coeffs),
        data_range=data_range(v for row in g.z for v in row),
        bounds=tuple(float(v) for v in g.bounds),
        x_nodes=g.x_array,
        y_nodes=g.y_array,
        x_exact=_exact_floats(g.x),
        y_exact=_exact_floats(g.y),
        node_values=_readonly(g.z_array),
    )


_SURFACES: ObjectCache[SurfaceEvaluator] = ObjectCache(_make_evaluator)
