"""The notebooks draw their figures: without an OpenGL they skip, naming the packages to install."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from systempackages import need_opengl  # noqa: E402


def pytest_runtest_setup(item):
    if item.path.suffix == ".ipynb":
        need_opengl(f"the figures of {item.path.name}")
