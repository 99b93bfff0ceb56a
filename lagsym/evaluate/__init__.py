"""Fast, numerically stable evaluation of Lagrange curves and surfaces (NumPy; a compiled kernel for large batches).

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

The modules, one concern each:

* :mod:`.chebyshev`: the exact change of basis and the basis values (the
  compensated recurrence, each value rounded once);
* :mod:`.compiled`: the same arithmetic for large batches of scattered points
  and grids, compiled (Numba), with the same bits;
* :mod:`.engine`: which of the two runs a large batch, an :class:`Engine`
  policy the caller may own (by default the compiled kernels once they have
  paid for their loading; ``Engine("numpy")`` turns them off);
* :mod:`.surface`: :class:`SurfaceEvaluator`, values on grids and at points,
  partial derivatives and the curvature bound (what drop-cutter needs);
* :mod:`.heights`: :func:`evaluate_points` and :func:`evaluate_grid`, the public calls (overflow named, not warned);
* :mod:`.curve`: :class:`CurveEvaluator`, the 1-D case;
* :mod:`.bounds`: the rounding-error bound;
* :mod:`.threads`: large grids and point sets shared among the threads of
  a :class:`~.threads.HelperPool`, bit for bit the values of one;
* :mod:`.cache`: what is computed once per surface or curve object,
  remembered while that object lives;
* :mod:`.barycentric`: the Lagrange basis itself, in the barycentric form
  ``L_j(t) = (w_j / (t - t_j)) / sum_k (w_k / (t - t_k))``, for what needs
  the basis values (:func:`basis_matrix`, :func:`lebesgue_constant`);
* :mod:`.power`: the power basis, for symbolic use (:func:`lambdify_surface`)
  and the normalized form a control runs (:func:`power_partials`).
"""

from __future__ import annotations

from .barycentric import barycentric_weights, basis_matrix, lebesgue_constant, normalize
from .bounds import EPS, EPS_BASIS
from .chebyshev import chebyshev_basis, chebyshev_matrix, chebyshev_matrix_float64, chebyshev_transform
from .curve import CurveEvaluator, curve_evaluator, evaluate_curve
from .engine import Engine, current_engine, use_engine
from .heights import evaluate_grid, evaluate_points
from .power import PARTIALS, lambdify_surface, power_partials
from .surface import (
    CHUNK_POINTS,
    COMPILED_POINTS,
    FAST_CHUNK_POINTS,
    SurfaceEvaluator,
    load_compiled,
    surface_evaluator,
)

__all__ = [
    "CHUNK_POINTS",
    "COMPILED_POINTS",
    "FAST_CHUNK_POINTS",
    "EPS",
    "EPS_BASIS",
    "PARTIALS",
    "SurfaceEvaluator",
    "CurveEvaluator",
    "Engine",
    "current_engine",
    "use_engine",
    "surface_evaluator",
    "curve_evaluator",
    "chebyshev_basis",
    "chebyshev_matrix",
    "chebyshev_matrix_float64",
    "chebyshev_transform",
    "lambdify_surface",
    "normalize",
    "barycentric_weights",
    "basis_matrix",
    "evaluate_curve",
    "evaluate_points",
    "evaluate_grid",
    "lebesgue_constant",
    "load_compiled",
    "power_partials",
]
