"""Handing a part of a large evaluation to another thread: a parked helper (lagsym) against a thread started for it.

lagsym's large grids and point sets are shared among threads
(:mod:`lagsym.evaluate.threads`); the other threads are helpers kept from one
call to the next, each parked on a lock of its own.  The peer is what it did
before: a ``threading.Thread`` started for the call, whose ``start()``
returns only once the new thread runs.  Printed, for ``--runs`` hand-overs
of each (alternating, with a 2000 x 2000 ``np.full`` between them, as a
sample's writes come between calls): how long the calling thread is held
(``start()``, or posting the part to the helper) and how long after the
hand-over began the other thread runs the part; min, median and 90th
percentile in microseconds, and the ratio of the peer's to lagsym's.

Run:  python3 benchmarks/bench_threads.py [--runs 301]
"""

from __future__ import annotations

import argparse
import sys
import threading
import time
from pathlib import Path

import numpy as np

import results as recorded

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from lagsym.evaluate import threads  # noqa: E402


def _thread_start() -> tuple[float, float]:
    """(held, runs after) for a thread started for the part."""
    ran = [0.0]
    t = time.perf_counter()
    th = threading.Thread(target=lambda: ran.__setitem__(0, time.perf_counter()), daemon=True)
    th.start()
    held = time.perf_counter() - t
    th.join()
    return held, ran[0] - t


def _helper(helper) -> tuple[float, float]:
    """(held, runs after) for the part posted to a parked helper."""
    ran = [0.0]
    t = time.perf_counter()
    helper.post(lambda: ran.__setitem__(0, time.perf_counter()))
    held = time.perf_counter() - t
    helper.wait()
    return held, ran[0] - t


def _row(name: str, v: np.ndarray) -> str:
    return f"| {name} | {v.min() * 1e6:.0f} | {np.median(v) * 1e6:.0f} | {np.percentile(v, 90) * 1e6:.0f} |"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=301)
    recorded.add_option(p)
    a = p.parse_args(argv)
    pool = threads.HelperPool()
    pool.run_parts(lambda lo, hi: None, [(0, 1), (1, 2)])  # the helper started, as after a first large call
    helper = pool._helpers[0]
    peer, ours = [], []
    for _ in range(a.runs):
        peer.append(_thread_start())
        np.full((2000, 2000), 1.0)
        ours.append(_helper(helper))
        np.full((2000, 2000), 1.0)
    peer, ours = np.array(peer), np.array(ours)
    print(f"{a.runs} hand-overs each, alternating\n")
    print("| hand-over | min (us) | median (us) | 90th percentile (us) |")
    print("|---|---:|---:|---:|")
    print(_row("`threading.Thread(...).start()` holds the caller (peer)", peer[:, 0]))
    print(_row("posting to a parked helper holds the caller (lagsym)", ours[:, 0]))
    print(_row("the started thread runs the part after (peer)", peer[:, 1]))
    print(_row("the helper runs the part after (lagsym)", ours[:, 1]))
    print(f"\nthe caller held: the peer {np.median(peer[:, 0]) / np.median(ours[:, 0]):.1f}x as long (median); "
          f"the part started: the peer {np.median(peer[:, 1]) / np.median(ours[:, 1]):.1f}x as late (median)")
    pool.close()
    held_peer, held_ours = np.median(peer[:, 0]), np.median(ours[:, 0])
    recorded.record("threads", task="handing a part of a large evaluation to another thread (the caller held)",
                    peer="`threading.Thread(...).start()`", ratio=held_peer / held_ours,
                    detail=f"medians of {a.runs}: {held_ours * 1e6:.1f} against {held_peer * 1e6:.1f} us",
                    argv=argv, path=a.results)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
