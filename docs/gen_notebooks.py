"""Run the notebooks and store their outputs: ``python3 docs/gen_notebooks.py [NAME.ipynb ...]``.

The notebooks are kept with their outputs, so a reader on a code host (and
the docs site, which shows them as they are stored) sees every equation,
table and figure.  tests/test_notebooks.py runs each notebook afresh and
checks that what it prints and displays is what is stored; run this after
changing a notebook or what lagsym prints.
"""

from __future__ import annotations

import base64
import struct
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOKS = ROOT / "notebooks"


def execute(path: Path, timeout: int = 900):
    """The notebook at ``path`` run from its own folder in a fresh kernel (with this checkout's lagsym)."""
    import os

    import nbformat
    from nbclient import NotebookClient

    nb = nbformat.read(path, as_version=4)
    pythonpath = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    old = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = pythonpath  # the kernel is a child process: it inherits the environment
    try:
        NotebookClient(nb, timeout=timeout, kernel_name="python3", record_timing=False,
                       resources={"metadata": {"path": str(path.parent)}}).execute()
    finally:
        if old is None:
            del os.environ["PYTHONPATH"]
        else:
            os.environ["PYTHONPATH"] = old
    return nb


def png_size(data: str) -> tuple[int, int]:
    """Width and height of a base64 PNG (from its IHDR chunk)."""
    raw = base64.b64decode(data[:64])
    return struct.unpack(">II", raw[16:24])


def outputs(nb) -> list[list[tuple]]:
    """What each code cell printed and displayed: text exactly (a stream whole), each picture as its size.

    A picture is compared by its size only: the same scene rendered by
    another OpenGL driver differs in a few pixels.
    """
    cells = []
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        seen = []
        for out in cell.get("outputs", []):
            if out.output_type == "stream":
                # A stream arrives in pieces as the kernel flushes it, which timing decides: compare it whole.
                if seen and seen[-1][:2] == ("stream", out.name):
                    seen[-1] = ("stream", out.name, seen[-1][2] + out.text)
                else:
                    seen.append(("stream", out.name, out.text))
            elif out.output_type == "error":
                seen.append(("error", out.ename, out.evalue))
            else:
                data = out.get("data", {})
                seen.append((out.output_type, tuple(sorted(
                    (kind, png_size(value) if kind == "image/png" else value) for kind, value in data.items()))))
        cells.append(seen)
    return cells


def store(path: Path) -> None:
    """Run the notebook and write it back with its outputs (metadata of each run left out)."""
    import nbformat

    nb = execute(path)
    for cell in nb.cells:
        cell.metadata.pop("execution", None)
    nbformat.write(nb, path)


def main(names: list[str]) -> None:
    paths = [NOTEBOOKS / n for n in names] if names else sorted(NOTEBOOKS.glob("*.ipynb"))
    for path in paths:
        store(path)
        print(f"stored {path.relative_to(ROOT)}")


if __name__ == "__main__":
    main(sys.argv[1:])
