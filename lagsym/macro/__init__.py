"""Parametric macro programs: the surface equation evaluated on the control (variable programming).

A point-list program for a fine finish runs to hundreds of kilobytes; a macro
program loops over integer-counted rows and points and computes each height on
the control from a well-conditioned form of the exact polynomial, so its size
does not depend on the step.  The modules, in the order data flows through them:

- :mod:`.model`: statements and expressions, and the control's decimal arithmetic;
- :mod:`.raster`: the raster counted on the control (:class:`MacroRaster`);
- :mod:`.form`: the normalized Horner or Lagrange form and its statements;
- :mod:`.ballend`: the normal offset and gouge check of a ball-end cutter;
- :mod:`.points`: the points a program should produce, computed on the PC;
- :mod:`.loops`: the counted loops every dialect renders (:class:`MacroLoops`);
- :mod:`.accuracy`: the control's arithmetic error, predicted;
- :mod:`.fanuc`, :mod:`.linuxcnc`, :mod:`.heidenhain`: one renderer a dialect;
- :mod:`.program`: :func:`macro_program`, the one entry point;
- :mod:`.stats`: the size comparison with a point list;
- :mod:`.roughing`, :mod:`.clearance`: the roughing macro (:func:`rough_macro`) and the proof of its clearance;
- :mod:`.roughpath`: the path the roughing macro's control computes, its descents held to the ramp angle.

:mod:`lagsym.simulate` dry-runs the result.
"""

from .accuracy import predicted_error
from .ballend import check_gouge, tip_points
from .form import FORMS, RowForm, row_form
from .loops import MacroLoops, macro_loops
from .points import planned_points, points_at
from .program import DEFAULT_PRECISION, MACRO_DIALECTS, PRECISIONS, MacroProgram, macro_program
from .clearance import Clearance
from .roughing import RoughMacro, rough_macro, rough_macro_program
from .raster import MacroRaster, macro_raster, raster_positions, sample_positions
from .stats import ProgramStats, point_list_size, program_stats, transfer_seconds

__all__ = [
    "Clearance",
    "RoughMacro",
    "rough_macro",
    "rough_macro_program",
    "DEFAULT_PRECISION",
    "FORMS",
    "MACRO_DIALECTS",
    "PRECISIONS",
    "MacroLoops",
    "MacroProgram",
    "MacroRaster",
    "ProgramStats",
    "RowForm",
    "check_gouge",
    "macro_loops",
    "macro_program",
    "macro_raster",
    "planned_points",
    "point_list_size",
    "points_at",
    "predicted_error",
    "program_stats",
    "raster_positions",
    "row_form",
    "sample_positions",
    "tip_points",
    "transfer_seconds",
]
