"""Fast, numerically stable evaluation of Lagrange curves and surfaces (pure NumPy).

Nothing here evaluates the expanded power-basis polynomial: with many nodes
that loses digits (about 1e-3 absolute at 10x10 nodes over a 0-100 mm box).

The evaluator maps each axis affinely onto ``s`` in about ``[-1, 1]`` and
re-expresses the exact polynomial in the Chebyshev basis of ``s``, exactly,
in rational arithmetic, before a single rounding to floats:

    F(x, y) = sum_ab C[a, b] T_a(s(x)) T_b(s(y)).

On a grid this is the tensor product ``Z = Tx.T @ C @ Ty`` of two small
Chebyshev basis matrices; at scattered points it is a row-wise contraction.
The rounding error is a few units of rounding times ``sum |C[a, b]|``, which
is of the size of the surface itself (``|C[a, b]| <= 4 max |F|`` on the box),
whatever the nodes: unlike a Lagrange-basis evaluation it is not multiplied
by the Lebesgue constants.  :meth:`SurfaceEvaluator.error_bound` states the
bound for a given box.

The Lagrange basis itself, in the barycentric form

    L_j(t) = (w_j / (t - t_j)) / sum_k (w_k / (t - t_k)),

is kept for what needs the basis values: :func:`basis_matrix` and
:func:`lebesgue_constant`.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from fractions import Fraction
from math import comb

import flint
import numpy as np

from ._arrays import readonly as _readonly

__all__ = [
    "CHUNK_POINTS",
    "SurfaceEvaluator",
    "CurveEvaluator",
    "surface_evaluator",
    "curve_evaluator",
    "chebyshev_matrix",
    "chebyshev_transform",
    "lambdify_surface",
    "normalize",
    "barycentric_weights",
    "basis_matrix",
    "evaluate_curve",
    "evaluate_points",
    "evaluate_grid",
    "lebesgue_constant",
]

EPS = float(np.finfo(float).eps)
EPS_BASIS = float(np.finfo(np.longdouble).eps)  # the basis recurrence runs in longdouble
CHUNK_POINTS = 1 << 16  # scattered points are evaluated in blocks of this many (bounded memory, warm caches)


def _fmpq(v: Fraction) -> flint.fmpq:
    return flint.fmpq(v.numerator, v.denominator)


def _frac(v: flint.fmpq) -> Fraction:
    return Fraction(int(v.p), int(v.q))


def chebyshev_transform(nodes) -> tuple[float, float, flint.fmpq_mat]:
    """The affine map of an axis onto ``[-1, 1]`` and the exact power-to-Chebyshev matrix.

    Parameters
    ----------
    nodes : sequence of Fraction
        The nodes of the axis, increasing.

    Returns
    -------
    offset, scale : float
        ``s = (x - offset) / scale`` maps the nodes onto about ``[-1, 1]``.
        Both are floats so that the float evaluator and the exact transform
        use the same map.
    matrix : flint.fmpq_mat
        ``A`` with ``d = A @ c``: the Chebyshev coefficients ``d[k]`` (of
        ``T_k(s)``) of the polynomial whose power coefficients in ``x`` are
        ``c[a]``.  Exact.

    Examples
    --------
    >>> off, scale, a = chebyshev_transform([Fraction(0), Fraction(2)])
    >>> off, scale, [str(v) for v in a.entries()]
    (1.0, 1.0, ['1', '1', '0', '1'])
    """
    nodes = [Fraction(v) for v in nodes]
    n = len(nodes)
    a, b = nodes[0], nodes[-1]
    offset, scale = float((a + b) / 2), float((b - a) / 2) or 1.0
    o, h = Fraction(offset), Fraction(scale)
    # x**a = (o + h s)**a = sum_p C(a, p) o**(a-p) h**p s**p
    shift = flint.fmpq_mat(n, n, [_fmpq(comb(q, p) * o ** (q - p) * h**p) if q >= p else 0
                                  for p in range(n) for q in range(n)])
    # cheb[p, k]: coefficient of s**p in T_k(s)
    rows = [[1] + [0] * (n - 1), [0, 1] + [0] * (n - 2)][:n]
    for k in range(2, n):
        rows.append([2 * (rows[k - 1][p - 1] if p else 0) - rows[k - 2][p] for p in range(n)])
    cheb = flint.fmpq_mat(n, n, [rows[k][p] for p in range(n) for k in range(n)])
    return offset, scale, cheb.solve(shift)


def chebyshev_matrix(s, n: int, out: np.ndarray | None = None) -> np.ndarray:
    """``T_k(s)`` for ``k < n`` by the three-term recurrence, as an ``(n, len(s))`` float array.

    The recurrence runs in ``numpy.longdouble`` (64-bit mantissa on x86)
    and is rounded once to float64, so the basis values carry half a unit
    of rounding; where ``longdouble`` is plain float64 the bound of
    :meth:`SurfaceEvaluator.error_bound` accounts for it.

    Examples
    --------
    >>> chebyshev_matrix(np.array([0.5, 1.0]), 3).tolist()
    [[1.0, 1.0], [0.5, 1.0], [-0.5, 1.0]]
    """
    s = np.asarray(s).ravel().astype(np.longdouble, copy=False)
    v = np.empty((n, s.size), dtype=np.longdouble)
    v[0] = 1.0
    if n > 1:
        v[1] = s
    if n > 2:
        s2 = 2.0 * s
        for k in range(2, n):
            np.multiply(s2, v[k - 1], out=v[k])
            v[k] -= v[k - 2]
    if out is None:
        return v.astype(float)
    out = out[:, : s.size]
    out[...] = v
    return out


def _cheb_growth(n: int, smax: float) -> np.ndarray:
    """``max |T_k(s)|`` over ``|s| <= smax``: 1 inside ``[-1, 1]``, ``T_k(smax)`` beyond."""
    return chebyshev_matrix(np.array([max(smax, 1.0)]), n)[:, 0]


def _axis_error(n: int, smax: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-degree size ``|T_k|`` and rounding weight (in units of ``longdouble`` rounding) for one axis.

    The weight counts the recurrence (at most ``k**2`` units) and the
    rounding of ``s`` itself (``|ds| <= 2 u |s|``) carried through the slope
    ``|T_k'| <= k**2 |T_k|``.
    """
    k = np.arange(n, dtype=float)
    smax = max(smax, 1.0)
    return _cheb_growth(n, smax), k**2 * (1.0 + 2.0 * smax)


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

    def _s(self, x) -> np.ndarray:
        x = np.asarray(x, dtype=float).astype(np.longdouble)
        return (x - self.x_offset) / np.longdouble(self.x_scale)

    def _t(self, y) -> np.ndarray:
        y = np.asarray(y, dtype=float).astype(np.longdouble)
        return (y - self.y_offset) / np.longdouble(self.y_scale)

    def x_factor(self, xs) -> np.ndarray:
        """``W = Tx.T @ C`` for the grid lines ``xs``: shape ``(len(xs), m)``.

        A grid is then ``W @ self.y_basis(ys)``, one matrix product, which
        lets a sampler compute the small factor once and stream blocks of rows.
        """
        n = self.shape[0]
        return chebyshev_matrix(self._s(xs), n).T @ self.coefficients

    def y_basis(self, ys) -> np.ndarray:
        """``Ty``: the Chebyshev basis of the grid lines ``ys``, shape ``(m, len(ys))``."""
        return chebyshev_matrix(self._t(ys), self.shape[1])

    def grid(self, xs, ys) -> np.ndarray:
        """``Z[i, j] = F(xs[i], ys[j])`` on the grid ``xs`` x ``ys``.

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
        return self.snap_grid(self.x_factor(xs) @ self.y_basis(ys), xs, ys)

    @staticmethod
    def _hits(nodes: np.ndarray, exact: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Indices into ``v`` of values that are a node exactly, and which node."""
        k = np.clip(np.searchsorted(nodes, v), 0, len(nodes) - 1)
        hit = (nodes[k] == v) & exact[k]
        return np.flatnonzero(hit), k[hit]

    def snap_grid(self, z: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        """Set ``z[i, j]`` to the control height where ``(xs[i], ys[j])`` is a control point exactly; in place."""
        ix, kx = self._hits(self.x_nodes, self.x_exact, xs)
        if ix.size:
            iy, ky = self._hits(self.y_nodes, self.y_exact, ys)
            if iy.size:
                z[np.ix_(ix, iy)] = self.node_values[np.ix_(kx, ky)]
        return z

    def points(self, x, y, chunk: int = CHUNK_POINTS) -> np.ndarray:
        """``F(x, y)`` at scattered points; ``x`` and ``y`` broadcast together.

        Works in blocks of ``chunk`` points, so memory stays a few megabytes
        above the result whatever the number of points.
        """
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        shape = x.shape
        xf, yf = x.ravel(), y.ravel()
        n, m = self.shape
        out = np.empty(xf.size)
        c = self.coefficients.T  # (m, n)
        vx = np.empty((n, min(chunk, xf.size)))
        vy = np.empty((m, min(chunk, xf.size)))
        for lo in range(0, xf.size, chunk):
            hi = min(lo + chunk, xf.size)
            tx = chebyshev_matrix(self._s(xf[lo:hi]), n, vx)
            ty = chebyshev_matrix(self._t(yf[lo:hi]), m, vy)
            out[lo:hi] = np.einsum("bp,bp->p", c @ tx, ty)
        px, kx = self._hits(self.x_nodes, self.x_exact, xf)
        if px.size:
            py, ky = self._hits(self.y_nodes, self.y_exact, yf[px])
            out[px[py]] = self.node_values[kx[py], ky]
        return out.reshape(shape)

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
            the two matrix products) plus ``a**2 + b**2`` units of the
            basis's ``longdouble`` rounding (recurrence and normalization).
        """
        x0, x1, y0, y1 = self.bounds if box is None else box
        sx = max(abs((x0 - self.x_offset) / self.x_scale), abs((x1 - self.x_offset) / self.x_scale))
        sy = max(abs((y0 - self.y_offset) / self.y_scale), abs((y1 - self.y_offset) / self.y_scale))
        n, m = self.shape
        gx, wx = _axis_error(n, sx)
        gy, wy = _axis_error(m, sy)
        size = np.abs(self.coefficients) * np.outer(gx, gy)
        weight = EPS * (n + m + 2) + EPS_BASIS * (wx[:, None] + wy[None, :])
        return float(np.sum(size * weight))

    def relative_error_bound(self, box: tuple[float, float, float, float] | None = None) -> float:
        """:meth:`error_bound` as a fraction of :attr:`data_range`."""
        return self.error_bound(box) / self.data_range


@dataclass(frozen=True, eq=False)
class CurveEvaluator:
    """A 1-D Lagrange curve in the Chebyshev basis of a normalized coordinate (see :class:`SurfaceEvaluator`)."""

    offset: float
    scale: float
    coefficients: np.ndarray
    data_range: float

    def __call__(self, x) -> np.ndarray:
        """``F(x)`` for ``x`` of any shape."""
        x = np.asarray(x, dtype=float)
        s = (x.astype(np.longdouble) - self.offset) / np.longdouble(self.scale)
        return (self.coefficients @ chebyshev_matrix(s, len(self.coefficients))).reshape(x.shape)


def _data_range(values) -> float:
    values = [float(v) for v in values]
    spread = max(values) - min(values)
    return spread if spread > 0 else max(max(abs(v) for v in values), 1.0)


def _exact_floats(nodes) -> np.ndarray:
    a = np.array([Fraction(float(v)) == v for v in nodes])
    a.setflags(write=False)
    return a


_SURFACES: dict[int, SurfaceEvaluator] = {}


def surface_evaluator(surface) -> SurfaceEvaluator:
    """The :class:`SurfaceEvaluator` of a :class:`~lagsym.lagrange.LagrangeSurface`.

    The exact change of basis is done once per surface object and remembered
    while the object lives.
    """
    key = id(surface)
    found = _SURFACES.get(key)
    if found is not None:
        return found
    g = surface.grid
    xo, xh, ax = chebyshev_transform(g.x)
    yo, yh, ay = chebyshev_transform(g.y)
    n, m = g.shape
    power = flint.fmpq_mat(n, m, [_fmpq(c) for row in surface.coefficients for c in row])
    cheb = ax * power * ay.transpose()
    coeffs = np.array([[float(_frac(cheb[a, b])) for b in range(m)] for a in range(n)])
    ev = SurfaceEvaluator(
        x_offset=xo, x_scale=xh, y_offset=yo, y_scale=yh,
        coefficients=_readonly(coeffs),
        data_range=_data_range(v for row in g.z for v in row),
        bounds=tuple(float(v) for v in g.bounds),
        x_nodes=g.x_array,
        y_nodes=g.y_array,
        x_exact=_exact_floats(g.x),
        y_exact=_exact_floats(g.y),
        node_values=_readonly(g.z_array),
    )
    _SURFACES[key] = ev
    weakref.finalize(surface, _SURFACES.pop, key, None)
    return ev


_CURVES: dict[int, CurveEvaluator] = {}


def curve_evaluator(curve) -> CurveEvaluator:
    """The :class:`CurveEvaluator` of a :class:`~lagsym.lagrange.LagrangeCurve` (remembered like :func:`surface_evaluator`)."""
    key = id(curve)
    found = _CURVES.get(key)
    if found is not None:
        return found
    off, scale, a = chebyshev_transform(curve.points.x)
    n = len(curve.coefficients)
    d = a * flint.fmpq_mat(n, 1, [_fmpq(c) for c in curve.coefficients])
    ev = CurveEvaluator(offset=off, scale=scale,
                        coefficients=_readonly([float(_frac(d[k, 0])) for k in range(n)]),
                        data_range=_data_range(curve.points.y))
    _CURVES[key] = ev
    weakref.finalize(curve, _CURVES.pop, key, None)
    return ev


def lambdify_surface(surface):
    """The NumPy function of the exact expanded expression, ``f(x, y)``, by ``sympy.lambdify``.

    This is the route for arbitrary symbolic use (derivatives, composition,
    code generation).  It evaluates the power basis, so it is slower and,
    with many nodes, less accurate than :meth:`SurfaceEvaluator.grid`; the
    sampler never uses it.  The result broadcasts ``x`` and ``y`` like any
    NumPy function, also for a constant surface.
    """
    import sympy

    from .lagrange import X, Y

    raw = sympy.lambdify((X, Y), surface.expr, modules="numpy")

    def f(x, y):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        return np.broadcast_to(raw(x, y), np.broadcast_shapes(x.shape, y.shape)) + 0.0

    f.__doc__ = f"z = {surface.expr}"
    return f


def normalize(nodes: np.ndarray, t) -> tuple[np.ndarray, np.ndarray]:
    """Map ``nodes`` and ``t`` affinely so that the nodes span ``[-1, 1]``."""
    nodes = np.asarray(nodes, dtype=float)
    a, b = nodes.min(), nodes.max()
    mid, half = (a + b) / 2.0, (b - a) / 2.0
    return (nodes - mid) / half, (np.asarray(t, dtype=float) - mid) / half


def barycentric_weights(nodes) -> np.ndarray:
    """Barycentric weights ``w_j = 1 / prod_{k != j} (t_j - t_k)`` for nodes on [-1, 1], rescaled to max |w| = 1."""
    s = np.asarray(nodes, dtype=float)
    diff = s[:, None] - s[None, :]
    np.fill_diagonal(diff, 1.0)
    # Sum logs instead of multiplying so high degree cannot underflow.
    sign = np.prod(np.sign(diff), axis=1)
    logw = -np.sum(np.log(np.abs(diff)), axis=1)
    return sign * np.exp(logw - logw.max())


def basis_matrix(nodes, t) -> np.ndarray:
    """Values of every Lagrange basis polynomial on ``nodes`` at the points ``t``.

    Returns an array of shape ``t.shape + (len(nodes),)``; entry ``[..., j]``
    is ``L_j(t)``.  At a node the row is exactly one-hot.

    Examples
    --------
    >>> basis_matrix([0.0, 1.0, 2.0], [0.5, 2.0]).round(6).tolist()
    [[0.375, 0.75, -0.125], [0.0, 0.0, 1.0]]
    """
    s, u = normalize(nodes, t)
    w = barycentric_weights(s)
    shape = u.shape
    u = u.reshape(-1, 1)
    d = u - s[None, :]
    exact = d == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        q = w / d
        out = q / q.sum(axis=1, keepdims=True)
    hit = exact.any(axis=1)
    if hit.any():
        out[hit] = exact[hit].astype(float)
    return out.reshape(shape + (len(s),))


def evaluate_curve(curve, x) -> np.ndarray:
    """Evaluate a :class:`~lagsym.lagrange.LagrangeCurve` at ``x`` (any shape)."""
    return curve_evaluator(curve)(x)


def evaluate_points(surface, x, y) -> np.ndarray:
    """Evaluate a surface at scattered points; ``x`` and ``y`` broadcast together."""
    return surface_evaluator(surface).points(x, y)


def evaluate_grid(surface, xs, ys) -> np.ndarray:
    """Evaluate a surface on the grid ``xs`` x ``ys``; result ``Z[i, j] = F(xs[i], ys[j])``."""
    return surface_evaluator(surface).grid(xs, ys)


def lebesgue_constant(nodes, samples: int = 4001) -> float:
    """The Lebesgue constant ``max_t sum_j |L_j(t)|`` of ``nodes`` over their span.

    It bounds how much the interpolant can amplify an error in the data: 1 for
    two nodes, growing like ``2**n / (e n log n)`` for equally spaced nodes.

    Examples
    --------
    >>> round(lebesgue_constant([0.0, 1.0]), 6)
    1.0
    """
    s = np.asarray(nodes, dtype=float)
    t = np.linspace(s.min(), s.max(), samples)
    lam = np.abs(basis_matrix(s, t)).sum(axis=1)
    # Refine around the worst sample: the maximum lies between two samples.
    k = int(lam.argmax())
    lo, hi = t[max(k - 1, 0)], t[min(k + 1, len(t) - 1)]
    fine = np.linspace(lo, hi, 201)
    return float(max(lam.max(), np.abs(basis_matrix(s, fine)).sum(axis=1).max()))
