"""The floating-point side of a fit: the degrees asked for, candidates scored, the fit's amplification.

The candidates are scored in the Chebyshev basis of the data box, where the
least-squares problem is well conditioned, so the scores are accurate to many
digits; they rank the candidates, and the chosen one is then fitted exactly.
"""

from __future__ import annotations

import math
import re

from ..errors import InputError
from ..io.decimals import column_floats

__all__ = ["CRITERIA", "MAX_DEGREE", "AMPLIFICATION_SAMPLES", "parse_degree", "scores", "leave_one_out",
           "amplification", "samples_for"]

CRITERIA = ("gcv", "loo")
MAX_DEGREE = 12  # one polynomial beyond this is a piecewise surface's job
AMPLIFICATION_SAMPLES = 65  # per axis at most: the fit's Lebesgue function sampled on up to 65 x 65 points
AMPLIFICATION_WORK = 4_000_000  # sample points times data points: fewer samples for many points, at least 17 x 17
_BLOCK = 1 << 14  # data points a block of the amplification's matrix products takes


def parse_degree(degree) -> tuple[int, int] | None:
    if degree is None or degree == "auto":
        return None
    if isinstance(degree, str):
        if not re.fullmatch(r"[0-9]{1,6}(x[0-9]{1,6})?", degree.strip().lower()):
            raise InputError(f"degree {degree!r} should be a whole number (4), two (4x3) or 'auto'")
        vals = [int(v) for v in degree.strip().lower().split("x")]
    elif isinstance(degree, int) and not isinstance(degree, bool):
        vals = [degree]
    else:
        try:
            vals = [int(v) for v in degree]
        except (TypeError, ValueError):
            raise InputError(f"degree {degree!r} should be a whole number, a pair or 'auto'") from None
    if len(vals) == 1:
        vals = vals * 2
    if len(vals) != 2 or not all(0 <= v <= MAX_DEGREE for v in vals):
        raise InputError(f"degree {degree!r}: give degrees from 0 to {MAX_DEGREE} in x and y")
    return vals[0], vals[1]


def _chebyshev(values, lo: float, hi: float, top: int):
    import numpy as np

    t = (2 * np.asarray(values, dtype=float) - (lo + hi)) / (hi - lo) if hi > lo else np.zeros(len(values))
    return np.polynomial.chebyshev.chebvander(t, top)


def scores(points, weights, criterion: str, max_degree: tuple[int, int]) -> list[tuple[tuple[int, int], float]]:
    """Every candidate's score in floating point, in the Chebyshev basis of the box, lowest first.

    One QR factorization of the largest candidate's basis, ``A = Q R``, serves
    them all: a candidate's columns are ``Q R_S``, so its residual is the part
    of the data outside ``Q`` (common to all) plus that of a small problem in
    ``R_S``, and its own factors are ``Q U`` and ``T`` from ``R_S = U T``.  One
    pass over the points instead of one a candidate.
    """
    import numpy as np

    xs = column_floats(points, 0)
    ys = column_floats(points, 1)
    zs = column_floats(points, 2)
    w = np.ones(len(xs)) if weights is None else np.array([float(v) for v in weights])
    sw = np.sqrt(w)
    vx = _chebyshev(xs, xs.min(), xs.max(), max_degree[0])
    vy = _chebyshev(ys, ys.min(), ys.max(), max_degree[1])
    n, width = len(xs), max_degree[1] + 1
    q_all, r_all = np.linalg.qr((vx[:, :, None] * vy[:, None, :]).reshape(n, -1) * sw[:, None])
    target = sw * zs
    y = q_all.T @ target
    outside = target - q_all @ y  # what no candidate reaches
    base = float(outside @ outside)
    out = []
    for p in range(max_degree[0] + 1):
        for q in range(max_degree[1] + 1):
            k = (p + 1) * (q + 1)
            if k >= n:
                continue
            u, t = np.linalg.qr(r_all[:, [a * width + b for a in range(p + 1) for b in range(q + 1)]])
            diag = np.abs(np.diag(t))
            if diag.min() <= 1e-10 * diag.max():
                continue  # these points do not determine the degree
            inside = y - u @ (u.T @ y)
            if criterion == "gcv":
                s = n * (base + float(inside @ inside)) / (n - k) ** 2
            else:
                qs = q_all @ u
                h = np.einsum("ij,ij->i", qs, qs)
                s = float(np.mean(((outside + q_all @ inside) / (1 - h)) ** 2))
            out.append(((p, q), s))
    out.sort(key=lambda t: (t[1], sum(t[0])))
    return out


def samples_for(n: int) -> int:
    """The points per axis the amplification is sampled on, for ``n`` data points."""
    return max(17, min(AMPLIFICATION_SAMPLES, math.isqrt(AMPLIFICATION_WORK // n)))


def amplification(points, weights, degree: tuple[int, int], samples: int) -> float:
    """The largest value of the fit's Lebesgue function over a grid of the box, in floating point.

    With ``A`` the Chebyshev basis at the points and ``G = A^T W A``, the
    fitted value at ``(x, y)`` is ``b(x, y) G^-1 A^T W z``; the sum of the
    absolute values of that row's entries is the Lebesgue function.  ``G`` is
    well conditioned in the Chebyshev basis of the box, so the normal
    equations lose nothing here that matters to a figure of a few digits.
    """
    import numpy as np

    xs = column_floats(points, 0)
    ys = column_floats(points, 1)
    w = np.array([float(v) for v in weights]) if weights is not None else np.ones(len(xs))
    (p, q), n = degree, len(xs)
    lo_x, hi_x, lo_y, hi_y = xs.min(), xs.max(), ys.min(), ys.max()

    def basis(start: int):  # the Chebyshev basis at a block of the points, and times their weights
        sx, sy = xs[start:start + _BLOCK], ys[start:start + _BLOCK]
        a = (_chebyshev(sx, lo_x, hi_x, p)[:, :, None] * _chebyshev(sy, lo_y, hi_y, q)[:, None, :]).reshape(len(sx), -1)
        return a, a * w[start:start + _BLOCK, None]

    # In blocks of points: one pass for G, one for the sums, each a matrix product of a size BLAS runs well,
    # and no matrix as long as the data.
    gram = sum((a.T @ aw for a, aw in map(basis, range(0, n, _BLOCK))), np.zeros(((p + 1) * (q + 1),) * 2))
    k = samples
    gx = _chebyshev(np.linspace(lo_x, hi_x, k), lo_x, hi_x, p)
    gy = _chebyshev(np.linspace(lo_y, hi_y, k), lo_y, hi_y, q)
    b = (gx[:, None, :, None] * gy[None, :, None, :]).reshape(k * k, -1)
    coef = np.linalg.solve(gram, b.T).T  # b G^-1, one row an evaluation point
    sums = np.zeros(len(coef))
    for start in range(0, n, _BLOCK):
        sums += np.abs(coef @ basis(start)[1].T).sum(axis=1)
    return float(sums.max())


def leave_one_out(points, weights, residuals, degree: tuple[int, int]) -> float:
    """The leave-one-out score of exact ``residuals``, the mean of ``w (r / (1 - h))**2``, leverages ``h`` in floats."""
    import numpy as np

    n, k = len(points), (degree[0] + 1) * (degree[1] + 1)
    xs = column_floats(points, 0)
    ys = column_floats(points, 1)
    sw = np.sqrt(np.array([float(v) for v in (weights or (1,) * n)]))
    vx = _chebyshev(xs, xs.min(), xs.max(), degree[0])
    vy = _chebyshev(ys, ys.min(), ys.max(), degree[1])
    qm, _ = np.linalg.qr((vx[:, :, None] * vy[:, None, :]).reshape(n, k) * sw[:, None])
    h = np.einsum("ij,ij->i", qm, qm)
    r = np.array([float(v) for v in residuals]) * sw
    return float(np.mean((r / (1 - h)) ** 2))
