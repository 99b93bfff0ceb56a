"""lagsym: exact Lagrange surfaces from a few control points, to the machine.

From a rectangular grid of control points lagsym derives the exact
tensor-product Lagrange polynomial ``z = F(x, y)``, samples it, compares it
with other surfaces, plans toolpaths and writes programs for CNC controls.

The names below are loaded on first use, so ``import lagsym`` (and the
``lagsym --version`` or ``--help`` that start with it) costs almost nothing;
``from lagsym import lagrange_surface`` then imports what that name needs.
They are listed in the order the data flows: points, grid, exact polynomial,
evaluator, sampling and comparison, toolpath and programs, serial line.

Imported inside a running IPython shell (a Jupyter kernel), lagsym registers
the rich display of surfaces and curves, their equation and a small figure;
``%load_ext lagsym`` does the same after an earlier import.
"""

from __future__ import annotations

import importlib as _importlib
import os as _os
import signal as _signal
import sys as _sys
import types as _types


def _interrupted_at_start(signum, frame):
    """Ctrl-C while the ``lagsym`` command loads, before it can say more: one line, nothing written, exit 130."""
    _sys.stderr.write("lagsym: interrupted; nothing was written\n")
    _os._exit(130)


# Run as the command (``python -m lagsym``, which imports this first with argv[0] "-m", or the installed
# script), a Ctrl-C before the command line's own handlers are in place ends in one line, not a traceback
# from the imports; lagsym.cli.main puts Python's handler back.
if _sys.argv[:1] == ["-m"] or _os.path.basename(_sys.argv[0] if _sys.argv else "") in ("lagsym", "lagsym.exe"):
    _signal.signal(_signal.SIGINT, _interrupted_at_start)

from typing import TYPE_CHECKING  # noqa: E402

__version__ = "0.1.0"

_EXPORTS = {
    "errors": ("ExitStatus", "LagsymError", "InputError", "GridError", "ConditioningError", "FormulaError", "ToolpathError",
               "ProgramError", "RenderError", "TransferError"),
    "io": ("read_points", "read_curve_points", "read_any_points"),
    "grid": ("ControlGrid", "CurvePoints", "grid_from_points", "grid_from_table", "curve_from_points"),
    "lagrange": ("LagrangeCurve", "LagrangeSurface", "lagrange_curve", "lagrange_surface", "lagrange_basis"),
    "exactsize": ("exact_time_limit",),
    "fit": ("SurfaceFit", "fit_surface"),
    "conditioning": ("require_conditioning", "amplification"),
    "evaluate": ("SurfaceEvaluator", "surface_evaluator", "evaluate_points", "evaluate_grid", "evaluate_curve",
                 "lambdify_surface", "Engine", "use_engine"),
    "sampling": ("Sample", "SampleGrid", "sample", "sample_grid"),
    "export": ("write_sample",),
    "cad": ("BezierPatch", "BSplinePatch", "bezier_patch", "cad_patch"),
    "export.cad": ("write_cad",),
    "formula": ("Formula", "parse_formula"),
    "surfaces": ("make_surface", "bezier_surface", "bspline_surface", "hermite_surface"),
    "compare": ("Comparison", "DeviationMeasures", "compare_surfaces", "deviation_measures", "render_table"),
    "toolpath": ("Toolpath", "plan_toolpath", "drop_cutter", "raster_pattern", "scallop_stepover"),
    "toolpath.rough": ("Stock", "RoughSpec", "RoughPath", "rough_toolpath", "stock_around"),
    "job": ("JobSpec", "OperationSpec", "ToolSpec", "read_job", "Operation", "plan_job", "job_program",
            "cycle_minutes"),
    "gcode": ("Moves", "parse_moves", "move_points"),
    "verify": ("CutReport", "simulate_cut"),
    "post.program": ("PointProgram", "point_program", "write_program"),
    "macro": ("MacroProgram", "macro_program", "planned_points", "predicted_error", "program_stats", "RoughMacro",
              "rough_macro", "rough_macro_program"),
    "simulate": ("ControlAlarm", "Simulation", "simulate"),
    "dnc": ("Program", "parse_program", "resume_setup", "PROFILES", "LineSettings", "profile", "LineFault",
            "TransferProgress", "TransferResult", "transfer_segments", "send_program", "receive_program"),
}
_WHERE = {name: module for module, names in _EXPORTS.items() for name in names}

__all__ = [name for names in _EXPORTS.values() for name in names]


def __getattr__(name: str):
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'lagsym' has no attribute {name!r}")
    value = getattr(_importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value  # later look-ups skip this function
    return value


_HIDDEN = {"annotations", "TYPE_CHECKING"}  # module-level machinery, not part of the API


def __dir__() -> list[str]:
    return sorted((set(globals()) - _HIDDEN) | set(__all__))


class _Package(_types.ModuleType):
    """The package object: a public name that is also a subpackage's name stays the public value.

    Importing ``lagsym.simulate`` makes Python set the attribute ``simulate`` of
    the package to the subpackage, which would shadow the function of that
    name (``from lagsym import *`` gave a module that cannot be called).
    """

    def __setattr__(self, name, value):
        if isinstance(value, _types.ModuleType) and _WHERE.get(name) == name and value.__name__ == f"{__name__}.{name}":
            value = getattr(value, name)
        super().__setattr__(name, value)


_sys.modules[__name__].__class__ = _Package


def load_ipython_extension(ipython) -> None:
    """``%load_ext lagsym``: show surfaces and curves as their equation and a small figure.

    Registers :func:`lagsym.plot.inline.rich_html` as the ``text/html``
    formatter of :class:`~lagsym.lagrange.LagrangeSurface` and
    :class:`~lagsym.lagrange.LagrangeCurve` by name, so neither lagsym's
    numeric modules nor pyvista load before a value is displayed.  ``import
    lagsym`` calls it itself in a running shell; the magic is for a shell
    started after lagsym was imported.
    """
    formatter = ipython.display_formatter.formatters["text/html"]
    for name in ("LagrangeSurface", "LagrangeCurve"):
        formatter.for_type_by_name("lagsym.lagrange", name, _rich_html)


def _rich_html(value):
    # Imported on the first display, which pays for pyvista, not the import.  By name, like the
    # exports above: the package facade reaches each layer only on demand, at run time; a static
    # import here would put every module that reads lagsym.__version__ above the plot layer.
    return _importlib.import_module(".plot.inline", __name__).rich_html(value)


def _register_in_running_ipython() -> None:
    """Register the rich display when imported inside an IPython shell; never import IPython here."""
    ipython = _sys.modules.get("IPython")
    get_ipython = getattr(ipython, "get_ipython", None)
    shell = get_ipython() if callable(get_ipython) else None
    if getattr(shell, "display_formatter", None) is not None:
        load_ipython_extension(shell)


_register_in_running_ipython()


if TYPE_CHECKING:  # for type checkers and editors: the same names, imported eagerly
    from .compare import Comparison, DeviationMeasures, compare_surfaces, deviation_measures, render_table
    from .dnc import (PROFILES, LineFault, LineSettings, Program, TransferProgress, TransferResult, parse_program,
                      profile, receive_program, resume_setup, send_program, transfer_segments)
    from .errors import (ConditioningError, ExitStatus, FormulaError, GridError, InputError, LagsymError, ProgramError, RenderError,
                         ToolpathError, TransferError)
    from .cad import BezierPatch, BSplinePatch, bezier_patch, cad_patch
    from .exactsize import exact_time_limit
    from .evaluate import (Engine, SurfaceEvaluator, evaluate_curve, evaluate_grid, evaluate_points, lambdify_surface,
                           surface_evaluator, use_engine)
    from .export import write_sample
    from .export.cad import write_cad
    from .formula import Formula, parse_formula
    from .gcode import Moves, move_points, parse_moves
    from .job import (JobSpec, Operation, OperationSpec, ToolSpec, cycle_minutes, job_program, plan_job,
                      read_job)
    from .grid import ControlGrid, CurvePoints, curve_from_points, grid_from_points, grid_from_table
    from .io import read_any_points, read_curve_points, read_points
    from .lagrange import LagrangeCurve, LagrangeSurface, lagrange_basis, lagrange_curve, lagrange_surface
    from .fit import SurfaceFit, fit_surface
    from .conditioning import amplification, require_conditioning
    from .macro import (MacroProgram, RoughMacro, macro_program, planned_points, predicted_error, program_stats,
                        rough_macro, rough_macro_program)
    from .post.program import PointProgram, point_program, write_program
    from .sampling import Sample, SampleGrid, sample, sample_grid
    from .simulate import ControlAlarm, Simulation, simulate
    from .surfaces import bezier_surface, bspline_surface, hermite_surface, make_surface
    from .toolpath import Toolpath, drop_cutter, plan_toolpath, raster_pattern, scallop_stepover
    from .toolpath.rough import RoughPath, RoughSpec, Stock, rough_toolpath, stock_around
    from .verify import CutReport, simulate_cut
