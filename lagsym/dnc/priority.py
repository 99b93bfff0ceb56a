"""Real-time scheduling for the sending thread, so that a busy computer still wakes it in time.

XON/XOFF leaves the sender to keep the characters in flight below what the
control takes past its DC3 (about 10 on a Fanuc), so the sender must wake
again before the few it wrote have left the line: within 0.35 ms for a
window of 4 at 115200 baud, 4 ms at 9600.  An ordinary thread on a loaded
computer is woken milliseconds late, and the line idles while it sleeps
(``benchmarks/bench_dnc.py`` measures the line rate reached under load).  With
``LineSettings.realtime`` the thread that sends runs under ``SCHED_FIFO`` at
:data:`PRIORITY` for the transfer and is put back after it: the scheduler
then runs it as soon as it wakes.  The sender waits on the port between
writes (it never spins), and Linux keeps 5 % of every second for ordinary
threads (``sched_rt_runtime_us``) however a real-time thread behaves.

Allowed to root, to a program with ``CAP_SYS_NICE``, or to a user whose
``rtprio`` limit (``ulimit -r``, ``/etc/security/limits.conf``) is at least
:data:`PRIORITY`.  Refused otherwise before anything is sent, with what to
change (exit status 3, a fault of the computer's set-up, not of the program).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator

from ..errors import TransferError

__all__ = ["PRIORITY", "realtime"]

PRIORITY = 10
"""The ``SCHED_FIFO`` priority of the sending thread (1-99; LinuxCNC's servo threads run far higher)."""


@contextlib.contextmanager
def realtime(enabled: bool) -> Iterator[None]:
    """Run the calling thread under ``SCHED_FIFO`` at :data:`PRIORITY` inside the block, if ``enabled``."""
    if not enabled:
        yield
        return
    if not hasattr(os, "sched_setscheduler"):
        raise TransferError("real-time priority (--realtime) is not available on this system; send without it "
                            "and keep --overrun-chars for the baud rate the computer keeps up with")
    policy, param = os.sched_getscheduler(0), os.sched_getparam(0)
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(PRIORITY))
    except PermissionError:
        raise TransferError(
            f"the system refused real-time priority {PRIORITY} for the sender (--realtime): allow it with "
            f"an 'rtprio {PRIORITY}' line for this user in /etc/security/limits.conf (then log in again) or "
            "'sudo setcap cap_sys_nice+ep' on the Python interpreter, or send without --realtime") from None
    try:
        yield
    finally:
        os.sched_setscheduler(0, policy, param)
