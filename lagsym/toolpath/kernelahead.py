"""The cutter kernel's heaviest callees compiled in two processes side by side, before the kernel itself.

Numba compiles a function's callees one after another, in the process that
first calls it, and keeps each in its cache; when it later compiles a caller
it loads a callee already there instead of compiling it again.  The cutter
kernel (:func:`.kernel.drop_chunk`) spends most of its compile in two
independent groups of callees, so :func:`compile_ahead` compiles one group
(:data:`PARTS` ``"newton"``) in a second process while this one compiles
the other (``"lattice"``), for the types ``drop_chunk`` calls them with
(:func:`signatures`).  ``drop_chunk`` then finds both in the cache.  On two
cores the kernel is ready in a little over half the time.

Should the types here ever differ from the ones ``drop_chunk`` passes, the
kernel compiles those callees itself as before: the cost comes back, the
result does not change (``tests/test_first_run.py`` checks that they match).
"""

from __future__ import annotations

import os
import subprocess
import sys

from .kernelcache import KERNEL_FILE

__all__ = ["PARTS", "signatures", "compile_part", "compile_ahead"]

PARTS = {"newton": ("_newton", "_refine"), "lattice": ("_candidates", "_starts")}
"""The callees of ``drop_chunk`` compiled ahead, in two groups that call nothing of each other."""


def signatures() -> dict[str, tuple]:
    """The argument types ``drop_chunk`` calls each callee of :data:`PARTS` with (C-contiguous arrays; the
    surface's coefficients read-only, as the planner hands them over)."""
    from numba import types

    f8, i8, b1 = types.float64, types.int64, types.boolean

    def a(dtype, dims, readonly=False):
        return types.Array(dtype, dims, "C", readonly=readonly)

    coefficients, row = a(f8, 2, True), a(f8, 1)
    return {
        "_newton": (a(f8, 2), i8, row, f8, f8, f8, f8, f8, row, row, row),
        "_refine": (coefficients, row, f8, f8, f8, f8, f8, f8, b1, a(f8, 2), row, row, row, row),
        "_candidates": (coefficients, row, f8, f8, a(f8, 2), row, row, row, row, row, a(b1, 1), a(f8, 2)),
        "_starts": (row, row, row, a(b1, 1), a(i8, 2), a(i8, 1), i8, i8, f8, f8, a(i8, 1), a(i8, 1), a(b1, 1),
                    a(i8, 1)),
    }


def compile_part(part: str) -> None:
    """Compile (or load from Numba's cache) the callees of ``PARTS[part]`` for their :func:`signatures`."""
    from . import kernel

    sigs = signatures()
    for name in PARTS[part]:
        getattr(kernel, name).compile(sigs[name])


def compile_ahead() -> None:
    """Compile the callees of :data:`PARTS`, ``"newton"`` in a second process while this one does ``"lattice"``.

    With one core, or where no second process starts, this one compiles
    both.  The second process is waited for, and ended with this one's
    block if that is left early (an interrupt): none outlives it.
    """
    child = None
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    if cores > 1:
        try:
            # From the folder that holds this lagsym, as the background compile runs (see .warmup).
            child = subprocess.Popen([sys.executable, "-m", __name__, "newton"], stdin=subprocess.DEVNULL,
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, close_fds=True,
                                     cwd=KERNEL_FILE.parents[2])
        except OSError:
            child = None
    try:
        compile_part("lattice")
        if child is None or child.wait() != 0:
            compile_part("newton")  # loads what the second process left in the cache, compiles what it did not
    finally:
        if child is not None and child.poll() is None:
            child.kill()
            child.wait()


if __name__ == "__main__":
    compile_part(sys.argv[1])
