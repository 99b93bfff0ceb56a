"""Atomic output for writers that open the file by name themselves (meshio, VTK)."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

from ..errors import InputError

__all__ = ["atomic_path", "usual_mode"]


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[str]:
    """Yield a temporary file name beside ``path``; it replaces ``path`` only if the block succeeds.

    Like :func:`lagsym.io.atomic_write`, for libraries that take a file name
    rather than an open stream: a failure leaves no partial file behind.
    """
    target = Path(path)
    directory = target.parent if str(target.parent) else Path(".")
    if not directory.is_dir():
        raise InputError(f"{path}: the folder {directory} does not exist")
    if target.is_dir():
        raise InputError(f"{path}: is a directory")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part" + target.suffix, dir=directory)
    os.close(fd)
    try:
        yield tmp
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def usual_mode(path: str | os.PathLike) -> None:
    """Give ``path`` the permissions a newly created file gets (``0o666`` less the umask).

    Temporary files are created private (``0o600``); an output file should not be.
    """
    mask = os.umask(0)
    os.umask(mask)
    os.chmod(path, 0o666 & ~mask)
