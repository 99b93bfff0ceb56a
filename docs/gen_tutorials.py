"""Write the tutorial pages from the notebooks: ``python3 docs/gen_tutorials.py``.

Each page holds the notebook's text and code in order; the notebooks are run
by the test suite (nbmake), and tests/test_docs.py checks the pages are current.
"""

from __future__ import annotations

import json
from pathlib import Path

HERE = Path(__file__).resolve().parent
NOTEBOOKS = HERE.parent / "notebooks"
PAGES = {
    "01-lagrange-curves.ipynb": "curves.md",
    "02-lagrange-surfaces.ipynb": "surfaces.md",
    "03-comparison.ipynb": "comparison.md",
    "04-surface-to-machine.ipynb": "machining.md",
}


def _page(notebook: Path) -> str:
    nb = json.loads(notebook.read_text())
    parts = []
    for cell in nb["cells"]:
        src = "".join(cell["source"]).rstrip()
        if not src:
            continue
        if cell["cell_type"] == "markdown":
            parts.append(src)
        elif cell["cell_type"] == "code":
            parts.append("```python\n" + src + "\n```")
    parts.append(f"*This page follows the notebook `notebooks/{notebook.name}`; run it in Jupyter to see the "
                 f"figures and outputs.*")
    return "\n\n".join(parts) + "\n"


def pages() -> dict[Path, str]:
    """``{tutorial page path: its text}`` for every notebook that exists."""
    return {HERE / "tutorials" / page: _page(NOTEBOOKS / nb) for nb, page in PAGES.items() if (NOTEBOOKS / nb).exists()}


if __name__ == "__main__":
    (HERE / "tutorials").mkdir(exist_ok=True)
    for path, text in pages().items():
        path.write_text(text)
        print(f"wrote {path}")
