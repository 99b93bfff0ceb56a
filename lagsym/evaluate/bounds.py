"""Bounds of the rounding error of an evaluation in the Chebyshev basis.

The rounding error is a few units of rounding times ``sum |C[a, b]|``, which is
of the size of the surface itself (``|C[a, b]| <= 4 max |F|`` on the box),
whatever the nodes; beyond the control box the Chebyshev polynomials grow and
the bound with them.
"""

from __future__ import annotations

import numpy as np

from .chebyshev import chebyshev_matrix

__all__ = ["EPS", "EPS_BASIS", "chebyshev_error_bound"]

EPS = float(np.finfo(float).eps)
EPS_BASIS = 2.0**-63
"""The unit the basis's own rounding is counted in.  The compensated recurrence
(:class:`.chebyshev.CompensatedBasis`) carries its rounding errors, so before
its one rounding to float64 a value of degree ``k`` is within about ``k**2``
units of ``2**-106`` of the exact one; counting ``k**2`` units of ``2**-63``
(x86's ``longdouble``, which the basis once ran in) leaves a margin of some
twelve orders of magnitude."""


def _cheb_growth(n: int, smax: float) -> np.ndarray:
    """``max |T_k(s)|`` over ``|s| <= smax``: 1 inside ``[-1, 1]``, ``T_k(smax)`` beyond."""
    return chebyshev_matrix(np.array([max(smax, 1.0)]), n)[:, 0]


def _axis_error(n: int, smax: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-degree size ``|T_k|`` and rounding weight (in units of :data:`EPS_BASIS`) for one axis.

    The weight counts the recurrence (at most ``k**2`` units) and the
    rounding of ``s`` itself (``|ds| <= 2 u |s|``) carried through the slope
    ``|T_k'| <= k**2 |T_k|``.
    """
    k = np.arange(n, dtype=float)
    smax = max(smax, 1.0)
    return _cheb_growth(n, smax), k**2 * (1.0 + 2.0 * smax)


def chebyshev_error_bound(coefficients: np.ndarray, sx: float, sy: float) -> float:
    """Bound on the absolute rounding error of ``sum C[a, b] T_a(s) T_b(t)`` over ``|s| <= sx``, ``|t| <= sy``.

    ``sum |C[a, b]| |T_a| |T_b|`` times ``n + m + 2`` units of float64
    rounding (the coefficients, the basis values and the two matrix
    products) plus ``a**2 + b**2`` units of :data:`EPS_BASIS` for the basis's
    own rounding (recurrence and normalization).
    """
    n, m = coefficients.shape
    gx, wx = _axis_error(n, sx)
    gy, wy = _axis_error(m, sy)
    size = np.abs(coefficients) * np.outer(gx, gy)
    weight = EPS * (n + m + 2) + EPS_BASIS * (wx[:, None] + wy[None, :])
    return float(np.sum(size * weight))
