"""The cutter kernel compiled in the background after the first command of an install, so the first plan need not wait.

Numba compiles the cutter kernel (:mod:`.kernel`) and the evaluation
kernels (:mod:`lagsym.evaluate.compiled`) the first time they run and keeps
the machine code in its cache, beside the modules (or under
``NUMBA_CACHE_DIR``).  Compiling takes several seconds; loading takes a
fraction of one.  So when a ``lagsym`` command ends and the cache holds no
cutter kernel yet, :func:`start_in_background` starts a detached process
that runs the kernels once on a tiny surface, filling the cache:
the README's first command (``lagsym equation``) leaves the kernels ready for
the ``toolpath`` that follows (and the large evaluations of ``sample`` and
``verify``).  The process holds a lock in the cache while it compiles, so
no second one starts beside it, and a plan that starts meanwhile waits for
the kernel rather than compiling it a second time (both say so,
:mod:`.kernelcache`); a plan with no kernel cached and none compiling
compiles it itself and says so (:mod:`.compiling`).  The cutter kernel's
heaviest callees compile in two processes side by side (:mod:`.kernelahead`),
and the evaluation kernels then wait, at low priority, until no plan runs
(each plan holds a shared lock in the cache until its command ends), so the
first plan has the cores.

Nothing here imports Numba: the checks look for the cache's index file and lock (:mod:`.kernelcache`).
``LAGSYM_NO_BACKGROUND_COMPILE=1`` turns the background process off.  Where
the cache would not be beside the modules or under ``NUMBA_CACHE_DIR`` (a
read-only install), nothing is started, so no command starts a process
that cannot leave its work behind.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys

from .kernelcache import (KERNEL_FILE, cache_folder, compiling_in_background, holding_lock, kernel_cached,
                          wait_for_no_plan)

__all__ = ["OFF", "cache_folder", "kernel_cached", "start_in_background", "compile_kernels", "compile_cutter_kernel",
           "compile_evaluation_kernels"]

OFF = "LAGSYM_NO_BACKGROUND_COMPILE"


def start_in_background() -> bool:
    """Start the detached process that fills the cache, unless it holds the kernel, cannot or is told not to.

    Returns whether a process was started.  It runs in a session of its own
    (the evaluation kernels at low priority), reads and writes nothing the user sees, and a failure
    to start it is not an error: the next plan compiles as before.
    """
    if os.environ.get(OFF) == "1" or cache_folder() is None or kernel_cached() or compiling_in_background():
        return False
    try:
        # Run from the folder that holds this lagsym: ``-m`` looks in the working folder first, and a user's
        # working folder may be a clone with the sources of another (whose cache would be filled instead).
        subprocess.Popen([sys.executable, "-m", "lagsym.toolpath.warmup"], stdin=subprocess.DEVNULL,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
                         close_fds=True, cwd=KERNEL_FILE.parents[2])
    except OSError:
        return False
    return True


def compile_kernels() -> None:
    """Run the cutter kernel for each cutter shape, then the evaluation kernels, on a tiny surface: Numba caches
    them."""
    compile_cutter_kernel()
    compile_evaluation_kernels()


def _tiny_surface():
    from ..grid import grid_from_table
    from ..lagrange import lagrange_surface

    return lagrange_surface(grid_from_table([0, 1, 2], [0, 1, 2], [[0, 1, 0], [1, 2, 1], [0, 1, 0]]))


def compile_cutter_kernel() -> None:
    """Run the cutter kernel for each cutter shape on a tiny surface, its heaviest callees compiled ahead on two
    cores at once (:mod:`.kernelahead`)."""
    import numpy as np

    from .dropcutter import drop_cutter
    from .kernelahead import compile_ahead

    compile_ahead()
    surface, xs = _tiny_surface(), np.linspace(0.0, 2.0, 5)
    for shape, corner in (("ball", None), ("flat", None), ("bull", 0.1)):
        drop_cutter(surface, xs, xs, 0.5, shape, corner=corner)


def compile_evaluation_kernels() -> None:
    """Run the evaluation kernels on a batch large enough to run compiled."""
    import numpy as np

    from ..evaluate import evaluate_grid, evaluate_points
    from ..evaluate.engine import COMPILED_POINTS, Engine, use_engine

    side = int(COMPILED_POINTS ** 0.5) + 1
    surface, many = _tiny_surface(), np.linspace(0.0, 2.0, side)
    with use_engine(Engine("compiled")):
        evaluate_grid(surface, many, many)
        evaluate_points(surface, np.resize(many, COMPILED_POINTS), np.resize(many[::-1], COMPILED_POINTS))


if __name__ == "__main__":
    folder = cache_folder()
    if folder is None:  # nowhere to keep the machine code: nothing to do for later commands
        sys.exit(0)
    with holding_lock(folder) as mine:
        if mine:
            compile_cutter_kernel()  # at the user's priority: the next plan waits for it
            # The evaluation kernels serve later commands only: behind whatever the user runs next, after any plan.
            with contextlib.suppress(OSError):
                os.nice(10)
            with wait_for_no_plan(folder):
                compile_evaluation_kernels()
