"""Shared fixtures."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
sys.path.insert(0, str(Path(__file__).resolve().parent))

os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")

settings.register_profile("ci", max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("dev", max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("ci" if os.environ.get("CI") else "dev")


# Debian packages the tests use but do not fetch themselves (README, "System packages"). Where one is
# missing, the tests that need it skip with one line naming it; LAGSYM_TEST_REQUIRE_ALL=1 (set by
# .ci/run) makes that a failure instead, so a green CI run never hides a skipped check.
SYSTEM_PACKAGES = {
    "socat": "the serial-line tests (a pseudo-terminal pair to a simulated control)",
    "libegl1 libegl-mesa0 libgl1-mesa-dri": "pictures: VTK's offscreen OpenGL (EGL on Mesa)",
    "xvfb": "the test of the private-Xvfb fallback for pictures",
    "libgl1 libx11-6": "reading STEP and IGES files back with OpenCascade (cadquery-ocp loads libGL and libX11)",
}


def missing_system_package(packages: str, what: str) -> None:
    """Skip (or, under LAGSYM_TEST_REQUIRE_ALL, fail) a test whose Debian ``packages`` are not installed."""
    assert packages in SYSTEM_PACKAGES, packages
    line = f"{what} not found: install Debian's {packages} (apt-get install {packages})"
    if os.environ.get("LAGSYM_TEST_REQUIRE_ALL"):
        pytest.fail(line, pytrace=False)
    pytest.skip(line, allow_module_level=True)


@pytest.fixture(scope="session")
def rs274():
    """LinuxCNC's standalone interpreter (fetched from Debian into .cache if need be)."""
    from debtools import rs274 as find

    return find()


@pytest.fixture
def run_cli(capsys):
    """Run the ``lagsym`` command in-process; returns (status, stdout, stderr)."""
    import io

    from lagsym.cli import main

    def run(*argv):
        out, err = io.StringIO(), io.StringIO()
        status = main([str(a) for a in argv], out, err)
        return status, out.getvalue(), err.getvalue()

    return run
