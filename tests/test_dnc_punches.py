"""The DNC server never loses a punch: shared folders, bursts, punch-alls, odd numbers, links, stops (pty pairs)."""

from __future__ import annotations

import functools
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from lagsym.dnc.config import load_config
from lagsym.dnc.server import serve
import simcontrol
from simcontrol import PtyPair, punch

pytestmark = pytest.mark.socat
ROOT = Path(__file__).resolve().parent.parent
BAUD = 38400


wait_until = functools.partial(simcontrol.wait_until, timeout=60.0)  # a busy server takes its time


def config_text(devices, received="received", extra=""):
    tables = []
    for i, device in enumerate(devices):
        tables.append(f'[[port]]\nname = "p{i}"\ndevice = "{device}"\nprofile = "fanuc"\nprograms = "programs"\n'
                      f'received = "{received}"\nrequest_delay_s = 0\n{extra}[port.line]\nbaud = {BAUD}\n')
    return "\n".join(tables)


class Server:
    """``serve`` in a thread on the given devices; its log lines per port and its status lines."""

    def __init__(self, tmp_path, devices, received="received", extra=""):
        (tmp_path / "programs").mkdir(exist_ok=True)
        cfg = tmp_path / "dnc.toml"
        cfg.write_text(config_text(devices, received, extra))
        self.config = load_config(cfg)
        self.logs = {p.name: [] for p in self.config.ports}
        self.lock = threading.Lock()
        self.stop = threading.Event()
        self.listening = {p.name: threading.Event() for p in self.config.ports}
        self.thread = threading.Thread(target=serve, args=(self.config, self.stop, self.log_for, self.status),
                                       daemon=True)
        self.thread.start()
        for event in self.listening.values():
            assert event.wait(20)
        time.sleep(0.3)

    def log_for(self, port):
        def log(line):
            with self.lock:
                self.logs[port.name].append(line)
        return log

    def status(self, name, text):
        if text.startswith("listening") and name in self.listening:
            self.listening[name].set()

    def lines(self, port, start):
        with self.lock:
            return [line for line in self.logs[port] if line.startswith(start)]

    def close(self):
        self.stop.set()
        self.thread.join(10)


def framed(number, body="G0 X1.\nM30"):
    return f"%\nO{number}\n{body}\n%\n"


@pytest.mark.slow
def test_two_ports_sharing_one_folder_punching_at_once_lose_nothing(tmp_path):
    pairs = [PtyPair(), PtyPair()]
    server = Server(tmp_path, [p.near for p in pairs])
    try:
        # Both ports punch the same program numbers at the same moments: every punch needs a name of its own.
        texts = {i: [framed(5000 + k % 3, f"(PORT {i} PUNCH {k})\nG0 X{k}.\nM30") for k in range(30)] for i in (0, 1)}

        def punches(i):
            for text in texts[i]:
                punch(pairs[i].far, b"\x12" + text.encode() + b"\x14", BAUD, delay_s=0.05)

        threads = [threading.Thread(target=punches, args=(i,)) for i in (0, 1)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(300)
        received = tmp_path / "received"
        assert wait_until(lambda: len(server.lines("p0", "received")) + len(server.lines("p1", "received")) == 60)
    finally:
        server.close()
        for p in pairs:
            p.close()
    saved = sorted(path.read_text() for path in received.glob("*.nc"))
    assert saved == sorted(texts[0] + texts[1])
    names = [re.search(r"saved as (\S+)", line)[1] for port in ("p0", "p1") for line in server.lines(port, "received")]
    assert len(set(names)) == 60 and {n for n in names} == {path.name for path in received.glob("*.nc")}


@pytest.mark.slow
def test_a_burst_of_300_small_punches_saves_all_300(tmp_path):
    pair = PtyPair()
    server = Server(tmp_path, [pair.near])
    texts = [framed(7000 + k) for k in range(300)]
    try:
        punch(pair.far, b"".join(b"\x12" + t.encode() + b"\x14" for t in texts), BAUD, delay_s=0.05)
        assert wait_until(lambda: len(server.lines("p0", "received")) == 300)
    finally:
        server.close()
        pair.close()
    received = tmp_path / "received"
    assert sorted(p.name for p in received.glob("*.nc")) == sorted(f"{7000 + k}.nc" for k in range(300))
    assert all((received / f"{7000 + k}.nc").read_text() == texts[k] for k in range(300))


@pytest.mark.slow
def test_a_punch_all_is_split_and_odd_numbers_are_saved_not_lost(tmp_path):
    pair = PtyPair()
    server = Server(tmp_path, [pair.near])
    received = tmp_path / "received"
    try:
        # Three programs in one % frame.
        punch(pair.far, b"\x12%\nO1001\nG0 X1.\nM99\nO1002\nG0 X2.\nM99\nO1003 (MAIN)\nM98 P1001\nM30\n%\x14", BAUD)
        assert wait_until(lambda: len(server.lines("p0", "received")) == 3)
        # A real program numbered as the drip request, whose first comment looks like a program number.
        program = "%\nO9998 (O1234)\nG21 G90\nG0 X10. Y10.\nG1 Z-1. F100.\nM30\n%\n"
        punch(pair.far, b"\x12" + program.encode() + b"\x14", BAUD)
        assert wait_until(lambda: (received / "9998.nc").exists())
        # A program number of 300 digits.
        huge = "%\nO" + "7" * 300 + "\nG0 X1.\nM30\n%\n"
        punch(pair.far, b"\x12" + huge.encode() + b"\x14", BAUD)
        assert wait_until(lambda: (received / "unnumbered.nc").exists())
    finally:
        server.close()
        pair.close()
    assert (received / "1001.nc").read_text() == "%\nO1001\nG0 X1.\nM99\n%\n"
    assert (received / "1002.nc").read_text() == "%\nO1002\nG0 X2.\nM99\n%\n"
    assert (received / "1003.nc").read_text() == "%\nO1003 (MAIN)\nM98 P1001\nM30\n%\n"
    assert (received / "9998.nc").read_text() == program
    assert not server.lines("p0", "request")
    assert (received / "unnumbered.nc").read_text() == huge
    assert any("O-number has 300 digits" in line for line in server.lines("p0", "received"))
    assert not any("ONone" in line or "None.nc" in line for line in server.logs["p0"])


@pytest.mark.slow
def test_a_link_in_the_received_folder_is_never_written_through(tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    received = tmp_path / "received"
    received.mkdir()
    (received / "2001.nc").symlink_to(outside / "stolen.nc")  # dangling
    (tmp_path / "programs").mkdir()
    (tmp_path / "programs" / "1234.nc").symlink_to(outside / "secret.nc")
    (outside / "secret.nc").write_text("%\nO1234\nM30\n%\n")
    pair = PtyPair()
    server = Server(tmp_path, [pair.near])
    try:
        punch(pair.far, b"\x12%\nO2001\nG0 X1.\nM30\n%\x14", BAUD)
        assert wait_until(lambda: (received / "2001.received-2.nc").exists())
        punch(pair.far, b"%\nO9999 (PRG=1234)\nM30\n%\n", BAUD)
        assert wait_until(lambda: server.lines("p0", "request for upload of O1234: "))
    finally:
        server.close()
        pair.close()
    assert not (outside / "stolen.nc").exists() and (received / "2001.nc").is_symlink()
    assert "symbolic link" in server.lines("p0", "request for upload of O1234")[0]
    assert not server.lines("p0", "sent")


@pytest.mark.slow
def test_failed_punches_are_kept_with_their_reason(tmp_path):
    pair = PtyPair()
    server = Server(tmp_path, [pair.near], extra="max_punch_bytes = 2000\n")
    failed = tmp_path / "received" / "failed"
    try:
        # Control codes no program holds, as a baud rate that does not match makes of text.
        garbage = b"\x12%\nO3001\n" + bytes([1, 2, 5, 6, 7, 8, 11, 12, 14, 15]) * 3 + b"\nM30\n%\x14"
        punch(pair.far, garbage, BAUD)
        assert wait_until(lambda: len(list(failed.glob("*.reason"))) == 1)
        long = b"\x12%\nO3002\n" + b"G1 X1. Y2.\n" * 400 + b"M30\n%\x14"
        punch(pair.far, long, BAUD)
        assert wait_until(lambda: len(list(failed.glob("*.reason"))) == 2)
    finally:
        server.close()
        pair.close()
    kept = sorted(failed.glob("*.punch"), key=lambda p: p.stat().st_mtime_ns)
    assert kept[0].read_bytes() == garbage[:-1]  # its DC4, after the closing %, went with the next punch
    assert "baud rate" in kept[0].with_suffix(".reason").read_text()
    # The first punch's DC4 came after its closing %: it opens the next punch's bytes, kept with them.
    wire = kept[1].read_bytes()
    assert wire[:1] == b"\x14" and long.startswith(wire[1:]) and len(wire) > 2000
    reason = kept[1].with_suffix(".reason").read_text()
    assert "max_punch_bytes (2000)" in reason
    # Dropped: the rest up to its closing %; the DC4 after that is no punch of its own.
    assert f"the {len(long) - (len(wire) - 1) - 1} bytes after the limit were discarded" in reason
    assert not list((tmp_path / "received").glob("*.nc"))
    assert len(server.lines("p0", "failed punch")) == 2


@pytest.mark.slow
def test_sigterm_mid_punch_keeps_what_arrived(tmp_path):
    pair = PtyPair()
    (tmp_path / "programs").mkdir()
    cfg = tmp_path / "dnc.toml"
    cfg.write_text(config_text([pair.near]).replace(f"baud = {BAUD}", "baud = 9600"))
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.Popen([sys.executable, "-m", "lagsym", "dnc", "serve", str(cfg)], cwd=tmp_path, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    data = b"\x12%\nO4001\n" + b"G1 X1. Y2. Z3.\n" * 300 + b"M30\n%\x14"
    sim = None
    try:
        assert "listening" in proc.stdout.readline()
        sim = threading.Thread(target=punch, args=(pair.far, data, 9600), daemon=True)
        sim.start()
        failed = tmp_path / "received" / "failed"
        assert wait_until(lambda: any(p.stat().st_size > 500 for p in failed.glob("*.punch")))
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
        if sim is not None:
            sim.join(30)
        pair.close()
    assert proc.returncode == 0, err
    (kept,) = failed.glob("*.punch")
    assert 500 < len(kept.read_bytes()) < len(data) and data.startswith(kept.read_bytes())
    assert "stopped" in kept.with_suffix(".reason").read_text()
    assert "failed punch after" in (tmp_path / "p0.log").read_text()


@pytest.mark.slow
def test_soak_two_ports_punching_and_requesting_at_random_with_faults(tmp_path):
    # Two ports share one folder; each, at random, punches one program or a punch-all, a burst of small
    # punches, garbage, a punch past max_punch_bytes, or a request.  In the end every program punched is in
    # exactly one file, every failed punch in exactly one failed/ file with its bytes, and every log line
    # names a file that holds what it says.  LAGSYM_SOAK_S lengthens it.
    import random

    duration = float(os.environ.get("LAGSYM_SOAK_S", "60"))
    (tmp_path / "programs").mkdir()
    (tmp_path / "programs" / "1234.nc").write_text(framed(1234, "G0 X5.\nM30"))
    pairs = [PtyPair(), PtyPair()]
    server = Server(tmp_path, [p.near for p in pairs], extra="max_punch_bytes = 3000\n")
    programs, failed_bytes, requests = [], [], [0, 0]
    serial_no = iter(range(1, 10**6))

    def program():
        n = next(serial_no)
        return framed(6000 + n % 7, f"(TAG {n})\nG1 X{n}. F100.\nM30")

    def run(i, seed):
        rng = random.Random(seed)
        deadline = time.monotonic() + duration
        while time.monotonic() < deadline:
            kind = rng.choice(["one", "all", "burst", "garbage", "long", "request"])
            if kind == "one":
                text = program()
                programs.append(text)
                data = b"\x12" + text.encode() + b"\x14"
            elif kind == "all":
                parts = [program() for _ in range(rng.randint(2, 4))]
                programs.extend(parts)
                data = b"\x12%\n" + "".join(p[2:-2] for p in parts).encode() + b"%\x14"
            elif kind == "burst":
                parts = [program() for _ in range(rng.randint(5, 30))]
                programs.extend(parts)
                data = b"".join(b"\x12" + p.encode() + b"\x14" for p in parts)
            elif kind == "garbage":
                data = b"\x12%\nO5555\n" + bytes(rng.choice([1, 2, 5, 6, 7]) for _ in range(40)) + b"\n\x14"
                failed_bytes.append(data)
            elif kind == "long":
                data = b"\x12%\nO5556\n" + b"G1 X1. Y2.\n" * 400 + b"M30\n%\x14"
                failed_bytes.append(data)
            else:
                data = b"%\nO9999 (PRG=1234)\nM30\n%\n"
                requests[i] += 1
            punch(pairs[i].far, data, BAUD, delay_s=0.05)
            if kind in ("long", "request"):
                time.sleep(1.5)  # the rest of a long punch is drained; an upload goes back
    threads = [threading.Thread(target=run, args=(i, 1000 + i)) for i in (0, 1)]
    try:
        for t in threads:
            t.start()
        for t in threads:
            t.join(duration + 300)
        received = tmp_path / "received"
        expected_lines = len(programs)
        assert wait_until(lambda: sum(len(server.lines(p, "received")) for p in ("p0", "p1")) >= expected_lines,
                          timeout=120)
        assert wait_until(lambda: len(list((received / "failed").glob("*.reason"))) >= len(failed_bytes))
        time.sleep(2)
    finally:
        server.close()
        for p in pairs:
            p.close()
    saved = sorted(p.read_text() for p in received.glob("*.nc"))
    assert saved == sorted(programs)  # each program exactly once
    # Every failed punch, once: its bytes (after a DC4 or line end left from the punch before) as sent, or the
    # start of them up to the limit for an over-long one.
    files = [p.read_bytes() for p in (received / "failed").glob("*.punch")]
    kept = sorted((len(b), b.lstrip(b"\x14\r\n")) for b in files)
    assert len(kept) == len(failed_bytes)
    for data in failed_bytes:
        match = [k for k in kept if k[1] == data or (k[0] > 3000 and data.startswith(k[1]))]
        assert match, data[:40]
        kept.remove(match[0])
    for port in ("p0", "p1"):
        for line in server.lines(port, "received"):
            name = re.search(r"saved as (\S+)", line)[1]
            number = re.match(r"received O(\d+)", line)[1]
            assert f"\nO{number}\n" in (received / name).read_text()
        assert len(server.lines(port, "sent O1234 (upload)")) == requests[int(port[1])]


@pytest.mark.slow
def test_a_punch_that_starts_during_a_send_is_saved(tmp_path):
    # The server uploads a long program; before it ends the control starts punching (the operator pressed
    # PUNCH): the send stops and the punch is saved, not read as the send's flow control and lost.
    from simcontrol import program_text

    (tmp_path / "programs").mkdir()
    (tmp_path / "programs" / "1234.nc").write_text(program_text(2000).replace("O1000", "O1234"))
    pair = PtyPair()
    server = Server(tmp_path, [pair.near])
    program = framed(4242, "G0 X4.\nM30")
    try:
        punch(pair.far, b"%\nO9999 (PRG=1234)\nM30\n%\n", BAUD)
        assert wait_until(lambda: server.lines("p0", "sending "))
        time.sleep(0.5)
        punch(pair.far, b"\x12" + program.encode() + b"\x14", BAUD, delay_s=0.05)
        assert wait_until(lambda: (tmp_path / "received" / "4242.nc").exists())
    finally:
        server.close()
        pair.close()
    assert (tmp_path / "received" / "4242.nc").read_text() == program
    assert server.lines("p0", "send of O1234 (upload) stopped")
