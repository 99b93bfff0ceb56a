"""Speed of ``lagsym verify`` on the README's finishing program, against the sampled press it replaced.

    python3 benchmarks/bench_verify.py                      # makes the program first if it is missing (~1.5 min)
    python3 benchmarks/bench_verify.py --program O1000.nc --runs 5 --peer-runs 2

The program is the README's: Example 4 at scale 20, 6 mm ball, ``--stepover
0.4 --step 0.2``, Fanuc.  Three things are timed, in turn, ``--runs`` times
(the peer ``--peer-runs`` times): the whole ``lagsym verify`` command in a
fresh process (start-up, reading the program, simulation, comparison), and
in this process the feed moves pressed into the default 401 x 401 map by
lagsym's exact swept segments and by the peer: the press lagsym used before,
kept here, which samples every move at half a cell sideways and 0.01 mm in
height and presses the tool's lower surface into every cell under each
sample.  Prints min and median of each, the ratio, and how the two maps
differ: the sampled one is never below the exact one (both are heights the
tool really reached), and it overstates the cut by at most its resolution
(the corner's sag over half a sample step plus half a height step).
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import results as recorded

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from lagsym.gcode import parse_moves  # noqa: E402
from lagsym.machine import cutter_profile  # noqa: E402
from lagsym.verify import height_map_axes  # noqa: E402
from lagsym.verify.heightmap import sweep  # noqa: E402

EX4 = ROOT / "examples" / "paper-example-4.json"
TOOLPATH = ["toolpath", str(EX4), "--scale", "20", "--tool-diameter", "6", "--stepover", "0.4", "--step", "0.2",
            "--feed", "600", "--safe-z", "80", "--dialect", "fanuc"]


def sampled_press(cut, a, b, xs, ys, r, corner, dz=0.01):
    """The peer: every move sampled at half a cell sideways and ``dz`` in height, the tool pressed at each sample."""
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    ds = 0.5 * min(hx, hy)
    for s in range(0, len(a), 20_000):
        pa, pb = a[s:s + 20_000], b[s:s + 20_000]
        d = pb - pa
        n = np.maximum(np.ceil(np.maximum(np.hypot(d[:, 0], d[:, 1]) / ds, np.abs(d[:, 2]) / dz)), 1).astype(np.int64)
        seg = np.repeat(np.arange(len(pa)), n)
        t = (np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
        pts = np.vstack([pa[seg] + t[:, None] * d[seg], pb[-1:]])
        _press(cut, pts, xs, ys, r, corner)


def _press(cut, pts, xs, ys, r, corner):
    """Lower ``cut`` to the tool's lower surface at every sampled position, grouped by nearest cell."""
    nx, ny = cut.shape
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    ix = np.rint((pts[:, 0] - xs[0]) / hx).astype(np.int64)
    iy = np.rint((pts[:, 1] - ys[0]) / hy).astype(np.int64)
    key = ix * (ny + 4 * int(r / hy) + 8) + iy
    order = np.argsort(key, kind="stable")
    key, px, py, pz, ix, iy = key[order], pts[order, 0], pts[order, 1], pts[order, 2], ix[order], iy[order]
    starts = np.flatnonzero(np.concatenate([[True], key[1:] != key[:-1]]))
    gx, gy = ix[starts], iy[starts]
    kx, ky = int(math.ceil(r / hx)) + 1, int(math.ceil(r / hy)) + 1
    for di in range(-kx, kx + 1):
        tx = gx + di
        okx = (tx >= 0) & (tx < nx)
        if not okx.any():
            continue
        dx2 = (xs[np.clip(ix + di, 0, nx - 1)] - px) ** 2
        for dj in range(-ky, ky + 1):
            ty = gy + dj
            ok = okx & (ty >= 0) & (ty < ny)
            if not ok.any():
                continue
            d2 = dx2 + (ys[np.clip(iy + dj, 0, ny - 1)] - py) ** 2
            inside = d2 <= r * r
            h = np.where(inside, pz + cutter_profile(np.where(inside, d2, 0.0), r, corner), np.inf)
            m = np.minimum.reduceat(h, starts)
            sel = ok & np.isfinite(m)
            if sel.any():
                cut[tx[sel], ty[sel]] = np.minimum(cut[tx[sel], ty[sel]], m[sel])


def command_time(program: Path) -> tuple[float, float]:
    """Wall and CPU time (user + system) of ``lagsym verify`` on the program in a fresh process."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run([sys.executable, "-m", "lagsym", "verify", str(EX4), str(program), "--scale", "20",
                    "--tool-diameter", "6"], env=env, check=False, capture_output=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def timed(fn) -> tuple[float, float]:
    """Wall and CPU time of ``fn()`` in this process."""
    t, c = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - t, time.process_time() - c


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--program", type=Path, default=Path("/tmp/lagsym-bench-O1000.nc"))
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--peer-runs", type=int, default=2)
    recorded.add_option(p)
    args = p.parse_args(argv)
    if not args.program.exists():
        print(f"making {args.program} (the README's toolpath command) ...", flush=True)
        subprocess.run([sys.executable, "-m", "lagsym", *TOOLPATH, "-o", str(args.program)], check=True,
                       env=dict(os.environ, PYTHONPATH=str(ROOT)))
    moves = parse_moves(args.program.read_text())
    known = np.asarray(moves.z_known)
    use = known & np.concatenate([[False], known[:-1]]) & ~np.asarray(moves.rapid)
    a, b = moves.path_mm[:-1][use], moves.path_mm[1:][use]
    xs, ys = height_map_axes((20.0, 100.0, 20.0, 100.0), None, None)
    times = {"verify command": [], "exact segments, 2 threads": [], "exact segments, 1 thread": [],
             "sampled press (peer)": []}
    maps = {}
    print(f"{len(a)} feed moves, {len(xs)} x {len(ys)} cells; load average {os.getloadavg()[0]:.1f}", flush=True)
    for k in range(max(args.runs, args.peer_runs)):
        if k < args.runs:
            times["verify command"].append(command_time(args.program))
            for name, workers in (("exact segments, 2 threads", 2), ("exact segments, 1 thread", 1)):
                cut = np.full((len(xs), len(ys)), np.inf)
                times[name].append(timed(lambda: sweep(cut, a, b, xs, ys, r=3.0, corner=3.0, workers=workers)))
                maps["exact"] = cut
        if k < args.peer_runs:
            cut = np.full((len(xs), len(ys)), np.inf)
            times["sampled press (peer)"].append(timed(lambda: sampled_press(cut, a, b, xs, ys, 3.0, 3.0)))
            maps["sampled"] = cut
    ref = [statistics.median(v) for v in zip(*times["exact segments, 1 thread"])]
    print(f"{'':28s} {'wall min':>9s} {'median':>7s} {'CPU min':>8s} {'median':>7s}  ratio to exact, 1 thread "
          "(wall, CPU medians)")
    for name, ts in times.items():
        if ts:
            wall, cpu = zip(*ts)
            print(f"{name:28s} {min(wall):8.2f}s {statistics.median(wall):6.2f}s {min(cpu):7.2f}s "
                  f"{statistics.median(cpu):6.2f}s  {statistics.median(wall) / ref[0]:.1f}x, "
                  f"{statistics.median(cpu) / ref[1]:.1f}x  ({len(ts)} runs)")
    if "sampled" in maps:
        ex, sa = maps["exact"], maps["sampled"]
        both = np.isfinite(ex) & np.isfinite(sa)
        diff = sa[both] - ex[both]
        ds = 0.5 * float(xs[1] - xs[0])
        sag = 3.0 - math.sqrt(9.0 - (ds / 2) ** 2)
        print(f"sampled minus exact: {diff.min():.2e} to {diff.max():.2e} mm (its stated resolution "
              f"{sag + 0.005:.4f} mm); cells reached by the exact sweep only: {int((np.isfinite(ex) & ~both).sum())}, "
              f"by the sampled press only: {int((np.isfinite(sa) & ~both).sum())}")
    print(f"load average at the end {os.getloadavg()[0]:.1f}")
    if times["sampled press (peer)"]:
        cpu_peer = statistics.median(t[1] for t in times["sampled press (peer)"])
        recorded.record("verify", task=f"simulating the README's finishing program ({len(a):,} feed moves) on "
                        f"{len(xs)}x{len(ys)} cells, exact swept ball", peer="the sampled press it replaced",
                        ratio=cpu_peer / ref[1], detail=f"CPU medians: {ref[1]:.2f} s against {cpu_peer:.2f} s; the "
                        f"whole command {statistics.median(t[0] for t in times['verify command']):.2f} s wall",
                        argv=argv, path=args.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
