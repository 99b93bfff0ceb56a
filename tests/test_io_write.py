"""Writing results: ``-o`` writes what is at the path the way a user expects, and a stop leaves nothing behind."""

from __future__ import annotations

import os
import signal
import stat
import subprocess
import sys
import time

import pytest

from conftest import EXAMPLES, ROOT
from lagsym.errors import OutputError
from lagsym.io import write_text

EXAMPLE1 = EXAMPLES / "paper-example-1.json"


def test_a_device_stays_a_device(run_cli):
    status, out, err = run_cli("equation", EXAMPLE1, "-o", "/dev/null")
    assert (status, out, err) == (0, "", "")
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)


def test_dev_stdout_prints_to_standard_output(tmp_path):
    done = subprocess.run([sys.executable, "-m", "lagsym", "equation", str(EXAMPLE1), "-o", "/dev/stdout"],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout == "z = x**2 + 3*y\n"


def test_a_symlink_is_written_through(run_cli, tmp_path):
    target = tmp_path / "real.txt"
    target.write_text("old\n")
    link = tmp_path / "link.txt"
    link.symlink_to(target)
    assert run_cli("equation", EXAMPLE1, "-o", link)[0] == 0
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_text() == "z = x**2 + 3*y\n"


def test_a_hard_linked_file_is_replaced_and_the_note_says_so(run_cli, tmp_path):
    # Rewriting in place would leave a prefix of the new content, the old gone, on a signal or a full disk.
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    a.write_text("old\n")
    os.link(a, b)
    status, out, err = run_cli("equation", EXAMPLE1, "-o", a)
    assert (status, out) == (0, "")
    assert err == f"lagsym: note: {a}: written as a new file; its 1 other hard link keeps the old content\n"
    assert os.stat(a).st_ino != os.stat(b).st_ino and os.stat(b).st_nlink == 1
    assert a.read_text() == "z = x**2 + 3*y\n" and b.read_text() == "old\n"


def test_an_existing_file_keeps_its_permissions(run_cli, tmp_path):
    p = tmp_path / "secret.txt"
    p.write_text("old\n")
    p.chmod(0o600)
    assert run_cli("equation", EXAMPLE1, "-o", p)[0] == 0
    assert stat.S_IMODE(p.stat().st_mode) == 0o600 and p.read_text() == "z = x**2 + 3*y\n"


def test_a_new_file_gets_the_umask_permissions(tmp_path):
    mask = os.umask(0o022)
    try:
        write_text(tmp_path / "new.txt", "x\n")
    finally:
        os.umask(mask)
    assert stat.S_IMODE((tmp_path / "new.txt").stat().st_mode) == 0o644


def test_a_full_disk_is_one_line(run_cli, tmp_path):
    status, out, err = run_cli("equation", EXAMPLE1, "-o", "/dev/full")
    assert status == 2 and out == ""
    assert err == "lagsym: error: /dev/full: cannot write (no space left on the device)\n"
    with pytest.raises(OutputError):
        write_text("/dev/full", "x")
    assert list(tmp_path.iterdir()) == []


def test_a_failed_write_leaves_no_partial_file(tmp_path):
    target = tmp_path / "keep.txt"
    target.write_text("old\n")

    class Boom(Exception):
        pass

    from lagsym.io import atomic_write

    with pytest.raises(Boom):
        with atomic_write(target) as fh:
            fh.write("half")
            raise Boom
    assert target.read_text() == "old\n" and sorted(p.name for p in tmp_path.iterdir()) == ["keep.txt"]


@pytest.mark.parametrize("sig, status", [(signal.SIGTERM, 143), (signal.SIGHUP, 129), (signal.SIGINT, 130)])
def test_a_signal_stops_a_long_write_with_one_line_and_no_partial_file(tmp_path, sig, status):
    out = tmp_path / "big.csv"
    proc = subprocess.Popen(
        [sys.executable, "-m", "lagsym", "sample", str(EXAMPLES / "paper-example-4.json"),
         "--nx", "3000", "--ny", "3000", "-o", str(out)],
        cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        # A shell's background job starts with SIGINT ignored, and Python then leaves it so: a command run
        # from a terminal has it at its default, which is what this checks.
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    while not any(p.name.endswith(".part.csv") for p in tmp_path.iterdir()):
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the sample never started writing"
        time.sleep(0.05)
    time.sleep(0.3)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == status, err
    name = {signal.SIGINT: "interrupted"}.get(sig, f"stopped by {sig.name}")
    assert err.strip().splitlines() == [f"lagsym: {name}; no partial output file is left"]
    assert list(tmp_path.iterdir()) == []
