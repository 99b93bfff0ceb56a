"""lagsym: exact Lagrange surfaces from a few control points, to the machine.

From a rectangular grid of control points lagsym derives the exact
tensor-product Lagrange polynomial ``z = F(x, y)``, samples it, compares it
with other surfaces, plans toolpaths and writes programs for CNC controls.
"""

from .cad import BezierPatch, BSplinePatch, bezier_patch, cad_patch
from .compare import Comparison, DeviationMeasures, compare_surfaces, deviation_measures, render_table
from .dnc import (
    PROFILES,
    LineFault,
    LineSettings,
    TransferProgress,
    TransferResult,
    plan_transfer,
    profile,
    receive_program,
    send_program,
)
from .dncplan import Program, parse_program, resume_setup
from .errors import (
    ExitStatus,
    FormulaError,
    GridError,
    InputError,
    LagsymError,
    ProgramError,
    RenderError,
    ToolpathError,
    TransferError,
)
from .evaluate import SurfaceEvaluator, surface_evaluator
from .export import write_sample
from .export.cad import write_cad
from .formula import Formula, parse_formula
from .gcode import Moves, move_points, parse_moves
from .grid import ControlGrid, CurvePoints, curve_from_points, grid_from_points, grid_from_table
from .io import read_any_points, read_curve_points, read_points
from .lagrange import LagrangeCurve, LagrangeSurface, lagrange_basis, lagrange_curve, lagrange_surface
from .macro import MacroProgram, macro_program, planned_points, predicted_error, program_stats
from .post.program import PointProgram, point_program, write_program
from .sampling import Sample, SampleGrid, sample, sample_grid
from .simulate import ControlAlarm, Simulation, simulate
from .surfaces import bezier_surface, bspline_surface, hermite_surface, make_surface
from .toolpath import Toolpath, drop_cutter, plan_toolpath, raster_pattern, scallop_stepover
from .verify import CutReport, simulate_cut

__version__ = "0.1.0"

__all__ = [
    "BezierPatch",
    "BSplinePatch",
    "bezier_patch",
    "cad_patch",
    "write_cad",
    "Comparison",
    "DeviationMeasures",
    "Formula",
    "bezier_surface",
    "bspline_surface",
    "compare_surfaces",
    "deviation_measures",
    "hermite_surface",
    "make_surface",
    "parse_formula",
    "render_table",
    "Sample",
    "SampleGrid",
    "SurfaceEvaluator",
    "sample",
    "sample_grid",
    "surface_evaluator",
    "write_sample",
    "ControlAlarm",
    "MacroProgram",
    "Simulation",
    "macro_program",
    "planned_points",
    "predicted_error",
    "program_stats",
    "simulate",
    "CutReport",
    "Moves",
    "PointProgram",
    "Toolpath",
    "drop_cutter",
    "move_points",
    "parse_moves",
    "plan_toolpath",
    "point_program",
    "raster_pattern",
    "scallop_stepover",
    "simulate_cut",
    "write_program",
    "PROFILES",
    "LineFault",
    "LineSettings",
    "Program",
    "TransferProgress",
    "TransferResult",
    "parse_program",
    "plan_transfer",
    "profile",
    "receive_program",
    "resume_setup",
    "send_program",
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
    "RenderError",
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
