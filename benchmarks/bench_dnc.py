"""Drip-feed throughput and overflow: lagsym's sender against the simulated control's line rate.

Over a socat pty pair, a simulated control (tests/simcontrol.py) takes
characters no faster than its baud allows.  Two figures per run:

* throughput: the time a perfect sender would take over the time the
  control spent receiving, when the control empties its buffer at once (so
  the line rate is the only limit) and when it empties it slower than the
  line (so XOFF/XON cycles govern, and a perfect sender fills the buffer at
  the line rate and then keeps up with the drain);
* overflow: characters that arrived after the control's DC3 beyond its
  tolerance (10, as a Fanuc), summed over every XOFF, and the most
  characters after any one DC3.

The peer in the same run is the line itself: the ratio, not the seconds,
is the figure (the machine is shared and noisy).  The kernel rig is a pty
pair with no relay in between, as a real UART; on the socat rig a loaded
machine can hold a DC3 in the relay for tens of milliseconds, which shows
as characters past DC3 that no real line would carry.

Run:  python3 benchmarks/bench_dnc.py [--baud 9600 19200] [--blocks 400] [--drain 0.6]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from lagsym.dnc import parse_program, profile, send_program, transfer_segments  # noqa: E402
from simcontrol import KernelPty, PtyPair, SimControl, chars_per_s, program_text  # noqa: E402

HIGH = 192  # the control's high-water mark, characters


def run(baud: int, blocks: int, drain: float | None, rig: str) -> dict:
    prog = parse_program(program_text(blocks))
    settings = profile("fanuc", baud=baud)
    cps = chars_per_s(baud)
    with (KernelPty() if rig == "kernel" else PtyPair()) as pair:
        sim = SimControl(pair.far, pair=pair if rig == "socat" else None, baud=baud,
                         drain_cps=None if drain is None else drain * cps,
                         buffer_chars=256, high_water=HIGH, low_water=64, tolerance=10)
        sim.start()
        expected = b"".join(b for _, b in transfer_segments(prog, settings, "drip"))
        result = send_program(pair.near, prog, settings, "drip")
        sim.wait_for(len(expected))
        rec = sim.stop()
    n = len(expected)
    if drain is None:
        ideal_s = n / cps
    else:
        # A perfect sender fills the buffer to its high mark at the line rate (the buffer grows at
        # (1 - drain) of it), then the control takes characters as fast as the machine drains them.
        fill = min(n, HIGH / (1 - drain))
        ideal_s = fill / cps + (n - fill) / (drain * cps)
    span = rec["last_byte_at"] - rec["first_byte_at"]
    return {
        "baud": baud, "bytes": n, "drain": drain, "exact": rec["received"] == expected,
        "throughput": ideal_s / span if span > 0 else 0.0,
        "sender_throughput": result.throughput / (1 if drain is None else drain),
        "xoffs": rec["xoffs"], "overflow": rec["overflow"], "max_after_xoff": rec["max_after_xoff"],
        "in_flight_at_xoff": result.max_in_flight_at_xoff,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baud", type=int, nargs="+", default=[9600, 19200])
    ap.add_argument("--blocks", type=int, default=400, help="program length in blocks (about 27 characters each)")
    ap.add_argument("--drain", type=float, default=0.6, help="control's drain rate over the line rate, for XOFF cycles")
    ap.add_argument("--rig", choices=("kernel", "socat"), nargs="+", default=["kernel", "socat"],
                    help="pty pair: kernel (no relay, as a real UART) and/or socat (a relay process in between)")
    args = ap.parse_args()
    print(f"{'rig':>6} {'baud':>6} {'control':>12} {'bytes':>6} {'exact':>5} {'of accepted':>11} {'XOFF':>5} "
          f"{'overflow':>8} {'max past DC3':>12} {'in flight at XOFF':>17}")
    for rig in args.rig:
        for baud in args.baud:
            for drain in (None, args.drain):
                r = run(baud, args.blocks, drain, rig)
                label = "line rate" if drain is None else f"drains {drain:.0%}"
                print(f"{rig:>6} {baud:>6} {label:>12} {r['bytes']:>6} {str(r['exact']):>5} {r['throughput']:>10.1%} "
                      f"{r['xoffs']:>5} {r['overflow']:>8} {r['max_after_xoff']:>12} {r['in_flight_at_xoff']:>17}",
                      flush=True)


if __name__ == "__main__":
    main()
