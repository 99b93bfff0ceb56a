"""Real programs the tests run, taken from Debian packages into a cache folder.

LinuxCNC's standalone G-code interpreter ``rs274`` comes from the
``linuxcnc-uspace`` package.  Installing that package pulls in a real-time
stack and a GUI; the tests need only the binary and a few shared libraries, so
they are fetched with ``apt-get download`` and unpacked with ``dpkg -x`` into
``.cache/debtools`` (override with ``LAGSYM_TOOL_CACHE``).  Nothing here is
skipped: if the tools cannot be had, the tests that need them fail and say why.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
CACHE = Path(os.environ.get("LAGSYM_TOOL_CACHE", REPO / ".cache" / "debtools"))
# rs274 embeds Python and reads its input with libedit (which needs libbsd); a minimal Debian has none of them.
RS274_PACKAGES = ("linuxcnc-uspace", "libboost-python1.74.0", "libpython3.11", "libedit2", "libbsd0")


class ToolUnavailable(RuntimeError):
    """A program the tests need could not be found or fetched."""


def _run(cmd: list[str], cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)


def _download(package: str, debs: Path) -> Path:
    found = sorted(debs.glob(f"{package}_*.deb"))
    if found:
        return found[-1]
    if not shutil.which("apt-get"):
        raise ToolUnavailable(f"cannot fetch {package}: apt-get is not on this machine")
    r = _run(["apt-get", "download", package], debs)
    if r.returncode != 0 and os.geteuid() == 0:
        _run(["apt-get", "update", "-qq"], debs)
        r = _run(["apt-get", "download", package], debs)
    found = sorted(debs.glob(f"{package}_*.deb"))
    if r.returncode != 0 or not found:
        raise ToolUnavailable(f"apt-get download {package} failed: {r.stderr.strip()[-400:]}")
    return found[-1]


def unpack(packages: tuple[str, ...]) -> Path:
    """Download and unpack ``packages`` into the cache; return the root they were unpacked into.

    Test processes running side by side (``pytest -n``) take turns: one unpacks while the others wait
    on a lock file, then find its stamp; none replaces a tree another is running programs from."""
    import fcntl

    root = CACHE / "root"
    stamp = CACHE / ("unpacked-" + "-".join(packages))
    if stamp.exists():
        return root
    CACHE.mkdir(parents=True, exist_ok=True)
    with open(CACHE / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if stamp.exists():
            return root
        return _unpack(packages, root, stamp)


def _unpack(packages: tuple[str, ...], root: Path, stamp: Path) -> Path:
    debs = CACHE / "debs"
    debs.mkdir(parents=True, exist_ok=True)
    # Unpack into a fresh folder and move it into place, so two test runs never see half a tree.
    tmp = Path(tempfile.mkdtemp(dir=CACHE))
    if root.exists():
        shutil.copytree(root, tmp / "root", symlinks=True)
    for pkg in packages:
        deb = _download(pkg, debs)
        r = _run(["dpkg", "-x", str(deb), str(tmp / "root")], CACHE)
        if r.returncode != 0:
            raise ToolUnavailable(f"dpkg -x {deb.name} failed: {r.stderr.strip()}")
    if root.exists():
        shutil.rmtree(root)
    (tmp / "root").rename(root)
    shutil.rmtree(tmp, ignore_errors=True)
    stamp.touch()
    return root


@dataclass(frozen=True)
class RS274:
    """The standalone interpreter: ``run(path)`` returns its canonical-command output."""

    binary: Path
    env: dict

    def run(self, program: Path, tool_table: str = "T1 P1 Z0 D6 ;tool\n") -> subprocess.CompletedProcess:
        """Interpret ``program`` in batch mode (``rs274 -g``); the output lists STRAIGHT_FEED etc."""
        with tempfile.TemporaryDirectory() as d:
            tbl = Path(d) / "tool.tbl"
            tbl.write_text(tool_table)
            return subprocess.run(
                [str(self.binary), "-t", str(tbl), "-g", str(program)],
                # rs274 keeps its tool table in a memory-mapped file $HOME/.tool.mmap: a HOME of its own
                # per run, or two runs at once (test workers, other checkouts) read each other's tools.
                capture_output=True, text=True, env={**self.env, "HOME": d}, cwd=d, timeout=600,
            )


def rs274() -> RS274:
    """Find (or fetch) LinuxCNC's ``rs274`` and the libraries it needs."""
    root = unpack(RS274_PACKAGES)
    binary = root / "usr" / "bin" / "rs274"
    if not binary.exists():
        raise ToolUnavailable(f"{binary} missing after unpacking {RS274_PACKAGES}")
    libs = [root / "usr" / "lib", root / "usr" / "lib" / "x86_64-linux-gnu", root / "usr" / "lib" / "aarch64-linux-gnu"]
    env = dict(os.environ)
    env["LD_LIBRARY_PATH"] = os.pathsep.join([str(p) for p in libs] + [env.get("LD_LIBRARY_PATH", "")])
    probe = subprocess.run([str(binary), "-g", os.devnull], capture_output=True, text=True, env=env, timeout=60)
    if "error while loading shared libraries" in probe.stderr:
        raise ToolUnavailable(f"rs274 cannot start: {probe.stderr.strip()}")
    return RS274(binary=binary, env=env)
