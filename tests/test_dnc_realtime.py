"""The sender at real-time priority (``--realtime``): granted for the send and given back, or refused first.

Real parts: a kernel pty pair with the simulated control on its far end, and
the scheduler's own answer (``sched_getscheduler``) read from inside the send.
Where this machine refuses real-time priority, the send must be refused
before the port opens, which the second test checks in a child process
whose real-time limit is 0 (and which is not root).
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from lagsym.dnc import parse_program, profile, send_program, transfer_segments
from lagsym.dnc.priority import PRIORITY
from lagsym.errors import TransferError
from simcontrol import KernelPty, SimControl, program_text

ROOT = Path(__file__).resolve().parent.parent


def _granted() -> bool:
    """Whether this process may run a thread under SCHED_FIFO (it is put back at once)."""
    policy, param = os.sched_getscheduler(0), os.sched_getparam(0)
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(PRIORITY))
    except PermissionError:
        return False
    os.sched_setscheduler(0, policy, param)
    return True


@pytest.mark.slow
def test_the_send_runs_at_real_time_priority_and_gives_it_back():
    baud = 38400
    prog = parse_program(program_text(150))
    # A control that never says XOFF: the feed is accepted without an answer.
    settings = profile("fanuc", baud=baud, realtime=True, stall_timeout_s=20, handshake_expected=False)
    seen = []
    before = os.sched_getscheduler(0), os.sched_getparam(0).sched_priority
    with KernelPty() as pair:
        sim = SimControl(pair.far, baud=baud)
        sim.start()
        try:
            expected = b"".join(b for _, b in transfer_segments(prog, settings, "drip"))
            if not _granted():
                with pytest.raises(TransferError, match=r"refused real-time priority 10 .*rtprio"):
                    send_program(pair.near, prog, settings, "drip")
                assert len(sim.received) == 0  # refused before the port opened
                return
            send_program(pair.near, prog, settings, "drip",
                         progress=lambda p: seen.append((os.sched_getscheduler(0), os.sched_getparam(0).sched_priority)))
            assert sim.wait_for(len(expected))
            assert bytes(sim.received) == expected
        finally:
            sim.stop()
    assert seen and set(seen) == {(os.SCHED_FIFO, PRIORITY)}
    assert (os.sched_getscheduler(0), os.sched_getparam(0).sched_priority) == before


def _no_rtprio():
    """In the child: a real-time limit of 0, which it cannot raise again."""
    resource.setrlimit(resource.RLIMIT_RTPRIO, (0, 0))


# Root would still be granted through CAP_SYS_NICE: its child runs without it (setpriv is util-linux's,
# in every Debian system).
_WITHOUT_SYS_NICE = ["setpriv", "--bounding-set", "-sys_nice", "--inh-caps", "-sys_nice"] if os.geteuid() == 0 else []


@pytest.mark.slow
def test_a_refused_priority_is_one_line_exit_3_before_the_port_opens():
    with tempfile.TemporaryDirectory() as tmp:
        prog = Path(tmp) / "O1.nc"
        prog.write_text("%\nO1\nG00 X0\nM30\n%\n")
        env = dict(os.environ, PYTHONPATH=str(ROOT))
        missing = "/dev/lagsym-no-such-port"

        def send(*extra):
            return subprocess.run([*_WITHOUT_SYS_NICE, sys.executable, "-m", "lagsym", "send", str(prog), "--port",
                                   missing, *extra], cwd=tmp, env=env, capture_output=True, text=True, timeout=60,
                                  preexec_fn=_no_rtprio)

        refused = send("--realtime")
        plain = send()
    assert refused.returncode == 3, refused.stderr
    assert refused.stderr.count("\n") == 1 and "Traceback" not in refused.stderr
    assert f"the system refused real-time priority {PRIORITY}" in refused.stderr
    assert "limits.conf" in refused.stderr and "without --realtime" in refused.stderr
    assert missing not in refused.stderr  # the port was never opened
    assert plain.returncode == 3 and missing in plain.stderr  # without the option the port is what fails
