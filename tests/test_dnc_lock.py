"""A port another program holds is noticed: other openers, lock files, and the kernel's exclusive open (pty pairs)."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from lagsym.dnc import profile
from lagsym.dnc.lock import LOCK_FOLDERS
from lagsym.dnc.port import Port
from simcontrol import PROGRAM, PtyPair

pytestmark = pytest.mark.socat


def lock_folder() -> Path:
    folder = next((Path(f) for f in LOCK_FOLDERS if os.path.isdir(f) and os.access(f, os.W_OK)), None)
    if folder is None:
        pytest.skip("no writable lock folder here")
    return folder


def write(tmp_path, text, name="prog.nc"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_a_cat_holding_the_port_is_named_and_the_send_refused(run_cli, tmp_path):
    with PtyPair() as pair:
        cat = subprocess.Popen(["cat", pair.near], stdout=subprocess.DEVNULL)
        try:
            time.sleep(0.5)  # cat has the device open
            status, _, err = run_cli("send", write(tmp_path, PROGRAM), "--port", pair.near, "--quiet")
        finally:
            cat.kill()
            cat.wait()
    assert status == 3, err
    assert f"the port is in use by another program (cat, pid {cat.pid})" in err and err.count("\n") == 1


def _lock_of(folder, pair) -> Path:
    return folder / ("LCK.." + os.path.realpath(pair.near)[len("/dev/"):].replace("/", "_"))


def _taken_over(pair, lock) -> None:
    """The lock is taken by this process while the port is open, and removed at close."""
    port = Port(pair.near, profile("fanuc"), write_timeout=1)
    try:
        assert lock.read_text() == f"{os.getpid():>10d}\n"
    finally:
        port.close()
    assert not lock.exists()


def test_a_lock_file_of_a_live_program_refuses_and_a_stale_one_is_taken_over(run_cli, tmp_path):
    folder = lock_folder()
    with PtyPair() as pair:
        lock = _lock_of(folder, pair)
        with open(pair.near, "rb") as device:  # the holder has the device open, as minicom would
            holder = subprocess.Popen(["sleep", "60"], stdin=device)
        try:
            lock.write_text(f"{holder.pid:>10d}\n")
            status, _, err = run_cli("send", write(tmp_path, PROGRAM), "--port", pair.near, "--quiet")
            assert status == 3 and f"pid {holder.pid}, lock file {lock})" in err, err
        finally:
            holder.kill()
            holder.wait()
        # Its owner gone, the lock is stale: taken over, held while the port is open, removed at close.
        _taken_over(pair, lock)


def test_a_lock_file_of_a_live_program_without_the_device_open_is_taken_over():
    # A program that closed the port and never removed its lock, or a pseudo-terminal number given to a new
    # pair since: its lock claims nothing, though its owner runs on.
    folder = lock_folder()
    with PtyPair() as pair:
        lock = _lock_of(folder, pair)
        idle = subprocess.Popen(["sleep", "60"])
        try:
            lock.write_text(f"{idle.pid:>10d}\n")
            _taken_over(pair, lock)
        finally:
            idle.kill()
            idle.wait()


def test_the_kernel_refuses_a_second_open_while_lagsym_holds_the_port():
    with PtyPair() as pair:
        device = os.path.realpath(pair.near)
        os.chmod(device, 0o666)  # a user other than root could open it, but for the exclusive open
        port = Port(pair.near, profile("fanuc"), write_timeout=1)
        try:
            probe = ("import os, sys\n"
                     "if os.getuid() == 0: os.setgid(65534); os.setuid(65534)\n"
                     "try:\n    os.open(sys.argv[1], os.O_RDWR | os.O_NOCTTY)\nexcept OSError as e:\n"
                     "    print(e.errno)\nelse:\n    print('opened')\n")
            busy = subprocess.run([sys.executable, "-c", probe, device], capture_output=True, text=True, timeout=20)
        finally:
            port.close()
        free = subprocess.run([sys.executable, "-c", probe, device], capture_output=True, text=True, timeout=20)
    assert busy.stdout.strip() == "16", busy  # EBUSY
    assert free.stdout.strip() == "opened", free
