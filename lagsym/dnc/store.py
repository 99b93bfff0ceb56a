"""Files a DNC transfer keeps: created exclusively, never through a symbolic link, never over another file.

Every name is taken with one ``open(O_CREAT | O_EXCL | O_NOFOLLOW)``: two
ports (or two servers) sharing a folder can never both take a name, and a
link planted in the folder (even a dangling one) is never written through,
because an exclusive create fails on any existing name, link or not.  The
program is then written into the file already taken, so a name that is
logged is a file that holds that program.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError, OutputError

__all__ = ["create_exclusive", "save_beside", "read_no_link"]

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_MAX_TRIES = 100_000


def create_exclusive(path: Path, data: bytes) -> bool:
    """Write ``data`` to a new file ``path``; False (nothing written) if the name exists in any form."""
    try:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW, 0o644)
    except FileExistsError:
        return False
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
        os.fsync(fd)
    except OSError:
        os.close(fd)
        os.unlink(path)
        raise
    os.close(fd)
    return True


def save_beside(folder: Path, stem: str, suffix: str, data: bytes) -> Path:
    """Save ``data`` as ``stem + suffix`` in ``folder``, or beside a taken name as ``stem.received-2`` + suffix, ...

    Raises
    ------
    OutputError
        If the folder cannot be written.
    """
    for k in range(1, _MAX_TRIES):
        path = folder / (f"{stem}{suffix}" if k == 1 else f"{stem}.received-{k}{suffix}")
        try:
            if create_exclusive(path, data):
                return path
        except OSError as e:
            raise OutputError(f"cannot save {path}: {e.strerror or e}") from None
    raise OutputError(f"{folder}: {_MAX_TRIES} files named {stem}{suffix} already; move some away")


def read_no_link(path: Path) -> str:
    """The text of ``path``, refusing a symbolic link (a configured folder serves only its own files)."""
    try:
        fd = os.open(path, os.O_RDONLY | _NOFOLLOW)
    except OSError as e:
        if os.path.islink(path):
            raise InputError(f"{path} is a symbolic link; only files in the folder itself are served") from None
        raise InputError(f"cannot read {path}: {e.strerror or e}") from None
    with os.fdopen(fd, "rb") as fh:
        return fh.read().decode("ascii", errors="replace")
