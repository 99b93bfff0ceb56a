"""Exact least-squares tensor-product polynomials through measured points (``lagsym fit``).

The paper (section 2) separates reliable data, which an interpolant may pass
through, from data with measurement errors, which calls for an approximating
function that "passes close to all the points but not necessarily through any
of them".  :func:`fit_surface` finds the polynomial

    ``p(x, y) = sum_{a <= P, b <= Q} c[a][b] x**a y**b``

that minimises ``sum_k w_k (z_k - p(x_k, y_k))**2`` over points given on a
grid or scattered, exactly: decimal text in the file is the decimal it spells
and the coefficients are the exact rational solution of the normal equations.

How it stays fast in exact arithmetic: every coordinate is scaled to an
integer (``x * Dx`` with ``Dx`` the common denominator of the x values, for
decimals a power of ten) and shifted by an integer near the middle of its
range, so the moments ``sum_k w_k u_k**s v_k**t`` and the right-hand side are
integer matrix products (python-flint's ``fmpz_mat``); the normal equations
``G c = r`` of size ``(P+1)(Q+1)`` are solved exactly (``fmpz_mat.solve``)
and the solution is carried back to powers of ``x`` and ``y`` by the exact
binomial change of variables.

The degrees may be chosen automatically.  Each candidate ``(P, Q)`` is scored
in floating point in the Chebyshev basis of the data box (well conditioned,
so the scores are accurate to many digits) by generalized cross-validation,
``GCV = N * RSS / (N - k)**2``, or by leave-one-out, ``PRESS = sum_k
w_k (r_k / (1 - h_kk))**2 / N`` (``h`` the leverages); the lowest score wins
and the chosen degrees are then fitted exactly, and their score recomputed
from the exact residuals.

The result is a :class:`SurfaceFit`; its :attr:`~SurfaceFit.surface` is a
:class:`~lagsym.lagrange.LagrangeSurface` through the fitted polynomial's
values at ``P+1`` by ``Q+1`` nodes near the Chebyshev extrema of the box, so
it *is* the fitted polynomial (a polynomial of degree ``P`` is its own
Lagrange interpolant on ``P+1`` nodes), well conditioned, and accepted by
every command and function that takes a surface.
"""

from __future__ import annotations

from .exact import fit_coefficients
from .hull import convex_hull, inside_hull, polygon_area
from .select import AMPLIFICATION_SAMPLES, CRITERIA, MAX_DEGREE
from .surface import NODE_DIGITS, SurfaceFit, fit_surface, representation_nodes

__all__ = ["SurfaceFit", "fit_surface", "fit_coefficients", "representation_nodes", "CRITERIA", "MAX_DEGREE",
           "AMPLIFICATION_SAMPLES", "NODE_DIGITS", "convex_hull", "polygon_area", "inside_hull"]
