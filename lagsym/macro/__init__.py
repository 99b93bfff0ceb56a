"""Parametric macro programs: the surface equation evaluated on the control (variable programming).

A point-list program for a fine finish runs to hundreds of kilobytes; a macro
program loops over integer-counted rows and points and computes each height on
the control from a well-conditioned form of the exact polynomial, so its size
does not depend on the step.  One module per dialect (:mod:`.fanuc`,
:mod:`.linuxcnc`, :mod:`.heidenhain`) renders the shared loop plan
(:mod:`.program`); :mod:`.form` holds the normalized Horner form, :mod:`.plan`
the raster and the points a program should produce, :mod:`.ballend` the
normal offset and gouge check of a ball-end cutter, :mod:`.stats` the size
comparison with a point list.  :mod:`lagsym.simulate` dry-runs the result.
"""

from .ballend import check_gouge, tip_points
from .form import FORMS, RowForm, row_form
from .plan import MacroRaster, macro_raster, planned_points, raster_positions
from .program import (
    DEFAULT_PRECISION,
    MACRO_DIALECTS,
    PRECISIONS,
    MacroPlan,
    MacroProgram,
    macro_plan,
    macro_program,
    predicted_error,
)
from .stats import ProgramStats, point_list_size, program_stats, transfer_seconds

__all__ = [
    "DEFAULT_PRECISION",
    "FORMS",
    "MACRO_DIALECTS",
    "PRECISIONS",
    "MacroPlan",
    "MacroProgram",
    "MacroRaster",
    "ProgramStats",
    "RowForm",
    "check_gouge",
    "macro_plan",
    "macro_program",
    "macro_raster",
    "planned_points",
    "point_list_size",
    "predicted_error",
    "program_stats",
    "raster_positions",
    "row_form",
    "tip_points",
    "transfer_seconds",
]
