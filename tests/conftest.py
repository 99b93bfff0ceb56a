"""Shared fixtures."""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
sys.path.insert(0, str(Path(__file__).resolve().parent))

os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
# No background compile from the commands the tests start: the session compiles the kernel itself (below), and
# tests/test_first_run.py turns it on where it is what is tested.
os.environ["LAGSYM_NO_BACKGROUND_COMPILE"] = "1"

settings.register_profile("ci", max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("dev", max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("ci" if os.environ.get("CI") else "dev")


from systempackages import SYSTEM_PACKAGES, missing_system_package, need_opengl  # noqa: E402,F401


def pytest_configure(config):
    """Fill Numba's cache once, before pytest-xdist starts its workers, when it holds no cutter kernel.

    On a fresh clone every worker would otherwise compile the same kernels at
    the same time, each for itself; compiled once here (every cutter shape and
    the evaluation kernels, in a process of its own so this one loads no
    Numba), the workers load them.
    """
    if hasattr(config, "workerinput"):
        return
    from lagsym.toolpath.warmup import cache_folder, kernel_cached

    if cache_folder() is not None and not kernel_cached():
        import subprocess

        subprocess.run([sys.executable, "-m", "lagsym.toolpath.warmup"], check=False)


@pytest.fixture(scope="session", autouse=True)
def _cutter_kernel_compiled():
    """The cutter kernel compiled into Numba's cache before any test runs.

    A cold cache (a fresh clone) makes the first command that drops a cutter
    say "compiling the cutter kernel" on standard error, which tests of a
    command's exact output do not expect; tests/test_first_run.py checks that
    line with a cache of its own.
    """
    import numpy as np

    from lagsym import lagrange_surface, read_points
    from lagsym.toolpath import drop_cutter

    surface = lagrange_surface(read_points(EXAMPLES / "paper-example-1.json"))
    x, y = surface.grid.x[0], surface.grid.y[0]
    drop_cutter(surface, np.array([float(x)]), np.array([float(y)]), 1.0)


@pytest.fixture
def line():
    """``start(kernel=False, **control)``: a socat pty pair (``kernel=True``: a relay-free kernel pair) with a simulated
    control started on its far end; ``(pair, control)``, both ended after the test."""
    from simcontrol import KernelPty, PtyPair, SimControl

    pairs, sims = [], []

    def start(kernel: bool = False, **kwargs):
        pair = KernelPty() if kernel else PtyPair()
        pairs.append(pair)
        sim = SimControl(pair.far, pair=None if kernel else pair, **kwargs)
        sim.start()
        sims.append(sim)
        return pair, sim

    yield start
    for sim in sims:
        sim.stop()
    for pair in pairs:
        pair.close()


@pytest.fixture(autouse=True)
def _socat(request):
    """Tests marked ``socat`` need Debian's socat for their pseudo-terminal pairs."""
    if request.node.get_closest_marker("socat") and shutil.which("socat") is None:
        missing_system_package("socat", "socat")


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


def made_once(tmp_path_factory, name: str, make):
    """``make()`` once for the whole run, shared by every pytest-xdist worker; the value (picklable) from then on.

    A module fixture is made on each worker that runs one of the module's
    tests: a job planned and read by rs274 took a minute of the run twice.
    The first worker to ask makes it and keeps it in a file beside the
    workers' temporary folders; the others wait for that one (a lock) and
    load it.
    """
    import fcntl
    import pickle

    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent  # the run's folder, above each worker's own
    kept = root / f"made-once-{name}.pickle"
    with open(root / f"made-once-{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if kept.exists():
            return pickle.loads(kept.read_bytes())
        value = make()
        kept.write_bytes(pickle.dumps(value))
        return value


def example_files(line: str) -> tuple[set[str], set[str]]:
    """The files in the working folder an example reads and those it writes (``-o``)."""
    import shlex

    words = shlex.split(line)[2:]
    written = {w for k, w in enumerate(words[1:]) if words[k] in ("-o", "--output")}
    read = {w for w in words if "." in w and "/" not in w and not w.startswith("-") and " " not in w} - written
    return read, written


def run_example(line: str, tmp_path_factory) -> str:
    """Run an example (a line of a command's help, ``lagsym ...``) in the working folder.

    One that writes files runs once in the whole run: where another test ran
    it already on the same inputs, its files are written again instead
    (:func:`made_once`).  Returns what it printed on standard error.
    """
    import hashlib
    import io
    import shlex

    from lagsym.cli import main

    def run():
        out, err = io.StringIO(), io.StringIO()
        status = main(shlex.split(line)[1:], out, err)
        assert status == 0, f"{line!r} exited {status}: {err.getvalue()}"
        return {name: Path(name).read_bytes() for name in writes}, err.getvalue()

    reads, writes = example_files(line)
    if not writes or any("/" in name for name in writes):
        return run()[1]
    key = hashlib.sha256(" ".join(shlex.split(line)).encode())
    for name in sorted(reads):
        key.update(name.encode() + b"\0" + (Path(name).read_bytes() if Path(name).is_file() else b""))
    files, err = made_once(tmp_path_factory, "example-" + key.hexdigest()[:24], run)
    for name, data in files.items():
        Path(name).write_bytes(data)
    return err


README_FINISHING = ("lagsym toolpath examples/paper-example-4.json --scale 20 --tool-diameter 6 --stepover 0.4 --step 0.2 "
                    "--feed 600 --safe-z 80 --dialect fanuc -o O1000.nc")
"""The README's finishing program, as the toolpath command's help gives it (:func:`run_example` runs it once)."""
