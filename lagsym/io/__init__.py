"""Every path lagsym reads or writes passes here.

- :mod:`~lagsym.io.files`: the bytes of an input (a regular file or standard
  input, within a size limit), programs as a control reads them, event logs;
- :mod:`~lagsym.io.points` and :mod:`~lagsym.io.table`: point files (JSON,
  CSV and other tables) into exact control grids;
- :mod:`~lagsym.io.write`: results written atomically, respecting what is at
  the path.
"""

from __future__ import annotations

from ..values import exact_number
from .files import (MAX_BYTES, MAX_FILE_POINTS, STDIN_SILENCE_S, EventLog, event_log, file_points_limit, read_bytes,
                    read_program, read_text)
from .points import (
    TABLE_SUFFIXES,
    SURFACE_FORMAT,
    PointsFile,
    ScatteredPoints,
    parse_curve_points,
    parse_points,
    read_any_points,
    read_curve_points,
    read_point_file,
    read_points,
    read_scattered_points,
    surface_file,
)
from .write import OutputNotice, atomic_path, atomic_write, check_apart, check_not_input, check_output, write_text

__all__ = [
    "read_points",
    "read_scattered_points",
    "ScatteredPoints",
    "surface_file",
    "SURFACE_FORMAT",
    "read_point_file",
    "PointsFile",
    "read_curve_points",
    "read_any_points",
    "read_program",
    "read_bytes",
    "read_text",
    "event_log",
    "EventLog",
    "parse_points",
    "parse_curve_points",
    "exact_number",
    "atomic_path",
    "atomic_write",
    "write_text",
    "check_output",
    "check_not_input",
    "check_apart",
    "OutputNotice",
    "MAX_BYTES",
    "MAX_FILE_POINTS",
    "file_points_limit",
    "STDIN_SILENCE_S",
    "TABLE_SUFFIXES",
]
