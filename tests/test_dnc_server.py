"""``lagsym dnc serve``, end to end on two pty pairs: punch, duplicate punch, requests, a missing program, SIGTERM."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from lagsym.dnc import parse_program, profile, transfer_segments
from simcontrol import PtyPair, SimControl, chars_per_s, program_text, punch, wait_until

pytestmark = pytest.mark.socat
ROOT = Path(__file__).resolve().parent.parent


def docs_config() -> str:
    """The configuration docs/dnc.md shows (the same as examples/dnc.toml)."""
    text = (ROOT / "docs" / "dnc.md").read_text()
    block = re.search(r"```toml\n(.*?)```", text, re.DOTALL).group(1)
    assert block == (ROOT / "examples" / "dnc.toml").read_text()
    return block


@pytest.mark.slow
def test_the_server_end_to_end_on_two_ports(tmp_path):
    mill, lathe = PtyPair(), PtyPair()
    config = docs_config().replace("/dev/ttyUSB0", mill.near).replace("/dev/ttyUSB1", lathe.near)
    config = config.replace("request_delay_s = 5 ", "request_delay_s = 2 ")
    (tmp_path / "dnc" / "programs").mkdir(parents=True)
    served = program_text(60).replace("O1000", "O1234")
    (tmp_path / "dnc" / "programs" / "1234.nc").write_text(served)
    cfg = tmp_path / "dnc.toml"
    cfg.write_text(config)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.Popen([sys.executable, "-m", "lagsym", "dnc", "serve", str(cfg)], cwd=tmp_path, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    received = tmp_path / "dnc" / "received"
    mill_log = tmp_path / "dnc" / "mill1.log"
    fanuc = profile("fanuc", baud=19200)
    try:
        assert wait_until(lambda: mill_log.exists() and "listening" in proc.stdout.readline())
        time.sleep(0.5)
        # Punches on both ports at once: each saved under its number, in its own folder.
        first = "%\nO2001 (FIRST)\nG0 X1.\nM30\n%\n"
        lathe_prog = "%\nO3001\nG0 X5.\nM30\n%\n"
        punch(lathe.far, b"\x12" + lathe_prog.replace("\n", "\r\n").encode() + b"\x14", 9600, stopbits=1)
        punch(mill.far, b"\x12" + first.encode() + b"\x14", 19200)
        assert wait_until(lambda: (received / "mill1" / "2001.nc").exists())
        assert (received / "mill1" / "2001.nc").read_text() == first
        assert wait_until(lambda: (received / "lathe2" / "3001.nc").exists())
        assert (received / "lathe2" / "3001.nc").read_text() == lathe_prog
        # The same number again: the first file is kept, the new one saved beside it.
        second = first.replace("FIRST", "SECOND")
        punch(mill.far, b"\x12" + second.encode() + b"\x14", 19200)
        assert wait_until(lambda: (received / "mill1" / "2001.received-2.nc").exists())
        assert (received / "mill1" / "2001.nc").read_text() == first
        assert (received / "mill1" / "2001.received-2.nc").read_text() == second
        # Requests: O9999 uploads, O9998 drip-feeds the program its first comment names.
        for request, mode in (("%\nO9999 (PRG=1234)\nM30\n%\n", "upload"), ("%\nO9998 (O1234)\nM30\n%\n", "drip")):
            punch(mill.far, request.encode(), 19200)
            # The control runs slower than the line, so a drip feed hears its XOFF and XON.
            sim = SimControl(mill.far, baud=19200, drain_cps=0.5 * chars_per_s(19200))
            sim.start()
            expected = b"".join(b for _, b in transfer_segments(parse_program(served), fanuc, mode))
            assert sim.wait_for(len(expected), timeout=30), mode
            time.sleep(0.3)
            assert sim.stop()["received"] == expected, mode
            assert wait_until(lambda: f"sent O1234 ({mode})" in mill_log.read_text())
        # A missing program is logged and nothing is sent.
        punch(mill.far, b"%\nO9999 (PRG=4321)\nM30\n%\n", 19200)
        sim = SimControl(mill.far, baud=19200)
        sim.start()
        assert wait_until(lambda: "O4321: no such program" in mill_log.read_text())
        time.sleep(2.5)
        assert sim.stop()["received"] == b""
        log = mill_log.read_text()
        assert re.search(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d received O2001: ", log, re.MULTILINE)
        # SIGTERM stops the server cleanly, at once: its ports wait in turns of well under a second, and
        # a loaded machine may only stretch those turns, never wait for a control or a timeout.
        t0 = time.monotonic()
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=30)
        assert time.monotonic() - t0 < 10.0
        assert proc.returncode == 0, err
        assert "server: stopped by SIGTERM" in out and "mill1: stopped" in out and "lathe2: stopped" in out
    finally:
        if proc.poll() is None:
            proc.kill()
        mill.close()
        lathe.close()


@pytest.mark.slow
def test_a_port_that_fails_does_not_stop_the_others(tmp_path):
    good = PtyPair()
    config = docs_config().replace("/dev/ttyUSB0", str(tmp_path / "no-such-port")).replace("/dev/ttyUSB1", good.near)
    (tmp_path / "dnc" / "programs").mkdir(parents=True)
    cfg = tmp_path / "dnc.toml"
    cfg.write_text(config)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.Popen([sys.executable, "-m", "lagsym", "dnc", "serve", str(cfg)], cwd=tmp_path, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        time.sleep(1.5)
        prog = "%\nO3002\nM30\n%\n"
        punch(good.far, b"\x12" + prog.replace("\n", "\r\n").encode() + b"\x14", 9600, stopbits=1)
        assert wait_until(lambda: (tmp_path / "dnc" / "received" / "lathe2" / "3002.nc").exists())
        assert "cannot open" in (tmp_path / "dnc" / "mill1.log").read_text()
        proc.send_signal(signal.SIGTERM)
        proc.communicate(timeout=10)
        assert proc.returncode == 0
    finally:
        if proc.poll() is None:
            proc.kill()
        good.close()


@pytest.mark.parametrize("edit, words", [
    (lambda c: c.replace("request_delay_s", "request_delay"), "port[0].request_delay: unknown key; the keys are"),
    (lambda c: c.replace("baud = 19200", "baud = 12"), "port[0].line: baud rate 12"),
    (lambda c: c.replace("baud = 19200", 'baud = 19200\nrealtime = "yes"'), "port[0].line: realtime 'yes' must be true"),
    (lambda c: c.replace('profile = "haas"', 'profile = "mazak"'), "port[1].profile"),
    (lambda c: c + "\n[extra]\n", "extra: unknown key"),
    (lambda c: c.replace('"dnc/lathe2.log"', '"dnc/mill1.log"'), "dnc/mill1.log is also port 'mill1''s log"),
    (lambda c: c.replace('"dnc/mill1.log"', '"dnc.toml"'), "dnc.toml is this configuration file"),
    (lambda c: c.replace('"dnc/mill1.log"', '"dnc/programs/O1234"'), "is named as a program in port 'mill1''s programs"),
    (lambda c: c.replace('"dnc/lathe2.log"', '"dnc/received/mill1/3002.received-2.nc"'),
     "is named as a program in port 'mill1''s received folder"),
    (lambda c: c.replace('"dnc/mill1.log"', '"/dev/ttyUSB1"'), "is port 'lathe2''s device"),
])
def test_a_bad_config_is_one_line_naming_the_key(run_cli, tmp_path, edit, words):
    (tmp_path / "dnc" / "programs").mkdir(parents=True)
    cfg = tmp_path / "dnc.toml"
    cfg.write_text(edit(docs_config()))
    status, out, err = run_cli("dnc", "serve", cfg)
    assert status == 2 and words in err and err.count("\n") == 1, err
