"""lagsym: exact Lagrange surfaces from a few control points, to the machine.

From a rectangular grid of control points lagsym derives the exact
tensor-product Lagrange polynomial ``z = F(x, y)``, samples it, compares it
with other surfaces, plans toolpaths and writes programs for CNC controls.
"""

from .errors import (
    ExitStatus,
    FormulaError,
    GridError,
    InputError,
    LagsymError,
    ProgramError,
    ToolpathError,
    TransferError,
)
from .grid import ControlGrid, CurvePoints, curve_from_points, grid_from_points, grid_from_table
from .io import read_any_points, read_curve_points, read_points
from .lagrange import LagrangeCurve, LagrangeSurface, lagrange_basis, lagrange_curve, lagrange_surface

__version__ = "0.1.0"

__all__ = [
    "ControlGrid",
    "CurvePoints",
    "ExitStatus",
    "FormulaError",
    "GridError",
    "InputError",
    "LagrangeCurve",
    "LagrangeSurface",
    "LagsymError",
    "ProgramError",
    "ToolpathError",
    "TransferError",
    "curve_from_points",
    "grid_from_points",
    "grid_from_table",
    "lagrange_basis",
    "lagrange_curve",
    "lagrange_surface",
    "read_any_points",
    "read_curve_points",
    "read_points",
]
