"""The notebooks run, once each a session, and show what is stored in them.

They are kept with their outputs (docs/gen_notebooks.py stores them), so a
reader on a code host and the docs site see every result; here each runs
afresh in its own kernel and what it prints and displays must be what is
stored: text exactly, each picture at its stored size.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "docs"))

import gen_notebooks  # noqa: E402

NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_a_fresh_run_shows_what_the_notebook_stores(path):
    import nbformat

    from systempackages import need_opengl

    need_opengl(f"{path.name}, whose figures are rendered offscreen")
    stored = gen_notebooks.outputs(nbformat.read(path, as_version=4))
    fresh = gen_notebooks.outputs(gen_notebooks.execute(path))
    assert not any(kind == "error" for cell in fresh for kind, *_ in cell)
    for k, (old, new) in enumerate(zip(stored, fresh)):
        assert old == new, f"{path.name}, code cell {k + 1}: stored {old!r}, a fresh run shows {new!r}; " \
                           "run python3 docs/gen_notebooks.py"
    assert len(stored) == len(fresh)


def test_every_notebook_is_stored_run_with_its_equations_and_figures():
    """Each code cell ran in order (its outputs stored); the equations display as LaTeX, the figures as PNG."""
    kinds = set()
    assert len(NOTEBOOKS) == 6
    for path in NOTEBOOKS:
        cells = [c for c in json.loads(path.read_text())["cells"] if c["cell_type"] == "code"]
        assert [c["execution_count"] for c in cells] == list(range(1, len(cells) + 1)), path.name
        for c in cells:
            for out in c["outputs"]:
                kinds.update(out.get("data", {}))
                assert out["output_type"] != "error", path.name
                # an object's bare repr (a plotter not shown) is no output for a reader
                assert " at 0x" not in out.get("data", {}).get("text/plain", ""), (path.name, out)
    assert {"text/latex", "image/png", "text/html"} <= kinds, kinds
