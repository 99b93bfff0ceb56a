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
