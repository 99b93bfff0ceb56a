"""Evaluation in the power basis: the expanded expression, and coefficients in normalized coordinates.

The expanded expression in the user's coordinates loses digits with many
nodes (see :mod:`lagsym.evaluate`); it is kept for symbolic use.  A power
basis in coordinates normalized onto ``[-1, 1]`` is well conditioned for the
degrees lagsym handles: it is the form a control runs (:mod:`lagsym.macro.form`),
and :func:`power_partials` evaluates it, with its partial derivatives, in floats.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import polynomial as P

__all__ = ["PARTIALS", "power_partials", "lambdify_surface"]

PARTIALS = ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2))
"""The value, the first and the second partial derivatives, as orders ``(in x, in y)``."""


def power_partials(coefficients, x, y, *, centre=(0.0, 0.0), inverse_half_width=(1.0, 1.0),
                   orders=PARTIALS) -> dict[tuple[int, int], np.ndarray]:
    """Value and partial derivatives of ``sum_ab c[a][b] u**a v**b`` at ``(x, y)``, per unit of ``x`` and ``y``.

    Parameters
    ----------
    coefficients : 2-D sequence of numbers
        ``c[a][b]`` multiplies ``u**a v**b`` (exact rationals are rounded once).
    x, y : array_like
        Points; they broadcast together.
    centre, inverse_half_width : pair of numbers
        The normalized coordinates: ``u = (x - centre[0]) * inverse_half_width[0]``
        and ``v`` the same in ``y``.
    orders : sequence of (int, int)
        Which derivatives, ``(in x, in y)``; by default :data:`PARTIALS`.

    Returns
    -------
    dict
        ``{(a, b): d**(a+b) F / dx**a dy**b}`` at the points, floats.

    Examples
    --------
    >>> f = power_partials([[0, 0], [0, 1]], 3.0, 2.0, centre=(1, 0), inverse_half_width=(0.5, 1))
    >>> float(f[0, 0]), float(f[1, 0]), float(f[0, 1]), float(f[1, 1])
    (2.0, 1.0, 1.0, 0.5)
    """
    c = np.array([[float(v) for v in row] for row in coefficients])
    ku, kv = (float(k) for k in inverse_half_width)
    u = (np.asarray(x, dtype=float) - float(centre[0])) * ku
    v = (np.asarray(y, dtype=float) - float(centre[1])) * kv

    def partial(a: int, b: int) -> np.ndarray:
        cc = c
        if a:
            cc = P.polyder(cc, a, axis=0) if cc.shape[0] > a else np.zeros((1, cc.shape[1]))
        if b:
            cc = P.polyder(cc, b, axis=1) if cc.shape[1] > b else np.zeros((cc.shape[0], 1))
        return P.polyval2d(u, v, cc) * ku**a * kv**b

    return {(a, b): partial(a, b) for a, b in orders}


def lambdify_surface(surface):
    """The NumPy function of the exact expanded expression, ``f(x, y)``, by ``sympy.lambdify``.

    This is the route for arbitrary symbolic use (derivatives, composition,
    code generation).  It evaluates the power basis, so it is slower and,
    with many nodes, less accurate than :meth:`SurfaceEvaluator.grid`; the
    sampler never uses it.  The result broadcasts ``x`` and ``y`` like any
    NumPy function, also for a constant surface.
    """
    import sympy

    # The surface's own symbols, whose names its construction checked: a name is written into the code
    # lambdify generates, and an expression in symbols the arguments do not name would fail or worse.
    raw = sympy.lambdify(surface.symbols, surface.expr, modules="numpy")

    def f(x, y):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        return np.broadcast_to(raw(x, y), np.broadcast_shapes(x.shape, y.shape)) + 0.0

    f.__doc__ = f"z = {surface.expr}"
    return f
