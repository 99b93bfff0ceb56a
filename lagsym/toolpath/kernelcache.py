"""Numba's cache of the cutter kernel: where it is, whether it holds the kernel, whether a compile fills it now.

Nothing here imports Numba: the checks look for the cache's index file, and
for the lock the background compile (:mod:`.warmup`) holds while it runs.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import os
import time
from pathlib import Path

__all__ = ["KERNEL_FILE", "cache_folder", "kernel_cached", "compiling_in_background", "wait_for_background",
           "holding_lock", "hold_planning_lock", "wait_for_no_plan"]

KERNEL_FILE = Path(__file__).resolve().with_name("kernel.py")
_LOCK = "lagsym-compiling.lock"  # held by the background process while it compiles
_PLANNING = "lagsym-planning.lock"  # shared by the processes that plan, until they end
_planning: dict[Path, int] = {}  # the planning locks this process holds, by cache folder


def cache_folder(module: Path = KERNEL_FILE) -> Path | None:
    """Where Numba keeps the machine code of ``module``: under ``NUMBA_CACHE_DIR`` or beside it (None: elsewhere).

    The same rule as Numba's own cache locators: ``NUMBA_CACHE_DIR`` holds a
    folder named after the module's folder and a SHA-1 of its path; else the
    ``__pycache__`` beside the module, if it can be written.
    """
    root = os.environ.get("NUMBA_CACHE_DIR")
    folder = module.parent
    if root:
        return Path(root) / f"{folder.name}_{hashlib.sha1(str(folder).encode()).hexdigest()}"
    cache = folder / "__pycache__"
    writable = os.access(cache, os.W_OK) if cache.exists() else os.access(folder, os.W_OK)
    return cache if writable else None


def kernel_cached(folder: Path | None = None) -> bool:
    """Whether the cache already holds an index of the cutter kernel's machine code."""
    folder = cache_folder() if folder is None else folder
    return folder is not None and any(folder.glob(f"{KERNEL_FILE.stem}.drop_chunk-*.nbi"))


def compiling_in_background(folder: Path | None = None) -> bool:
    """Whether a background process is compiling into the cache now (it holds the lock file there)."""
    folder = cache_folder() if folder is None else folder
    if folder is None:
        return False
    try:
        fd = os.open(folder / _LOCK, os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        return False
    except BlockingIOError:
        return True
    finally:
        os.close(fd)


def wait_for_background(tell, *, after: float = 2.0, limit: float = 600.0) -> None:
    """Wait while the background compile runs and the cache holds no cutter kernel yet; ``tell()`` after ``after`` s.

    A plan that starts a few seconds after the install's first command
    would otherwise compile the same kernel beside it, each slowing the
    other: it waits for the kernel instead, which is further along.
    """
    folder = cache_folder()
    start, told = time.monotonic(), False
    while (folder is not None and not kernel_cached(folder) and compiling_in_background(folder)
           and time.monotonic() - start < limit):
        if not told and time.monotonic() - start >= after:
            tell()
            told = True
        time.sleep(0.05)


@contextlib.contextmanager
def holding_lock(folder: Path):
    """The lock that says a compile is running; nothing (and no compile) if another process holds it."""
    folder.mkdir(parents=True, exist_ok=True)
    fd = os.open(folder / _LOCK, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            yield False
            return
        yield True
    finally:
        os.close(fd)


def hold_planning_lock(folder: Path | None = None) -> bool:
    """Hold, until this process ends, a shared lock in the cache saying that a plan runs here; whether it is held.

    The background compile leaves the evaluation kernels, which no plan
    needs, until no process holds it (:func:`wait_for_no_plan`): compiling
    them beside the first plan would take a share of its cores.  A plan never
    waits for this lock: where the background process holds it (compiling
    now), the plan runs without it.
    """
    folder = cache_folder() if folder is None else folder
    if folder is None:
        return False
    if folder in _planning:
        return True
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd = os.open(folder / _PLANNING, os.O_RDONLY | os.O_CREAT, 0o644)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return False
    _planning[folder] = fd  # closed, and so released, when the process ends
    return True


@contextlib.contextmanager
def wait_for_no_plan(folder: Path, *, limit: float = 120.0):
    """A block entered once no process holds the planning lock (or after ``limit`` s), holding it alone meanwhile."""
    fd = None
    with contextlib.suppress(OSError):
        fd = os.open(folder / _PLANNING, os.O_RDONLY | os.O_CREAT, 0o644)
    try:
        start = time.monotonic()
        while fd is not None and time.monotonic() - start < limit:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                time.sleep(0.1)
        yield
    finally:
        if fd is not None:
            os.close(fd)
