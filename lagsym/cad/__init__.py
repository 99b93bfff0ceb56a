"""The exact surface in the form CAD systems store surfaces: Bezier and B-spline patches.

:func:`cad_patch` converts the Lagrange surface (or a comparison surface's
control net) exactly; :mod:`lagsym.cad.solid` finds its lowest height and the
volume above a base.  File formats are in :mod:`lagsym.export.step`,
:mod:`lagsym.export.iges` and :mod:`lagsym.export.patchjson`.
"""

from .convert import (KERNEL_MAX_DEGREE, METHODS, bernstein_transform, bezier_patch, cad_patch, double_error_bound,
                      piecewise_patch)
from .patch import BezierPatch, BSplinePatch, de_casteljau, insert_knot, split_half
from .solid import HeightBounds, check_base, exact_height, lowest_height, polynomial_volume, volume

__all__ = [
    "KERNEL_MAX_DEGREE",
    "METHODS",
    "BezierPatch",
    "BSplinePatch",
    "HeightBounds",
    "bernstein_transform",
    "bezier_patch",
    "cad_patch",
    "check_base",
    "de_casteljau",
    "double_error_bound",
    "exact_height",
    "insert_knot",
    "lowest_height",
    "piecewise_patch",
    "polynomial_volume",
    "split_half",
    "volume",
]
