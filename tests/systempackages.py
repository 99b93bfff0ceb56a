"""The Debian packages the tests use but do not fetch themselves, and how a test says one is missing.

Used by tests/conftest.py (which also skips the notebooks, as they draw) and the tests that draw.
"""

from __future__ import annotations

import os

import pytest

# Debian packages the tests use but do not fetch themselves (README, "System packages"). Where one is
# missing, the tests that need it skip with one line naming it; LAGSYM_TEST_REQUIRE_ALL=1 (set by
# .ci/run) makes that a failure instead, so a green CI run never hides a skipped check.
SYSTEM_PACKAGES = {
    "socat": "the serial-line tests (a pseudo-terminal pair to a simulated control)",
    "libegl1 libegl-mesa0 libgl1-mesa-dri": "pictures: VTK's offscreen OpenGL (EGL on Mesa)",
    "xvfb": "the test of the private-Xvfb fallback for pictures",
    "libgl1 libx11-6": "reading STEP and IGES files back with OpenCascade (cadquery-ocp loads libGL and libX11)",
}


def missing_line(packages: str, what: str) -> str:
    """The one line that says which Debian ``packages`` to install for ``what``."""
    assert packages in SYSTEM_PACKAGES, packages
    return f"{what} not found: install Debian's {packages} (apt-get install {packages})"


def missing_system_package(packages: str, what: str) -> None:
    """Skip (or, under LAGSYM_TEST_REQUIRE_ALL, fail) a test whose Debian ``packages`` are not installed."""
    line = missing_line(packages, what)
    if os.environ.get("LAGSYM_TEST_REQUIRE_ALL"):
        pytest.fail(line, pytrace=False)
    pytest.skip(line, allow_module_level=True)


def can_render() -> bool:
    """Whether VTK can draw in this process (lagsym.plot's own choice of window)."""
    from lagsym import plot
    from lagsym.errors import RenderError

    try:
        plot.rendering_backend()
    except RenderError:
        return False
    return True


def need_opengl(what: str) -> None:
    """Skip (or fail, as :func:`missing_system_package`) when nothing here can render ``what``."""
    if not can_render():
        missing_system_package("libegl1 libegl-mesa0 libgl1-mesa-dri", f"an offscreen OpenGL (EGL or OSMesa) for {what}")
