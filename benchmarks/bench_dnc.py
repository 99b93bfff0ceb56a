"""Drip-feed throughput, overflow and starvation: lagsym's sender against the simulated control's line rate.

A pty pair has no baud rate: whatever is written to one end can be read at
the other at once.  The line rate here is the simulated control's
(tests/simcontrol.py): it takes characters from its end no faster than its
baud allows (7E2: baud / 11 characters per second), so what it has not yet
taken is what is still on the wire, and that is what arrives after its DC3.
Three controls, each with a sender window (``overrun_chars``, the most
characters lagsym keeps on their way) that fits what the control takes past
its DC3 (its headroom):

* ``fanuc``: a 256-character buffer, DC3 at 192, DC1 at 64; headroom 10 (a
  Fanuc raises alarm 087 about 10 characters past DC3); window 4, the default;
* ``room64``: the same buffer, headroom 64 (the room left above the DC3
  mark); window 32;
* ``room256``: a 512-character buffer, DC3 at 256, DC1 at 128, headroom
  256; window 128.

Per control and baud rate:

* throughput at the line rate: a control that empties its buffer at once,
  so the line is the only limit; the time a perfect sender needs (bytes over
  the line rate) over the time from the first to the last character;
* a control whose machine consumes at 90 % of the line rate: the buffer
  fills slowly, the control says XOFF and XON, and the figures are the
  throughput against a perfect sender (which fills the buffer at the line
  rate and then keeps up with the machine), the XOFF count, the overflow
  (characters received after a DC3 beyond the headroom, summed over every
  XOFF and every run), the most characters after any one DC3, and the
  starvation (time the machine found the buffer empty while some of the
  program had not yet arrived).

Time the simulated control itself lost to the scheduler is not charged to
the sender.  The peer in the same run is the line itself: the ratios, not
the seconds, are the figures (the machine is shared and noisy).  The kernel
rig is a pty pair with no relay in between, as a real UART; on the socat
rig a loaded machine can hold a DC3 in the relay for tens of milliseconds,
which shows as characters past DC3 that no real line would carry.

``--load N`` runs N busy processes beside the transfers (a shop PC doing
other work), and the load average is recorded with the figures.  With the
default controls and baud rates the headline goes to
``benchmarks/results.json`` (``dnc``, or ``dnc-realtime`` with
``--realtime``): the least line rate any control reached, with each
control's figures at 115200 baud in its detail.

Run:  python3 benchmarks/bench_dnc.py [--baud 9600 115200] [--control fanuc room256] [--runs 3] [--blocks 400]
      python3 benchmarks/bench_dnc.py --load 10            # the recorded headline
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import results as recorded  # noqa: E402
from lagsym.dnc import parse_program, profile, send_program, transfer_segments  # noqa: E402
from lagsym.dnc.priority import PRIORITY  # noqa: E402
from simcontrol import KernelPty, PtyPair, SimControl, chars_per_s, program_text  # noqa: E402

# name: (buffer, DC3 mark, DC1 mark, headroom past DC3, sender window), characters
CONTROLS = {"fanuc": (256, 192, 64, 10, 4), "room64": (256, 192, 64, 64, 32), "room256": (512, 256, 128, 256, 128)}
BAUDS = (9600, 19200, 38400, 57600, 115200)


def run(baud: int, blocks: int, drain: float | None, rig: str, control: str, realtime: bool = False) -> dict:
    """One drip feed; ``drain`` is the machine's rate over the line rate (None: it empties the buffer at once)."""
    buffer, high, low, headroom, window = CONTROLS[control]
    prog = parse_program(program_text(blocks))
    # A control that empties its buffer at once never answers, nor one fed slower than its machine runs:
    # no handshake is expected of them (the figures here are the line rates, the truth is the tests').
    settings = profile("fanuc", baud=baud, overrun_chars=window, buffer_chars=buffer, stall_timeout_s=30,
                       realtime=realtime, handshake_expected=False)
    cps = chars_per_s(baud)
    with (KernelPty() if rig == "kernel" else PtyPair()) as pair:
        sim = SimControl(pair.far, pair=pair if rig == "socat" else None, baud=baud,
                         drain_cps=None if drain is None else drain * cps,
                         buffer_chars=buffer, high_water=high, low_water=low, tolerance=headroom)
        sim.start()
        if realtime:  # a real control's UART and firmware answer at once: so does the simulated one here
            os.sched_setscheduler(sim._proc.pid, os.SCHED_FIFO, os.sched_param(PRIORITY + 1))
        expected = b"".join(b for _, b in transfer_segments(prog, settings, "drip"))
        send_program(pair.near, prog, settings, "drip")
        sim.wait_for(len(expected))
        rec = sim.stop()
    n = len(expected)
    if drain is None:
        ideal_s = n / cps
    else:
        # A perfect sender fills the buffer to its high mark at the line rate (the buffer grows at
        # (1 - drain) of it), then the control takes characters as fast as the machine consumes them.
        fill = min(n, high / (1 - drain))
        ideal_s = fill / cps + (n - fill) / (drain * cps)
    span = rec["last_byte_at"] - rec["first_byte_at"]
    return {"bytes": n, "exact": rec["received"] == expected, "throughput": ideal_s / span if span > 0 else 0.0,
            "xoffs": rec["xoffs"], "overflow": rec["overflow"], "max_after_xoff": rec["max_after_xoff"],
            "starved_s": rec["starved_s"], "span_s": span}


def spread(values, fmt: str) -> str:
    """min / median of a figure over the runs."""
    values = sorted(values)
    low, mid = format(values[0], fmt), format(statistics.median(values), fmt)
    return low if len(values) == 1 else f"{low} / {mid}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baud", type=int, nargs="+", default=list(BAUDS))
    ap.add_argument("--control", choices=tuple(CONTROLS), nargs="+", default=list(CONTROLS),
                    help="the simulated controls (see the module notes)")
    ap.add_argument("--blocks", type=int, default=400, help="program length in blocks (about 26 characters each)")
    ap.add_argument("--drain", type=float, default=0.9, help="machine's consumption over the line rate")
    ap.add_argument("--runs", type=int, default=1, help="repeat each measurement; figures are min / median")
    ap.add_argument("--rig", choices=("kernel", "socat"), default="kernel",
                    help="pty pair: kernel (no relay, as a real UART) or socat (a relay process in between)")
    ap.add_argument("--realtime", action="store_true",
                    help="the sender at real-time priority (LineSettings.realtime), and the simulated control "
                         "one above it, as a control's UART and firmware; needs root or CAP_SYS_NICE")
    ap.add_argument("--load", type=int, default=0, help="busy processes to run beside the transfers")
    recorded.add_option(ap)
    args = ap.parse_args()
    busy = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(args.load)]
    try:
        table = measure(args)
        if args.baud == list(BAUDS) and args.control == list(CONTROLS) and args.drain == 0.9:
            record(args, table)  # while the busy processes run: the load average recorded is theirs
    finally:
        for proc in busy:
            proc.kill()
            proc.wait()


def record(args, table: dict) -> None:
    """The headline: the least median line rate of any control and baud, with the 115200-baud figures."""
    worst_key = min(table, key=lambda k: table[k]["line"])
    worst = table[worst_key]
    detail = "; ".join(
        f"{c} at 115200: {table[(c, 115200)]['line']:.1%} of the line, {table[(c, 115200)]['held']:.1%} with "
        f"XOFF, {table[(c, 115200)]['overflow']} past its headroom" for c in CONTROLS)
    task = (f"drip feed, {args.blocks} blocks, beside {args.load} busy processes"
            f"{', the sender at real-time priority' if args.realtime else ''} (the least of 3 controls x 5 baud "
            f"rates: {worst_key[0]} at {worst_key[1]})")
    recorded.record("dnc-realtime" if args.realtime else "dnc", task=task, peer="the line itself (a perfect sender)",
                    ratio=worst["line"], detail=detail, path=args.results)


def measure(args) -> dict:
    """Print the table; the medians per (control, baud)."""
    table = {}
    print(f"rig {args.rig}; sender {'at real-time priority' if args.realtime else 'an ordinary thread'}; "
          f"{args.load} busy processes; machine at {args.drain:.0%} of the line rate for the XOFF columns; "
          f"{args.runs} run(s), figures min / median")
    print(f"{'control':>8} {'window':>6} {'headroom':>8} {'baud':>6} {'bytes':>6} {'exact':>5} {'line rate':>15} "
          f"{'with XOFF':>15} {'XOFF':>7} {'overflow':>8} {'max past DC3':>12} {'starved s':>13}")
    for control in args.control:
        _, _, _, headroom, window = CONTROLS[control]
        for baud in args.baud:
            free = [run(baud, args.blocks, None, args.rig, control, args.realtime) for _ in range(args.runs)]
            held = [run(baud, args.blocks, args.drain, args.rig, control, args.realtime) for _ in range(args.runs)]
            exact = all(r["exact"] for r in free + held)
            print(f"{control:>8} {window:>6} {headroom:>8} {baud:>6} {free[0]['bytes']:>6} {str(exact):>5} "
                  f"{spread([r['throughput'] for r in free], '.1%'):>15} "
                  f"{spread([r['throughput'] for r in held], '.1%'):>15} "
                  f"{spread([r['xoffs'] for r in held], 'd'):>7} {sum(r['overflow'] for r in free + held):>8} "
                  f"{max(r['max_after_xoff'] for r in held):>12} "
                  f"{spread([r['starved_s'] for r in held], '.3f'):>13}", flush=True)
            table[(control, baud)] = {"line": statistics.median(r["throughput"] for r in free),
                                      "held": statistics.median(r["throughput"] for r in held),
                                      "overflow": sum(r["overflow"] for r in free + held)}
    print("overflow: summed over every XOFF of every run; max past DC3: the most over the runs; starved s: time "
          "the machine found the buffer empty while the program had not all arrived")
    return table


if __name__ == "__main__":
    main()
