"""Claiming a local serial device the ways other serial tools look for: a UUCP lock file, and a look for openers.

:class:`lagsym.dnc.port.Port` claims a device four ways, each catching a
different kind of other program:

* ``flock`` on the open device (pyserial's ``exclusive=True``): catches
  another lagsym and any program that takes the same advisory lock; a
  program that takes none (``cat``, a terminal program without locking)
  is not stopped by it.
* ``TIOCEXCL`` on the open device: from then on the kernel refuses every
  further open of the device with EBUSY, except by root (CAP_SYS_ADMIN).
* A lock file ``LCK..ttyUSB0`` in ``/run/lock`` or ``/var/lock``
  (:func:`take_lock_file`), in the format minicom, picocom, cu and
  ModemManager use: a device another of those holds is refused, and
  they see lagsym's.  A lock whose owner has ended, or runs on without the
  device open (where ``/proc`` shows its files), is stale and taken over.
  Where no lock folder can be written it is skipped.
* A look through ``/proc`` for other processes that have the device open
  (:func:`other_openers`): catches a ``cat`` or a terminal that opened the
  device before lagsym, which none of the above can.  It sees only the
  processes the user may look at (all of them as root), and on Linux only.

Not caught: a program run as root that opens the device after lagsym did
and takes no lock (TIOCEXCL does not bind root, and the look through
``/proc`` is made when the port opens); a program in another container or
user namespace that ``/proc`` does not show; and anything on the far side
of a network serial server (``socket://``, ``rfc2217://``), where none of
these apply.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["take_lock_file", "release_lock_file", "other_openers", "LOCK_FOLDERS"]

LOCK_FOLDERS = ("/run/lock", "/var/lock")


def _lock_name(device: str) -> str:
    real = os.path.realpath(device)
    rest = real[len("/dev/"):] if real.startswith("/dev/") else os.path.basename(real)
    return "LCK.." + rest.replace("/", "_")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _holds(pid: int, device: str) -> bool | None:
    """Whether process ``pid`` has ``device`` open; None where ``/proc`` cannot tell.

    A lock file whose owner still runs but has let the device go (a program that
    closed the port and never removed its lock, or a pseudo-terminal's number
    given to a new pair since) claims nothing: other serial tools would wait
    for that owner to end, which may be never.
    """
    real = os.path.realpath(device)
    try:
        fds = os.listdir(f"/proc/{pid}/fd")
    except OSError:
        return None
    for fd in fds:
        try:
            if os.readlink(f"/proc/{pid}/fd/{fd}") == real:
                return True
        except OSError:
            continue
    return False


def _name_of(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/comm").read_text().strip() or "?"
    except OSError:
        return "?"


def take_lock_file(device: str) -> tuple[Path | None, str | None]:
    """Take the device's lock file: ``(path taken or None, who holds it if someone else does)``."""
    name = _lock_name(device)
    for folder in LOCK_FOLDERS:
        if not (os.path.isdir(folder) and os.access(folder, os.W_OK)):
            continue
        path = Path(folder) / name
        for _attempt in range(2):
            try:
                fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), 0o644)
            except FileExistsError:
                try:
                    pid = int(path.read_text(errors="replace").split()[0])
                except (OSError, ValueError, IndexError):
                    pid = None
                if pid == os.getpid():  # this process holds it already: its flock on the device says so
                    return None, None
                if pid is not None and _alive(pid) and _holds(pid, device) is not False:
                    return None, f"{_name_of(pid)}, pid {pid}, lock file {path}"
                try:  # stale: its owner is gone, or runs on without the device open
                    path.unlink()
                except OSError:
                    return None, None
                continue
            except OSError:
                break
            with os.fdopen(fd, "w") as fh:
                fh.write(f"{os.getpid():>10d}\n")
            return path, None
        return None, None
    return None, None


def release_lock_file(path: Path | None) -> None:
    """Remove a lock file this process took (and only if it still names this process)."""
    if path is None:
        return
    try:
        if int(path.read_text().split()[0]) == os.getpid():
            path.unlink()
    except (OSError, ValueError, IndexError):
        pass


def other_openers(device: str) -> list[str]:
    """Other processes that have ``device`` open, as ``"cat, pid 123"``; empty where /proc cannot tell.

    A process that holds the master side of the same pseudo-terminal is its far end, not a second
    opener, and is not listed.
    """
    real = os.path.realpath(device)
    try:
        minor = os.minor(os.stat(real).st_rdev)
    except OSError:
        return []
    found = []
    me = os.getpid()
    try:
        pids = [int(p) for p in os.listdir("/proc") if p.isdigit()]
    except OSError:
        return []
    for pid in pids:
        if pid == me:
            continue
        holds = far_end = False
        try:
            for fd in os.listdir(f"/proc/{pid}/fd"):
                try:
                    target = os.readlink(f"/proc/{pid}/fd/{fd}")
                except OSError:
                    continue
                if target == real:
                    holds = True
                elif target == "/dev/ptmx" and real.startswith("/dev/pts/"):
                    info = Path(f"/proc/{pid}/fdinfo/{fd}").read_text()
                    far_end = far_end or f"tty-index:\t{minor}\n" in info
        except OSError:
            continue
        if holds and not far_end:
            found.append(f"{_name_of(pid)}, pid {pid}")
    return found
