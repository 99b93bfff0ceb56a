"""Render the pictures of docs/paper.md with lagsym itself: ``python3 docs/gen_figures.py``."""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))

FIGURES = {
    "fig3-curve.png": ["plot", "examples/paper-curve-3rd.json"],
    "fig4-basis.png": ["plot", "examples/paper-example-2.json", "--show", "basis"],
    "fig9-surface.png": ["plot", "examples/paper-example-4.json"],
    "fig10-compare.png": ["plot", "examples/paper-example-4.json", "--show", "compare"],
    "fig11-growth.png": ["plot", "examples/parabola.json", "--show", "growth", "1/(1 + ((x-20)**2 + (y-20)**2)/25)"],
}


def main() -> int:
    from lagsym.cli import main as lagsym

    size = []  # the default size: sharp on the page, text legible
    for name, argv in FIGURES.items():
        if lagsym([*argv, *size, "-o", str(HERE / "images" / name)]) != 0:
            return 1
    with tempfile.TemporaryDirectory() as d:
        program = str(Path(d) / "rough.nc")
        if lagsym(["toolpath", "examples/paper-example-4.json", "--scale", "20", "--tool-diameter", "6",
                   "--stepover", "2", "--step", "1", "--safe-z", "80", "-o", program]) != 0:
            return 1
        if lagsym(["plot", "examples/paper-example-4.json", "--show", "toolpath", program, "--scale", "20",
                   *size, "-o", str(HERE / "images" / "fig12-toolpath.png")]) != 0:
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
