"""Shop-floor faults on a real line: each told truly, nothing lost (pty pairs, a simulated control, real signals)."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import subprocess
import sys
import termios
import threading
import time
from pathlib import Path

import pytest

from lagsym.dnc import LineFault, LineSettings, parse_program, profile, send_program, transfer_segments
from lagsym.dnc.port import Port
from rfc2217rig import Rfc2217Server
from simcontrol import PROGRAM, KernelPty, PtyPair, chars_per_s, program_text, punch

pytestmark = pytest.mark.socat
ROOT = Path(__file__).resolve().parent.parent


def write(tmp_path, text, name="prog.nc"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def lagsym_process(*argv):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.Popen([sys.executable, "-m", "lagsym", *map(str, argv)], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def wait_until_open(proc, device, timeout=60.0):
    """Whether ``proc`` opened ``device`` (its /proc fd table names it) within ``timeout`` seconds."""
    target = os.path.realpath(device)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        with contextlib.suppress(OSError):  # an fd closed between the listing and the look
            if any(os.readlink(f"/proc/{proc.pid}/fd/{fd}") == target for fd in os.listdir(f"/proc/{proc.pid}/fd")):
                return True
        time.sleep(0.02)
    return False


# -- 6: SIGTERM and SIGHUP are handled as Ctrl-C is ---------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_stops_a_drip_feed_with_the_resume_block_and_exit_3(line, tmp_path, sig):
    # The control runs slower than the line, so it answers XOFF/XON: what it took before is known.
    pair, sim = line(baud=9600, drain_cps=0.5 * chars_per_s(9600))
    path = write(tmp_path, program_text(600))
    proc = lagsym_process("send", path, "--port", pair.near, "--profile", "fanuc", "--mode", "drip", "--quiet")
    assert sim.wait_for(2000, timeout=30)
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=20)
    assert proc.returncode == 3, err
    assert err.startswith(f"lagsym: error: stopped by {sig.name} on {pair.near}; block ") and "--start-block" in err
    assert err.count("\n") == 1


@pytest.mark.slow
def test_a_signal_stops_a_receive_with_exit_3_and_nothing_saved(tmp_path):
    with PtyPair() as pair:
        target = tmp_path / "got.nc"
        proc = lagsym_process("receive", "--port", pair.near, "--timeout", "60", "-o", target)
        # Signalled once it listens on the port (its handlers are in place before it opens it), not after
        # a guessed delay that a loaded machine overruns while the command still imports.
        assert wait_until_open(proc, pair.near)
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=20)
    assert proc.returncode == 3, err
    assert "stopped by SIGTERM; nothing was saved" in err and not target.exists()


@pytest.mark.parametrize("command", ["receive", "send"])
def test_a_signal_while_the_port_opens_is_exit_3_and_leaves_the_port_free(monkeypatch, tmp_path, command):
    # The signal lands after the device is open but before the transfer has begun (a CI run caught a
    # receive there, exit 143 with a generic message): the command stops as it does a moment later.
    import serial

    from lagsym.dnc import receive_program
    from lagsym.dnc.lock import release_lock_file, take_lock_file
    from lagsym.errors import Terminated, TransferError

    opened = serial.Serial.open

    def open_then_signal(self):
        opened(self)
        raise Terminated(signal.SIGTERM)

    with KernelPty() as pair:
        monkeypatch.setattr(serial.Serial, "open", open_then_signal)
        with pytest.raises(TransferError) as info:
            if command == "receive":
                receive_program(pair.near, profile("fanuc"), start_timeout_s=5)
            else:
                send_program(pair.near, parse_program(PROGRAM), profile("fanuc"))
        monkeypatch.undo()
        assert info.value.exit_status == 3
        assert ("stopped by SIGTERM; nothing was saved" if command == "receive"
                else "stopped by SIGTERM while opening") in str(info.value)
        device = os.path.realpath(pair.near)
        held = [fd for fd in os.listdir("/proc/self/fd") if os.path.realpath(f"/proc/self/fd/{fd}") == device]
        assert len(held) == 1  # the pair's own end only: the command's is closed
        lock, holder = take_lock_file(pair.near)  # and its lock file removed
        release_lock_file(lock)
        assert holder is None


# -- 5: the port is opened exclusively ----------------------------------------------------------------------


def test_a_busy_port_is_one_line_and_exit_3(run_cli, tmp_path):
    with PtyPair() as pair:
        holder = Port(pair.near, profile("fanuc"), write_timeout=1)
        try:
            status, out, err = run_cli("send", write(tmp_path, PROGRAM), "--port", pair.near, "--quiet")
            rstatus, _, rerr = run_cli("receive", "--port", pair.near, "--timeout", "1", "--quiet")
        finally:
            holder.close()
    assert status == 3 and rstatus == 3
    assert err == f"lagsym: error: cannot open {pair.near}: the port is in use by another program (another lagsym, " \
                  "a terminal or a DNC service); close it and try again\n"
    assert "in use" in rerr


# -- 2: a stall is a stall, not a lost cable ----------------------------------------------------------------


@pytest.mark.slow
def test_a_missing_dc1_and_a_silent_receive_are_not_called_lost_lines(line, run_cli, tmp_path):
    pair, sim = line(baud=38400)
    status, _, err = run_cli("send", write(tmp_path, PROGRAM), "--port", pair.near, "--wait-for-xon",
                             "--stall-timeout", "0.5", "--quiet")
    assert status == 3 and "sent no DC1 (XON) to start the transfer within 0.5 s" in err
    assert "line was lost" not in err and "reconnect" not in err
    with PtyPair() as other:
        status, _, err = run_cli("receive", "--port", other.near, "--timeout", "0.5", "--quiet")
    assert status == 3 and err.startswith("lagsym: error: nothing arrived") and "line" not in err.split(";")[0][20:]


# -- 1: rfc2217:// works, through a real RFC 2217 server ----------------------------------------------------


@pytest.mark.slow
def test_send_over_rfc2217_arrives_byte_exact(line):
    baud = 38400
    pair, sim = line(baud=baud)
    server = Rfc2217Server(pair.near)
    try:
        prog = parse_program(program_text(80))
        settings = profile("fanuc", baud=baud)
        result = send_program(server.url, prog, settings, "upload")
        expected = b"".join(b for _, b in transfer_segments(prog, settings, "upload"))
        assert sim.wait_for(len(expected))
        assert bytes(sim.received) == expected and result.blocks == len(prog)
    finally:
        server.close()


@pytest.mark.slow
def test_a_drip_feed_over_rfc2217_hears_the_controls_xoff_and_xon(line):
    # Both directions at once through the RFC 2217 server: the program out, DC3 and DC1 back.
    baud = 9600
    pair, sim = line(baud=baud, drain_cps=0.5 * chars_per_s(baud), buffer_chars=256, high_water=192, low_water=64)
    server = Rfc2217Server(pair.near)
    try:
        prog = parse_program(program_text(120))
        settings = profile("fanuc", baud=baud, stall_timeout_s=20)
        events = []
        result = send_program(server.url, prog, settings, "drip", log=events.append)
        expected = b"".join(b for _, b in transfer_segments(prog, settings, "drip"))
        assert sim.wait_for(len(expected))
        assert bytes(sim.received) == expected
        assert sim.xoffs >= 3 and result.xoff_count == sim.xoffs
        pauses = [e.split()[0] for e in events if e.startswith(("XOFF", "XON"))]
        # The last DC3 may come after the last character has left (the server still held some): no XON then.
        assert pauses[::2] == ["XOFF"] * sim.xoffs and set(pauses[1::2]) == {"XON"}
    finally:
        server.close()


@pytest.mark.slow
def test_receive_over_rfc2217(run_cli, tmp_path):
    with PtyPair() as pair:
        server = Rfc2217Server(pair.near)
        text = program_text(20)
        t = threading.Thread(target=punch, args=(pair.far, b"\x12" + text.encode() + b"\x14", 38400),
                             kwargs={"delay_s": 1.0}, daemon=True)
        t.start()
        try:
            status, out, err = run_cli("receive", "--port", server.url, "--baud", 38400, "--timeout", "20",
                                       "--quiet")
        finally:
            t.join(10)
            server.close()
    assert status == 0, err
    assert out == text


# -- 4: delivery, and a dropped line seen through the carrier ----------------------------------------------


@pytest.mark.slow
def test_a_control_that_stops_taking_the_program_is_not_reported_as_delivered(line, run_cli, tmp_path):
    pair, sim = line(baud=38400, discard_after_bytes=1000)
    text = program_text(200)
    status, out, err = run_cli("send", write(tmp_path, text), "--port", pair.near, "--baud", 38400)
    assert status == 0, err
    assert len(sim.received) == 1000
    # The message says what was sent (all of it) and that nothing confirmed it arrived.
    sent = re.match(rf"sent (\d+) blocks \((\d+) bytes\) to {re.escape(pair.near)} in ", out)
    assert sent and int(sent[1]) == text.count("\n") - 2 and int(sent[2]) == len(text)
    assert out.splitlines()[1].startswith("the control confirmed nothing: it never answered XON/XOFF")


@pytest.mark.parametrize("flow", ["xonxoff", "rtscts", "dtrdsr", "none"])
def test_the_flow_control_setting_reaches_the_port_and_the_kernel(flow):
    # A pty has no modem lines, but it keeps the hardware flow-control flag: the kernel's own view of the
    # line (read through the master side) shows what lagsym asked for.  Linux has no DTR/DSR flow control
    # in the kernel: there it is pyserial's setting and lagsym's pause on DSR.
    with KernelPty() as pair:
        port = Port(pair.near, profile("fanuc", flow=flow), write_timeout=1)
        try:
            iflag, _, cflag, _, ispeed, _, _ = termios.tcgetattr(pair.fd)
            assert port._ser.rtscts == (flow == "rtscts") and port._ser.dsrdtr == (flow == "dtrdsr")
        finally:
            port.close()
    assert bool(cflag & termios.CRTSCTS) == (flow == "rtscts")
    assert not iflag & (termios.IXON | termios.IXOFF)  # XON/XOFF stays lagsym's, never the kernel's
    assert ispeed == termios.B9600 and cflag & termios.CSTOPB  # the rest of the set-up reached it too


@pytest.mark.slow
@pytest.mark.parametrize("flow, signal_name", [("rtscts", "cts"), ("dtrdsr", "dsr")])
def test_a_low_cts_or_dsr_pauses_the_send_until_it_rises(line, flow, signal_name):
    # The RFC 2217 server reports the modem lines the test sets, as a serial server reports its port's.
    baud = 9600
    pair, sim = line(baud=baud)
    server = Rfc2217Server(pair.near)
    prog = parse_program(program_text(200))
    settings = profile("fanuc", baud=baud, flow=flow)
    counts, events = [], []

    def hold():
        sim.wait_for(1500)
        setattr(server.lines, signal_name, False)
        time.sleep(1.0)  # what was on its way arrives
        counts.append(sim.arrived)
        time.sleep(1.0)
        counts.append(sim.arrived)
        setattr(server.lines, signal_name, True)

    t = threading.Thread(target=hold, daemon=True)
    t.start()
    try:
        result = send_program(server.url, prog, settings, "drip", log=events.append)
    finally:
        t.join(10)
        server.close()
    up = signal_name.upper()
    assert [e.split()[:2] for e in events if e.startswith(up)] == [[up, "low"], [up, "high"]]
    expected = b"".join(b for _, b in transfer_segments(prog, settings, "drip"))
    assert sim.wait_for(len(expected))
    assert bytes(sim.received) == expected
    assert 1500 <= counts[0] == counts[1] < len(expected)  # nothing went while the signal was low
    assert result.confirmed


@pytest.mark.slow
def test_a_dropped_dsr_is_a_lost_line_within_a_second(line):
    baud = 9600
    pair, sim = line(baud=baud)
    server = Rfc2217Server(pair.near)
    prog = parse_program(program_text(400))
    settings = profile("fanuc", baud=baud, carrier="dsr", buffer_chars=0)
    dropped = []

    def drop():
        sim.wait_for(1500)
        server.lines.dsr = False
        dropped.append(time.monotonic())

    t = threading.Thread(target=drop, daemon=True)
    t.start()
    try:
        with pytest.raises(LineFault, match="the control dropped DSR") as info:
            send_program(server.url, prog, settings, "drip")
        seen = time.monotonic()
    finally:
        t.join(5)
        server.close()
    assert seen - dropped[0] < 1.0
    assert info.value.start_block == info.value.last_block + 1


def test_a_carrier_the_port_cannot_sense_is_refused(run_cli, tmp_path):
    with PtyPair() as pair:
        status, _, err = run_cli("send", write(tmp_path, PROGRAM), "--port", pair.near, "--carrier", "cd", "--quiet")
    assert status == 3 and "reports no CD line" in err


# -- 8: drip feeds, long holds and memory -------------------------------------------------------------------


def test_a_macro_program_is_refused_for_a_drip_feed(run_cli, tmp_path):
    macro = "%\nO1\n#1=0\nWHILE[#1LT3]DO1\n#1=#1+1\nEND1\nM30\n%\n"
    status, _, err = run_cli("send", write(tmp_path, macro, "m.nc"), "--port", "loop://", "--mode", "drip")
    assert status == 2 and "block 3 (WHILE[#1LT3]DO1) loops or jumps" in err and "--mode upload" in err


@pytest.mark.slow
def test_stall_timeout_forever_waits_out_a_long_hold(line, run_cli, tmp_path):
    pair, sim = line(baud=38400, xon_after_s=1.5)
    status, _, err = run_cli("send", write(tmp_path, PROGRAM), "--port", pair.near, "--baud", 38400,
                             "--wait-for-xon", "--stall-timeout", "forever", "--quiet")
    assert status == 0, err
    status, _, err = run_cli("send", write(tmp_path, PROGRAM), "--port", "loop://", "--stall-timeout", "-1")
    assert status == 2 and "forever" in err


@pytest.mark.slow
def test_an_upload_larger_than_the_memory_is_refused(run_cli, tmp_path):
    text = program_text(100)
    size = len(b"".join(b for _, b in transfer_segments(parse_program(text), profile("fanuc"))))
    status, _, err = run_cli("send", write(tmp_path, text), "--port", "loop://", "--profile", "fanuc",
                             "--memory-chars", size - 1)
    assert status == 2 and f"{size} characters do not fit the control's memory of {size - 1}" in err
    status, _, err = run_cli("send", write(tmp_path, text), "--port", "loop://", "--profile", "fanuc",
                             "--memory-chars", size, "--quiet")
    assert status == 0, err


# -- 9: resume from what the control shows ------------------------------------------------------------------


def _all_lines(sim, segments) -> list[str]:
    """The control's lines once it has every byte of ``segments``: a send ends when its last byte has left the
    port, and socat's relay can lag behind on a loaded machine."""
    assert sim.wait_for(sum(len(chunk) for _, chunk in segments))
    return sim.lines()


def test_start_at_the_n_number_the_control_shows(line, run_cli, tmp_path):
    text = PROGRAM.replace("G1 X30.", "N900 G1 X30.")
    pair, sim = line(baud=38400)
    status, _, err = run_cli("send", write(tmp_path, text), "--port", pair.near, "--baud", 38400, "--mode", "drip",
                             "--start-at", "N900", "--no-handshake-expected", "--quiet")
    assert status == 0, err
    lines = _all_lines(sim, transfer_segments(parse_program(text), LineSettings(baud=38400), "drip", start_block=11))
    assert lines[1] == "(RESUME AT BLOCK 11)" and lines[-4:] == ["N900 G1 X30.", "G0 Z25.", "M30", "%"]


# -- 10: receive: no overwrite, says when to punch, garbage, TV and ISO checks -------------------------------


def test_receive_refuses_to_overwrite_and_says_when_to_punch(run_cli, tmp_path):
    target = tmp_path / "old.nc"
    target.write_text("keep me\n")
    status, _, err = run_cli("receive", "--port", "loop://", "-o", target)
    assert status == 2 and "exists" in err and "--overwrite" in err and target.read_text() == "keep me\n"
    with PtyPair() as pair:
        status, _, err = run_cli("receive", "--port", pair.near, "--timeout", "0.3", "-o", tmp_path / "new.nc")
    assert status == 3
    assert err.startswith(f"waiting on {pair.near} for 0.3 s: start the output (PUNCH) on the control now\n")


def test_garbage_from_a_baud_mismatch_says_to_check_the_settings(run_cli, tmp_path):
    with PtyPair() as pair:
        junk = bytes([0x12, 0x25, 0x0a]) + bytes(range(0x80, 0xff)) + b"\x0a%\x0a"
        t = threading.Thread(target=punch, args=(pair.far, junk, 38400), daemon=True)
        t.start()
        status, _, err = run_cli("receive", "--port", pair.near, "--baud", 38400, "--bytesize", 8, "--parity",
                                 "none", "--stopbits", 1, "--timeout", "20", "--quiet", "-o", tmp_path / "x.nc")
        t.join(10)
    assert status == 3, err
    assert "127 of the 131 characters" in err and "check the baud rate and format (38400 baud, 8N1)" in err
    assert not (tmp_path / "x.nc").exists()


def test_tv_check_pads_blocks_to_even_and_iso_check_refuses_lower_case(line, run_cli, tmp_path):
    pair, sim = line(baud=38400)
    status, _, err = run_cli("send", write(tmp_path, PROGRAM), "--port", pair.near, "--baud", 38400, "--tv-check",
                             "--quiet")
    assert status == 0, err
    lines = _all_lines(sim, transfer_segments(parse_program(PROGRAM), LineSettings(baud=38400, tv_check=True)))
    assert lines[1:-1] == [b if len(b) % 2 else b + " " for b in parse_program(PROGRAM).blocks]
    assert all((len(x) + 1) % 2 == 0 for x in lines)
    status, _, err = run_cli("send", write(tmp_path, PROGRAM.replace("M8", "M8 (coolant)")), "--port", "loop://",
                             "--iso-check")
    assert status == 2 and "block 7 holds" in err and "ISO 840" in err
