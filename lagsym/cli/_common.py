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
