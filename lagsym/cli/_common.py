"""Helpers the sub-commands share: writing results to a file or stdout."""

from __future__ import annotations

from typing import IO

from ..errors import InputError
from ..io import write_text


def emit(text: str, output: str | None, out: IO[str]) -> None:
    """Write ``text`` (plus a final newline) to the file ``output``, atomically, or to ``out``."""
    if not text.endswith("\n"):
        text += "\n"
    if output and output != "-":
        write_text(output, text)
    else:
        out.write(text)


def origin(text: str) -> tuple[float, float, float]:
    """``X,Y,Z`` in millimetres."""
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3 or not all(v == v and abs(v) != float("inf") for v in values):
        raise InputError(f"--origin {text!r} must be three numbers X,Y,Z in mm")
    return values


COLUMNS_HELP = ("which columns of a table are x, y, z: every column named in order (id,x,y,z) "
                "or the 1-based numbers of x, y, z (2,3,4); default: from the header, or the only columns")
SNAP_HELP = ("take node coordinates that differ by at most TOL as one node (measured grids, CMM jitter); "
             "says how many points moved and by how much")


def add_points_arguments(p) -> None:
    """The options of every command that reads a points file: ``--columns`` and ``--snap``."""
    p.add_argument("--columns", metavar="LIST", help=COLUMNS_HELP)
    p.add_argument("--snap", metavar="TOL", help=SNAP_HELP)


def load_points(path: str, args, err: IO[str], what: str = "surface"):
    """Read the points file ``path`` with the command's ``--columns`` and ``--snap``.

    How a table was read is said on ``err`` unless it is the plain x,y,z
    layout, and so is what ``--snap`` moved: a number read from the wrong
    column or a node moved too far should never pass unseen.  A command
    without the two options reads the file the same way.
    """
    from ..io import read_point_file

    f = read_point_file(path, what, getattr(args, "columns", None), getattr(args, "snap", None))
    if not f.plain:
        err.write(f"{path}: read as {f.layout}\n")
    if f.snapped is not None:
        err.write(f.snapped.text(str(path)) + "\n")
    return f.points


def add_program_arguments(g) -> None:
    """The program start and end options a point-list and a macro program share (argument group ``g``)."""
    from ..machine import COOLANTS, PROGRAM_LINE_ENDINGS

    g.add_argument("--scale", type=float, default=1.0,
                   help="model scale: the part is SCALE times the size the points describe, in their units "
                        "(a file in inches is 25.4 mm per unit at scale 1; default 1)")
    g.add_argument("--work-offset", default="G54", metavar="G5x",
                   help="work offset: G54 (default) to G59, G54.1 Pn (Fanuc), G59.1-G59.3 (LinuxCNC)")
    g.add_argument("--tool-number", type=int, default=1, metavar="N", help="tool number T (default 1)")
    g.add_argument("--length-offset", type=int, metavar="H",
                   help="tool length offset number for G43 H (default: the tool number)")
    g.add_argument("--feed-height", type=float, default=2.0, metavar="MM",
                   help="height above the first point where the rapid down ends and the plunge feed begins "
                        "(default 2); --safe-z must be at least this far above the path")
    g.add_argument("--coolant", choices=COOLANTS, default="off",
                   help="off (default), flood (M08) or mist (M07); M09 at the end")
    g.add_argument("--line-ending", choices=PROGRAM_LINE_ENDINGS, default="lf", help="lf (default) or crlf")


def program_settings(args, grid, **kw):
    """The :class:`~lagsym.machine.MachineSettings` of the program options, for a surface read from ``grid``.

    The surface's units (from its file; millimetres if it names none) and
    ``--scale`` give the millimetres per surface unit.
    """
    from ..machine import MachineSettings, mm_per_surface_unit

    units = grid.units or "mm"
    return MachineSettings(
        mm_per_unit=mm_per_surface_unit(units, args.scale), surface_units=units, origin_mm=origin(args.origin),
        units=args.units, feed_mm_min=args.feed, plunge_feed_mm_min=args.plunge_feed, spindle_rpm=args.spindle,
        safe_z_mm=args.safe_z, program_number=args.program, work_offset=args.work_offset,
        line_ending=args.line_ending, decimals=args.decimals, tool_number=args.tool_number,
        length_offset=args.length_offset, feed_height_mm=args.feed_height, coolant=args.coolant, **kw)
