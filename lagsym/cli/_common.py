"""Helpers the sub-commands share: writing results to a file or stdout."""

from __future__ import annotations

from typing import IO

from ..io import write_text


def emit(text: str, output: str | None, out: IO[str]) -> None:
    """Write ``text`` (plus a final newline) to the file ``output``, atomically, or to ``out``."""
    if not text.endswith("\n"):
        text += "\n"
    if output and output != "-":
        write_text(output, text)
    else:
        out.write(text)
