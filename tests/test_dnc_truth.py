"""A send tells apart what left the port and what the control surely holds (kernel pty pairs, a simulated control).

The kernel pair has no relay between the ends: a DC3 is readable by the
sender the moment the control writes it, as at a real UART.  Through socat's
relay a loaded machine held a DC3 back for longer than 800 characters take on
the line, so the sender, rightly crediting what had left before its last look
found no answer, credited bytes the dying control had never taken.
"""

from __future__ import annotations

import functools
import re

import pytest

from lagsym.dnc import LineFault, LineSettings, parse_program, profile, send_program, transfer_segments
from simcontrol import chars_per_s, program_text

@pytest.fixture
def line(line):
    """The shared fixture's kernel pairs only."""
    return functools.partial(line, kernel=True)


def write(tmp_path, text, name="prog.nc"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def whole_blocks(received: bytes) -> int:
    """Program blocks the control holds whole: complete lines after the leading % line."""
    return max(0, len(received.replace(b"\x00", b"").split(b"\n")) - 2)


@pytest.mark.slow
def test_a_drip_feed_the_control_never_answered_is_exit_3(line, run_cli, tmp_path):
    # The control stops taking the program after 1500 characters while the line stays up, and it reads
    # faster than the line, so it never says XOFF: nothing ever showed that it took anything.
    baud = 38400
    pair, sim = line(baud=baud, discard_after_bytes=1500)
    text = program_text(603)
    status, out, err = run_cli("send", write(tmp_path, text), "--port", pair.near, "--baud", baud, "--mode", "drip")
    assert status == 3, out + err
    assert "never answered with flow control" in err and "--no-handshake-expected" in err
    assert "no block surely reached the control" in err and err.count("\n") == 1
    assert "--start-block" not in err and "send again" in err  # nothing known: from the start
    assert len(sim.received) == 1500


@pytest.mark.slow
def test_no_handshake_expected_accepts_a_silent_control_and_says_nothing_is_confirmed(line, run_cli, tmp_path):
    baud = 38400
    pair, sim = line(baud=baud)
    text = program_text(120)
    status, out, err = run_cli("send", write(tmp_path, text), "--port", pair.near, "--baud", baud, "--mode", "drip",
                               "--no-handshake-expected")
    assert status == 0, err
    assert "the control confirmed nothing: it never answered XON/XOFF" in out
    expected = b"".join(b for _, b in transfer_segments(parse_program(text), LineSettings(baud=baud), "drip"))
    assert sim.wait_for(len(expected)) and bytes(sim.received) == expected


@pytest.mark.slow
def test_a_control_that_dies_after_answering_is_never_credited_past_its_last_answer(line, run_cli, tmp_path):
    # The control runs slower than the line and says XOFF/XON, then stops taking the program while the
    # line stays up: it takes everything and answers nothing.  The summary credits it only with what had
    # left the port when it last answered, which it does hold.
    baud = 38400
    pair, sim = line(baud=baud, drain_cps=0.3 * chars_per_s(baud), buffer_chars=512, high_water=384, low_water=64,
                     discard_after_bytes=3000)
    text = program_text(603)
    status, out, err = run_cli("send", write(tmp_path, text), "--port", pair.near, "--baud", baud, "--mode", "drip",
                               "--stall-timeout", "20")
    if status == 3:  # it stopped inside an XOFF (when depends on the machine's load): a stall, told truly
        assert "the control held XOFF (DC3) for more than 20 s" in err, err
        m = re.search(r"block (\d+) surely reached the control", err)
    else:
        assert status == 0, err
        m = re.search(r"the last after block (\d+): block \1 surely reached it; the blocks after it left the port "
                      r"but nothing shows that the control holds them", out)
    assert m, out + err
    held = whole_blocks(sim.stop()["received"])
    assert 1 <= int(m[1]) <= held < 603


@pytest.mark.slow
def test_a_fault_after_a_silent_death_resumes_within_what_the_control_holds(line):
    # Stopped (as by SIGTERM) long after the control silently stopped taking the program: the resume block
    # comes from what surely arrived, never from what only left the port.
    baud = 38400
    pair, sim = line(baud=baud, drain_cps=0.3 * chars_per_s(baud), buffer_chars=512, high_water=384, low_water=64,
                     discard_after_bytes=3000)
    settings = profile("fanuc", baud=baud, buffer_chars=512, stall_timeout_s=20.0)

    def progress(p):
        if p.bytes_done > 9000:
            raise KeyboardInterrupt

    with pytest.raises(LineFault) as info:
        send_program(pair.near, parse_program(program_text(900)), settings, "drip", progress=progress)
    fault = info.value
    held = whole_blocks(sim.stop()["received"])
    assert 1 <= fault.last_block <= held and fault.start_block <= held + 1
    if "held XOFF (DC3) for more than 20 s" in str(fault):
        return  # it died inside an XOFF (when depends on the machine's load): a stall, told truly
    assert fault.last_left_block > held  # the port took far more than the control holds
    assert f"blocks {fault.last_block + 1} to {fault.last_left_block} left the port, but the control did not " \
           "answer after them" in str(fault)


def test_garbage_answers_from_a_control_at_another_baud_rate_stop_the_send(line, run_cli, tmp_path):
    baud = 19200
    pair, sim = line(baud=baud, drain_cps=0.3 * chars_per_s(baud), garble_answers=True)
    status, out, err = run_cli("send", write(tmp_path, program_text(300)), "--port", pair.near, "--baud", baud,
                               "--mode", "drip", "--quiet")
    assert status == 3, out + err
    assert "the control answered 0xE6" in err and "check the baud rate and format (19200 baud, 7E2)" in err
    assert err.count("\n") == 1


class _Quiet:
    """A line that took every byte at once and has nothing to read until told: the sender's looks, by hand."""

    def __init__(self):
        self.incoming = b""

    def read(self, _n):
        got, self.incoming = self.incoming, b""
        return got


def test_an_answer_vouches_only_for_what_had_left_a_settling_time_before_the_last_look_that_found_none():
    """The way back takes time too: an answer read now may have been sent before the last look (which found
    none) by up to the settling time, so it vouches for what had left by then, not for what left since.  A
    control answering from the first blocks, its DC3 delivered late, used to be credited with blocks it never
    held (a loaded machine's delivery, a USB adapter's latency timer)."""
    from lagsym.dnc.sender import Sender

    segments = [(n, f"N{n} G1 X{n}.\n".encode()) for n in range(1, 401)]
    line = _Quiet()
    sender = Sender(line, segments, profile("haas", baud=115200), "drip", "/dev/null", progress=None, log=None)
    settle = sender.settle_s
    first, second = 2000, 4000

    def look(now, pos, answer=b""):
        sender.pos, sender.line_free, sender.queued = pos, 0.0, 0  # everything written has left the line
        line.incoming = answer
        sender.poll(now)

    look(10.0, first)
    look(10.0 + 4 * settle, second)  # more has left since: the control's answer may be older than this look
    look(10.0 + 4 * settle + 0.001, second, b"\x13")
    assert sender.known == first < second
    assert sender.last_sure_block() == max(n for end, n in sender.ends if end <= first)
    look(10.0 + 8 * settle, second)
    look(10.0 + 8 * settle + 0.001, second, b"\x11")  # a later answer vouches for what had left by then
    assert sender.known == second
