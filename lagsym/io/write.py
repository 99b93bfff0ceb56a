"""Writing results: a file appears complete or not at all, and what is at the path is respected.

A regular file is replaced in one rename (keeping its permissions, and its
hard links by rewriting in place), a symbolic link is followed, and a device,
pipe or ``/dev/stdout`` is written through once the content is complete.
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO

from ..errors import InputError, OutputError

__all__ = ["atomic_path", "atomic_write", "write_text", "check_output"]


def _write_error(path, e: OSError) -> OutputError:
    reason = (e.strerror or str(e)).lower()
    if e.errno == errno.ENOSPC:
        reason = "no space left on the device"
    return OutputError(f"{path}: cannot write ({reason}); any earlier file there is untouched")


def _is_stream(given: Path, real: Path) -> bool:
    """A target written through rather than replaced: a device, pipe or socket, or a /dev or /proc name."""
    if str(given).startswith(("/dev/", "/proc/")):
        return True
    try:
        return not stat.S_ISREG(real.stat().st_mode)
    except (FileNotFoundError, NotADirectoryError):  # a new name; its folder is checked next
        return False


def check_output(path: str | os.PathLike) -> tuple[Path, bool, Path]:
    """Whether ``path`` can be written, before any work: ``(real path, written through, folder of the temporary)``.

    Raises :class:`InputError` for a folder, a name under something that is
    not a folder, or a missing folder.
    """
    given = Path(path)
    real = Path(os.path.realpath(given))
    if real.is_dir():
        raise InputError(f"{path}: is a directory")
    stream = _is_stream(given, real)
    directory = Path(tempfile.gettempdir()) if stream else real.parent
    if not directory.is_dir():
        what = f"{directory} is not a folder" if directory.exists() else f"the folder {directory} does not exist"
        raise InputError(f"{path}: {what}")
    return real, stream, directory


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[str]:
    """Yield a temporary file name; once the block succeeds its content becomes ``path``'s.

    For libraries that write a file by name (meshio, VTK) as much as for
    :func:`atomic_write`.  How the content arrives depends on what ``path`` is:

    - a regular file, or a new name: the temporary file sits beside it and
      replaces it in one rename, keeping an existing file's permissions (a new
      file gets ``0o666`` less the umask); a file with other hard links is
      rewritten in place instead, so the links stay one file;
    - a symbolic link: the same, for the file it points to (the link stays);
    - a device, pipe or socket (``/dev/null``, ``/dev/stdout``, a FIFO): written
      through, after the content is complete.

    A failure part-way, a full disk included, leaves any earlier file
    untouched and no partial file behind, and is one :class:`OutputError`.
    """
    given = Path(path)
    real, stream, directory = check_output(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{real.name}.", suffix=".part" + real.suffix, dir=directory)
    except OSError as e:
        raise _write_error(path, e) from None
    os.close(fd)
    try:
        yield tmp
        if stream:
            _copy_into(tmp, given)
        else:
            _commit(tmp, real)
    except OSError as e:
        raise _write_error(path, e) from None
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)


def _copy_into(tmp: str, target: Path) -> None:
    with open(tmp, "rb") as src, open(target, "wb") as dst:
        shutil.copyfileobj(src, dst, 1 << 20)


def _commit(tmp: str, target: Path) -> None:
    try:
        old = target.stat()
    except FileNotFoundError:
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, target)
        return
    if old.st_nlink > 1:
        with open(tmp, "rb") as src, open(target, "r+b") as dst:
            shutil.copyfileobj(src, dst, 1 << 20)
            dst.truncate()
            dst.flush()
            os.fsync(dst.fileno())
        return
    os.chmod(tmp, stat.S_IMODE(old.st_mode))
    os.replace(tmp, target)


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "w", newline: str | None = None) -> Iterator[IO]:
    """Open a temporary file whose content becomes ``path``'s only if the block succeeds (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp:
        kwargs = {} if "b" in mode else {"encoding": "utf-8", "newline": newline}
        try:
            with open(tmp, mode, **kwargs) as fh:
                yield fh
                fh.flush()
                os.fsync(fh.fileno())
        except OSError as e:
            raise _write_error(path, e) from None


def write_text(path: str | os.PathLike, text: str, newline: str | None = "") -> None:
    """Write ``text`` to ``path`` atomically (no newline translation by default)."""
    with atomic_write(path, "w", newline=newline) as fh:
        fh.write(text)
