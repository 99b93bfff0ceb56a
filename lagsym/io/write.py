"""Writing results: a file appears complete or not at all, and what is at the path is respected.

A regular file, or a new name, is always replaced in one rename of a
temporary file written beside it (keeping an existing file's permissions; a
file with other hard links becomes a new file, and :class:`OutputNotice` says
the other links keep the old content); a symbolic link is followed; a device,
pipe or socket, told by what it is (``stat``), not by its name, is written
through once the content is complete.  An output that is one of the inputs is
refused before any work (:func:`check_not_input`).
"""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import shutil
import stat
import tempfile
import warnings
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import IO

from ..errors import InputError, OutputError
from .files import path_problem

__all__ = ["atomic_path", "atomic_write", "write_text", "check_output", "check_not_input", "check_apart",
           "OutputNotice", "temporary_name", "error_reason"]

SUFFIX_KEPT = 16  # characters of the target's extension the temporary keeps (meshio and VTK choose a format by it)


class OutputNotice(UserWarning):
    """Something about a finished write the user should know (the command line prints it as one line)."""


def error_reason(e: OSError) -> str:
    """Why a write or a path failed, in the words a message gives: ``no space left on the device``, ..."""
    return "no space left on the device" if e.errno == errno.ENOSPC else (e.strerror or str(e)).lower()


def _write_error(path, e: OSError, stream: bool = False) -> OutputError:
    if isinstance(e, OutputError):  # already one line that names the path: never wrapped twice
        return e
    tail = "" if stream else "; any earlier file there is untouched"
    return OutputError(f"{path}: cannot write ({error_reason(e)}){tail}")


def _path_error(path, e: OSError) -> InputError:
    return InputError(f"{path}: {path_problem(e) or f'cannot use this path ({error_reason(e)})'}")


def _target(path) -> tuple[Path, os.stat_result | None]:
    """What ``path`` names: the real path, and its status (None for a new name); an InputError for a bad path."""
    name = os.fspath(path) if isinstance(path, os.PathLike) else path
    if not isinstance(name, str) or not name:
        raise InputError(f"output path {path!r:.80} is not a file name")
    if "\x00" in name:
        raise InputError(f"{name!r}: a file name cannot hold a NUL character")
    try:
        info = os.stat(name)  # follows a symbolic link, as the write will
    except (FileNotFoundError, NotADirectoryError):  # a new name; its folder is checked next
        info = None
    except OSError as e:
        raise _path_error(path, e) from None
    try:
        real = Path(os.path.realpath(name, strict=False))
    except OSError as e:
        raise _path_error(path, e) from None
    return real, info


def check_output(path: str | os.PathLike) -> tuple[Path, bool, Path]:
    """Whether ``path`` can be written, before any work: ``(real path, written through, folder of the temporary)``.

    Raises :class:`InputError` for a folder, a name under something that is
    not a folder, a missing folder, a symbolic-link loop, or a name or path
    over the system's limits.
    """
    real, info = _target(path)
    if info is not None and stat.S_ISDIR(info.st_mode):
        raise InputError(f"{path}: is a directory")
    stream = info is not None and not stat.S_ISREG(info.st_mode)
    directory = Path(tempfile.gettempdir()) if stream else real.parent
    try:
        folder = stat.S_ISDIR(os.stat(directory).st_mode)
    except (FileNotFoundError, NotADirectoryError):
        raise InputError(f"{path}: the folder {directory} does not exist") from None
    except OSError as e:  # the folder's whole path over the system's limit, a loop, no permission
        raise _path_error(path, e) from None
    if not folder:
        raise InputError(f"{path}: {directory} is not a folder")
    if not stream:
        limit = _name_max(directory)
        if len(os.fsencode(real.name)) > limit:
            raise InputError(f"{path}: the name is {len(os.fsencode(real.name))} bytes, more than the "
                             f"{limit} the file system allows")
    return real, stream, directory


def check_not_input(output, inputs: Iterable, option: str = "") -> None:
    """Refuse an ``output`` that is one of ``inputs`` (the same device and inode), before any work is done.

    ``option`` (``--print-output``) is named before the path when the output is not the command's ``-o``.
    """
    try:
        out = os.stat(output)
    except (OSError, ValueError, TypeError):
        return  # a new name, or one check_output refuses
    if not stat.S_ISREG(out.st_mode):
        return
    for given in inputs:
        try:
            info = os.stat(given)
        except (OSError, ValueError, TypeError):
            continue
        if (info.st_dev, info.st_ino) == (out.st_dev, out.st_ino):
            same = "" if os.fspath(given) == os.fspath(output) else f" ({given})"
            named = f"{option} {output}" if option else f"{output}"
            raise InputError(f"{named}: is also an input{same}; write the result to another file")


def _identity(path) -> tuple | None:
    """What an output writes: its device and inode, its real path for a new name, None for a device or pipe."""
    try:
        info = os.stat(path)
    except (FileNotFoundError, NotADirectoryError):
        try:
            return ("new", os.path.realpath(path))
        except (OSError, ValueError):
            return None
    except (OSError, ValueError, TypeError):
        return None  # check_output refuses it
    return ("file", info.st_dev, info.st_ino) if stat.S_ISREG(info.st_mode) else None


def check_apart(outputs: Iterable[tuple[str, str]]) -> None:
    """Refuse two outputs of one command, ``(option, path)`` pairs, that name one file: the later would replace
    the earlier.  A device or pipe (``/dev/null``) may take several."""
    seen: list[tuple[str, str, tuple]] = []
    for option, path in outputs:
        key = _identity(path)
        if key is None:
            continue
        for first, earlier, other in seen:
            if key == other:
                same = "" if os.fspath(earlier) == os.fspath(path) else f" ({earlier})"
                raise InputError(f"{option} {path}: is also the output of {first}{same}; give each output its "
                                 f"own file")
        seen.append((option, path, key))


def _name_max(directory: Path) -> int:
    try:
        return int(os.pathconf(directory, "PC_NAME_MAX"))
    except (OSError, ValueError):
        return 255


def temporary_name(target: Path, name_max: int = 255) -> str:
    """The name of the temporary beside ``target``: hidden, random, with its extension, within ``name_max`` bytes.

    Examples
    --------
    >>> t = temporary_name(Path("/w/part.vtk"))
    >>> t.startswith(".part.vtk.") and t.endswith(".part.vtk"), len(temporary_name(Path("a" * 251 + ".csv")))
    (True, 255)
    """
    suffix = target.suffix if len(target.suffix) <= SUFFIX_KEPT and target.suffix.isascii() else ""
    tail = f".{secrets.token_hex(4)}.part{suffix}"
    room = name_max - 1 - len(tail.encode())
    stem = os.fsencode(target.name)[:room].decode("utf-8", "ignore")
    return f".{stem}{tail}"


def _new_temporary(directory: Path, target: Path) -> str:
    limit = _name_max(directory)
    for _ in range(100):
        tmp = str(directory / temporary_name(target, limit))
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        except FileExistsError:
            continue
        os.close(fd)
        return tmp
    raise FileExistsError(errno.EEXIST, "no free temporary name")


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[str]:
    """Yield a temporary file name; once the block succeeds its content becomes ``path``'s.

    For libraries that write a file by name (meshio, VTK) as much as for
    :func:`atomic_write`.  How the content arrives depends on what ``path`` is:

    - a regular file, or a new name: the temporary file sits beside it and
      replaces it in one rename, keeping an existing file's permissions (a new
      file gets ``0o666`` less the umask).  A file with other hard links is
      replaced too: the name becomes a new file, the other links keep the old
      content, and an :class:`OutputNotice` warning says so;
    - a symbolic link: the same, for the file it points to (the link stays);
    - a device, pipe or socket (``/dev/null``, ``/dev/stdout``, a FIFO): written
      through, after the content is complete.

    A failure part-way, a full disk included, leaves any earlier file
    untouched and no partial file behind, and is one :class:`OutputError`.
    """
    given = Path(path)
    real, stream, directory = check_output(path)
    try:
        tmp = _new_temporary(directory, real)
    except OSError as e:
        raise _write_error(path, e, stream) from None
    try:
        yield tmp
        if stream:
            _copy_into(tmp, given)
        else:
            _sync(tmp)
            _commit(tmp, real, path)
    except OSError as e:
        raise _write_error(path, e, stream) from None
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)


def _sync(tmp: str) -> None:
    """The temporary's bytes on the disk before the rename: a file system that allocates late says ENOSPC here."""
    fd = os.open(tmp, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _copy_into(tmp: str, target: Path) -> None:
    with open(tmp, "rb") as src, open(target, "wb") as dst:
        shutil.copyfileobj(src, dst, 1 << 20)


def _commit(tmp: str, target: Path, given) -> None:
    try:
        old = target.stat()
    except FileNotFoundError:
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, target)
        return
    os.chmod(tmp, stat.S_IMODE(old.st_mode))
    os.replace(tmp, target)
    if old.st_nlink > 1:
        others = old.st_nlink - 1
        warnings.warn(OutputNotice(f"{given}: written as a new file; its {others} other hard "
                                   f"link{'s' if others > 1 else ''} keep{'' if others > 1 else 's'} "
                                   f"the old content"), stacklevel=2)


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
        except OutputError:
            raise
        except OSError as e:
            raise _write_error(path, e) from None


def write_text(path: str | os.PathLike, text: str, newline: str | None = "") -> None:
    """Write ``text`` to ``path`` atomically (no newline translation by default)."""
    with atomic_write(path, "w", newline=newline) as fh:
        fh.write(text)
