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
        m = re.search(r"times, which show that block (\d+) surely reached it; the blocks after it left the port "
                      r"but nothing shows that the control holds them", out)
    assert m, out + err
    held = whole_blocks(sim.stop()["received"])
    assert 1 <= int(m[1]) <= held < 603


@pytest.mark.slow
@pytest.mark.parametrize("late_s", [0.0, 0.4])
def test_a_fault_after_a_silent_death_resumes_within_what_the_control_holds(line, late_s):
    # Stopped (as by SIGTERM) long after the control silently stopped taking the program: the resume block
    # comes from what surely arrived, never from what only left the port.  With late answers the computer
    # delivers each DC3 and DC1 0.4 s after the control sent it (about 1,500 characters at this rate).
    baud = 38400
    pair, sim = line(baud=baud, drain_cps=0.3 * chars_per_s(baud), buffer_chars=512, high_water=384, low_water=64,
                     discard_after_bytes=3000, late_answers_s=late_s)
    settings = profile("fanuc", baud=baud, buffer_chars=512, stall_timeout_s=5.0)

    def progress(p):
        if p.bytes_done > 9000:
            raise KeyboardInterrupt

    with pytest.raises(LineFault) as info:
        send_program(pair.near, parse_program(program_text(900)), settings, "drip", progress=progress)
    fault = info.value
    record = sim.stop()
    held = whole_blocks(record["received"])
    assert fault.last_block <= held and fault.start_block <= held + 1
    # An XOFF after the XON that ended a pause proves what was written before that pause (a few hundred
    # characters: past block 1).  The control sends a second XOFF only after an XON; if it died inside its first
    # (on a loaded machine the sender can be late to hear it while the control takes the rest), nothing is
    # proved and "no block surely reached the control" is the true answer.
    if record["xoffs"] >= 2:
        assert fault.last_block >= 1, (record["xoffs"], str(fault))
    if "held XOFF (DC3) for more than 5 s" in str(fault):
        return  # it died inside an XOFF (when depends on the machine's load): a stall, told truly
    assert fault.last_left_block > held  # the port took far more than the control holds
    assert f"blocks {fault.last_block + 1} to {fault.last_left_block} left the port, but no answer of the " \
           "control shows that it holds them" in str(fault)


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


def test_an_xoff_vouches_only_for_what_was_written_before_the_pause_the_last_xon_ended():
    """When an answer was sent cannot be told from when it was read: a loaded computer holds the control's
    DC3 back as long as it likes (a kernel pty's input work once held one for about half a second, and the
    sender was credited 1,700 characters the control never held).  So only what the protocol proves
    counts: a DC3 after the XON that ended a pause shows the buffer rose after that XON, past all that had
    been written before the pause; a DC3 with no XON before it, and an XON, prove nothing of their own."""
    from lagsym.dnc.sender import Sender

    segments = [(n, f"N{n} G1 X{n}.\n".encode()) for n in range(1, 401)]
    line = _Quiet()
    sender = Sender(line, segments, profile("haas", baud=115200), "drip", "/dev/null", progress=None, log=None)

    def look(now, pos, answer=b""):
        sender.pos, sender.line_free, sender.queued = pos, 0.0, 0  # everything written has left the line
        line.incoming = answer
        sender.poll(now)

    look(10.0, 2000, b"\x13")  # the first XOFF: however early it was sent, nothing shows how much it holds
    assert sender.known == 0 and sender.paused and sender.last_sure_block() == 0
    look(11.0, 2000, b"\x11")  # the XON that ends the pause: it proves nothing yet
    assert sender.known == 0 and not sender.paused
    look(11.5, 3000, b"\x11")  # an XON while sending (a repeat): no pause ended, nothing to build on
    look(30.0, 6000, b"\x13")  # an XOFF read long after: the buffer rose after the XON at 2000 bytes
    assert sender.known == 2000
    assert sender.last_sure_block() == max(n for end, n in sender.ends if end <= 2000)
    look(31.0, 6000, b"\x11\x13")  # XON and XOFF in one read: the pause had ended at 6000 bytes
    assert sender.known == 6000
