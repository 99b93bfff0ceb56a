"""``lagsym receive``: created exclusively at the end, counts right, shows progress on a terminal (pty pairs)."""

from __future__ import annotations

import os
import re
import select
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from simcontrol import PtyPair, program_text, punch

pytestmark = pytest.mark.socat
ROOT = Path(__file__).resolve().parent.parent


def lagsym_process(*argv, stderr=subprocess.PIPE):
    env = dict(os.environ, PYTHONPATH=str(ROOT), TERM="xterm", COLUMNS="160")
    return subprocess.Popen([sys.executable, "-m", "lagsym", *map(str, argv)], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=stderr)


def wait_for_text(proc_err_fd, text, timeout=30.0):
    seen = b""
    deadline = time.monotonic() + timeout
    while text.encode() not in seen and time.monotonic() < deadline:
        ready, _, _ = select.select([proc_err_fd], [], [], 0.1)
        if ready:
            try:
                seen += os.read(proc_err_fd, 65536)
            except OSError:
                break
    return seen


@pytest.mark.slow
def test_a_file_that_appears_while_receive_waits_is_never_replaced(tmp_path):
    target = tmp_path / "got.nc"
    text = program_text(30)
    with PtyPair() as pair:
        proc = lagsym_process("receive", "--port", pair.near, "--baud", 38400, "--timeout", "60", "-o", target)
        assert b"start the output (PUNCH)" in proc.stderr.readline()
        target.write_text("someone else's file\n")  # appears while lagsym waits
        punch(pair.far, b"\x12" + text.encode() + b"\x14", 38400)
        out, err = proc.communicate(timeout=30)
    assert proc.returncode == 2, err
    assert target.read_text() == "someone else's file\n"
    beside = tmp_path / "got.received-2.nc"
    assert beside.read_text() == text
    assert f"{target} appeared while lagsym waited and was kept; the program is saved as {beside}" in err.decode()


@pytest.mark.slow
def _bytes_read(pid: int) -> int:
    with open(f"/proc/{pid}/io") as f:
        return int(re.search(r"rchar: (\d+)", f.read())[1])


def _read_nothing_for(pid: int, seconds: float, timeout: float = 120.0) -> int:
    """Wait until the process has read nothing for ``seconds`` (its start-up done); what it has read by then."""
    deadline, last, since = time.monotonic() + timeout, -1, time.monotonic()
    while time.monotonic() < deadline:
        now = _bytes_read(pid)
        if now != last:
            last, since = now, time.monotonic()
        elif time.monotonic() - since >= seconds:
            return now
        time.sleep(0.05)
    raise AssertionError("the receiver kept reading")


@pytest.mark.slow
def test_a_line_lost_mid_program_counts_the_bytes_that_arrived(tmp_path):
    data = b"\x12" + program_text(400).encode()
    with PtyPair() as pair:
        proc = lagsym_process("receive", "--port", pair.near, "--baud", 38400, "--timeout", "60", "--quiet",
                              "-o", tmp_path / "x.nc")
        base = _read_nothing_for(proc.pid, 1.0)
        sender = threading.Thread(target=punch, args=(pair.far, data[:5000], 38400), kwargs={"delay_s": 0.1})
        sender.start()
        sender.join(30)
        # The cut comes once the receiver has read all 5000 (a hang-up flushes what is unread; on a loaded machine
        # the relay and the receiver took longer than a fixed half second).
        deadline = time.monotonic() + 60
        while _bytes_read(proc.pid) < base + 5000 and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.2)
        pair.hang_up()
        out, err = proc.communicate(timeout=30)
    assert proc.returncode == 3, err
    m = re.search(rb"was lost after (\d+) bytes", err)
    assert m and int(m[1]) == 5000, err
    assert not (tmp_path / "x.nc").exists()


@pytest.mark.slow
def test_receive_shows_characters_blocks_and_rate_on_a_terminal(tmp_path):
    text = program_text(200)
    master, slave = os.openpty()
    try:
        with PtyPair() as pair:
            proc = lagsym_process("receive", "--port", pair.near, "--baud", 9600, "--timeout", "60",
                                  "-o", tmp_path / "p.nc", stderr=slave)
            assert b"PUNCH" in wait_for_text(master, "PUNCH")
            t = threading.Thread(target=punch, args=(pair.far, b"\x12" + text.encode() + b"\x14", 9600))
            t.start()
            seen = wait_for_text(master, "received 202 lines", timeout=60)
            t.join(30)
            proc.communicate(timeout=30)
    finally:
        os.close(master)
        os.close(slave)
    assert proc.returncode == 0
    shown = [(int(c), int(b)) for c, b in re.findall(rb"(\d+) characters, (\d+) blocks", seen)]
    assert len(shown) >= 3  # it moved while the program arrived
    assert shown == sorted(shown) and shown[-1] == (len(text) - 1, 200)  # all but the line end after the closing %
    assert (tmp_path / "p.nc").read_text() == text
