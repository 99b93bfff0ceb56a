"""The exact change to the Chebyshev basis of normalized coordinates, and the basis values.

An axis is mapped affinely onto ``s`` in about ``[-1, 1]`` and the exact
power-basis polynomial is re-expressed, exactly, in the Chebyshev polynomials
``T_k(s)``; only the result is rounded.  :func:`chebyshev_basis` (compensated,
each value rounded once, for sampling) and :func:`chebyshev_matrix_float64`
(the plain recurrence, for the many small evaluations of a search) give the
basis values at points.
"""

from __future__ import annotations

from fractions import Fraction
from math import comb

import flint
import numpy as np

__all__ = ["SPLIT", "CompensatedBasis", "chebyshev_transform", "chebyshev_basis", "chebyshev_matrix",
           "chebyshev_matrix_float64", "data_range", "split"]


def fmpq(v: Fraction) -> flint.fmpq:
    """A :class:`~fractions.Fraction` as a python-flint rational."""
    return flint.fmpq(v.numerator, v.denominator)


def fraction(v: flint.fmpq) -> Fraction:
    """A python-flint rational as a :class:`~fractions.Fraction`."""
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
    shift = flint.fmpq_mat(n, n, [fmpq(comb(q, p) * o ** (q - p) * h**p) if q >= p else 0
                                  for p in range(n) for q in range(n)])
    # powers[k, p]: the coefficient of T_k(s) in s**p, in closed form,
    # s**p = 2**(1-p) sum_{k = p, p-2, ...} C(p, (p-k)/2) T_k(s) with the T_0 term halved.
    # Solving the triangular system of the T_k's power coefficients instead gives the same
    # matrix, but a general exact solve grows its intermediate rationals: over a minute for
    # 100 nodes with decimal coordinates, where this product takes under a second.
    powers = flint.fmpq_mat(n, n, [_power_in_chebyshev(k, p) for k in range(n) for p in range(n)])
    return offset, scale, powers * shift


def _power_in_chebyshev(k: int, p: int) -> flint.fmpq:
    """The coefficient of ``T_k(s)`` in ``s**p``."""
    if k > p or (p - k) % 2:
        return flint.fmpq(0)
    return flint.fmpq(comb(p, (p - k) // 2) * (1 if k == 0 else 2), 2**p)


SPLIT = 134217729.0
"""``2**27 + 1``: Veltkamp's constant, which splits a float64 into two halves of 26 bits whose products are exact."""


def split(v: float) -> tuple[float, float]:
    """``v = hi + lo`` with ``hi`` holding the upper 26 bits of ``v`` (Veltkamp's split of a scalar)."""
    c = SPLIT * v
    hi = c - (c - v)
    return hi, v - hi


class CompensatedBasis:
    """The Chebyshev basis at many points, compensated, with its scratch space reused from block to block.

    ``T_k((x - offset) / scale)`` for ``k < n``: ``s`` is formed as an
    unevaluated sum ``sh + sl`` (the subtraction's and the division's rounding
    errors recovered exactly), and the three-term recurrence ``T_k = 2 s T_{k-1}
    - T_{k-2}`` runs in float64 while the rounding error of every product and
    sum is recovered exactly (Dekker's product by Veltkamp's split, Knuth's
    sum) and carried in a second recurrence.  Each value is then rounded once:
    the result is as if the recurrence had run in about twice float64's
    precision (Ogita, Rump and Oishi's compensated algorithms).  Every
    operation is an elementwise float64 one, vectorized by NumPy, in the order
    :mod:`.compiled` runs it, so both give the same bits.
    """

    def __init__(self, size: int, degree: int):
        self.w = np.empty((10, size))
        self.u = np.empty((max(degree, 2), size))
        self.e = np.empty((max(degree, 2), size))

    def basis(self, x: np.ndarray, offset: float, scale: float, n: int, out: np.ndarray) -> np.ndarray:
        """``T_k((x - offset) / scale)`` for ``k < n`` into ``out[:, :len(x)]``; ``x`` is float64."""
        k = x.size
        d, b, dl, sh, shi, slo, p, pe, t1, t2 = self.w[:, :k]
        out = out[:, :k]
        o, h = float(offset), float(scale)
        hhi, hlo = split(h)
        # s = sh + sl: x - offset by Knuth's two-sum, then the division's remainder by Dekker's product
        np.subtract(x, o, out=d)
        np.subtract(d, x, out=b)
        np.subtract(d, b, out=t1)
        np.subtract(x, t1, out=t1)
        np.subtract(-o, b, out=dl)
        dl += t1
        np.divide(d, h, out=sh)
        self._split(sh, shi, slo, t1)
        np.multiply(sh, h, out=p)
        self._product_error(shi, slo, hhi, hlo, p, out=pe, t=t1)
        sl = self.e[1, :k]
        np.subtract(d, p, out=sl)
        sl -= pe
        sl += dl
        sl /= h
        out[0] = 1.0
        if n < 2:
            return out
        np.add(sh, sl, out=out[1])
        u, e = self.u[:, :k], self.e[:, :k]
        u[0], e[0], u[1] = 1.0, 0.0, sh
        for j in range(2, n):
            # p + pe = sh * u[j-1] exactly
            np.multiply(u[j - 1], sh, out=p)
            self._split(u[j - 1], d, b, t1)
            self._product_error(shi, slo, d, b, p, out=pe, t=t1)
            # u[j] + sigma = 2 p - u[j-2] exactly (p + p is exact)
            np.add(p, p, out=d)
            np.subtract(d, u[j - 2], out=u[j])
            np.subtract(u[j], d, out=b)
            np.subtract(u[j], b, out=t1)
            np.subtract(d, t1, out=t1)
            np.add(u[j - 2], b, out=t2)
            np.subtract(t1, t2, out=e[j])
            # e[j] = sigma + (2 (sh e[j-1] + sl u[j-1] + pe) - e[j-2])
            np.multiply(sh, e[j - 1], out=t1)
            np.multiply(sl, u[j - 1], out=t2)
            t1 += t2
            t1 += pe
            t1 += t1
            t1 -= e[j - 2]
            e[j] += t1
            np.add(u[j], e[j], out=out[j])
        return out

    @staticmethod
    def _split(v, hi, lo, c) -> None:
        """``v = hi + lo`` elementwise, Veltkamp's split."""
        np.multiply(v, SPLIT, out=c)
        np.subtract(c, v, out=hi)
        np.subtract(c, hi, out=hi)
        np.subtract(v, hi, out=lo)

    @staticmethod
    def _product_error(ahi, alo, bhi, blo, p, *, out, t) -> None:
        """``out = a b - p`` exactly for ``p = fl(a b)``: Dekker's product from the two splits."""
        np.multiply(ahi, bhi, out=out)
        out -= p
        np.multiply(ahi, blo, out=t)
        out += t
        np.multiply(alo, bhi, out=t)
        out += t
        np.multiply(alo, blo, out=t)
        out += t


def chebyshev_basis(x, offset: float, scale: float, n: int, out: np.ndarray | None = None) -> np.ndarray:
    """``T_k((x - offset) / scale)`` for ``k < n``, as an ``(n, len(x))`` float64 array, each value rounded once.

    The compensated recurrence of :class:`CompensatedBasis`: the normalization
    and the recurrence carry their rounding errors exactly, so before its one
    rounding to float64 each value is the exact ``T_k`` of the exact
    ``(x - offset) / scale`` within about ``k**2`` units of ``2**-106`` (of
    ``T_k``'s size; what is neglected is the error terms' own rounding), and
    in practice it is rounded correctly.  The same in float64 on every
    platform, with no ``longdouble``.  A value beyond about ``1e300`` (far
    outside the box, at a high degree) overflows the split and comes out NaN.

    Examples
    --------
    >>> chebyshev_basis(np.array([2.0, 3.0]), 2.0, 2.0, 3).tolist()
    [[1.0, 1.0], [0.0, 0.5], [-1.0, -0.5]]
    """
    x = np.asarray(x, dtype=float).ravel()
    out = np.empty((n, x.size)) if out is None else out
    if x.size:
        CompensatedBasis(x.size, n).basis(x, offset, scale, n, out)
    return out[:, : x.size]


def chebyshev_matrix(s, n: int, out: np.ndarray | None = None) -> np.ndarray:
    """``T_k(s)`` for ``k < n`` by the compensated three-term recurrence, as an ``(n, len(s))`` float array.

    :func:`chebyshev_basis` with ``s`` already normalized.

    Examples
    --------
    >>> chebyshev_matrix(np.array([0.5, 1.0]), 3).tolist()
    [[1.0, 1.0], [0.5, 1.0], [-0.5, 1.0]]
    """
    return chebyshev_basis(s, 0.0, 1.0, n, out)


def chebyshev_matrix_float64(s, n: int) -> np.ndarray:
    """:func:`chebyshev_matrix` with the recurrence in float64: half the work, ``k**2`` units of rounding at degree ``k``.

    Examples
    --------
    >>> chebyshev_matrix_float64(np.array([0.5, 1.0]), 3).tolist()
    [[1.0, 1.0], [0.5, 1.0], [-0.5, 1.0]]
    """
    s = np.asarray(s, dtype=float).ravel()
    v = np.empty((n, s.size))
    v[0] = 1.0
    if n > 1:
        v[1] = s
    if n > 2:
        s2 = 2.0 * s
        for k in range(2, n):
            np.multiply(s2, v[k - 1], out=v[k])
            v[k] -= v[k - 2]
    return v


def data_range(values) -> float:
    """Spread of the data heights (``max - min``, or ``max |v|`` or 1 where flat): the scale errors are measured against."""
    values = [float(v) for v in values]
    spread = max(values) - min(values)
    return spread if spread > 0 else max(max(abs(v) for v in values), 1.0)
