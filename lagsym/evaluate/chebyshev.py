"""The exact change to the Chebyshev basis of normalized coordinates, and the basis values.

An axis is mapped affinely onto ``s`` in about ``[-1, 1]`` and the exact
power-basis polynomial is re-expressed, exactly, in the Chebyshev polynomials
``T_k(s)``; only the result is rounded.  :func:`chebyshev_matrix` (long
double, for sampling) and :func:`chebyshev_matrix_float64` (for the many small
evaluations of a search) give the basis values at points.
"""

from __future__ import annotations

from fractions import Fraction
from math import comb

import flint
import numpy as np

__all__ = ["chebyshev_transform", "chebyshev_matrix", "chebyshev_matrix_float64", "data_range"]


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
