"""``lagsym simulate`` of the README's 4 mm ball macro at 8 digits, against the block-by-block interpreter, in one run.

The program is the README's: ``lagsym macro examples/paper-example-4.json
--scale 20 --tool-diameter 4 --stepover 0.5 --step 0.2 --safe-z 100
--dialect fanuc --program 1001`` (2,525,622 blocks executed, 64,566 moves).

The peer is the executor lagsym had before the compiler, kept here only:
it runs the same parsed blocks one at a time, each expression a tree of
closures over the control's methods (:func:`lagsym.simulate.expressions.closure`),
a handler per kind of block and the variable range checked at every read.
It is the natural yardstick -- the same arithmetic, the same alarms, the same
runaway guard, only interpreted -- and it checks that the compiled run gives
the same moves: its moves must be the compiled run's, value for value.
It takes about ten times as long, so it runs the first ``--peer-blocks``
blocks only (``--peer-blocks 0``: the whole program), and the ratio is of the
time per block executed.

Printed: min and median, wall and CPU (user + system) time, of ``--runs``
runs of each, alternating, in this process (``simulate()`` alone), then of
``--runs`` fresh processes of the whole command (start-up, the run and the
CSV written), and the load average when it started.  On a shared machine the
CPU time is the steadier figure: it is about the wall time of a quiet run.

Run:  python3 benchmarks/bench_simulate.py [--runs 5] [--peer-blocks 300000]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import results as recorded

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from lagsym.simulate import simulate  # noqa: E402
from lagsym.simulate.alarms import BlockAlarm, ControlAlarm  # noqa: E402
from lagsym.simulate.blocks import (Assign, AssignNamed, End, Goto, IfGoto, IfGotoLabel, IfThen, Label,  # noqa: E402
                                    Nop, OElse, OElseIf, OEndIf, OEndWhile, OIf, OWhile, Stop, While, Words)
from lagsym.simulate.control import ControlState  # noqa: E402
from lagsym.simulate.executor import _labels, _match_loops  # noqa: E402
from lagsym.simulate.reader import read_blocks  # noqa: E402
from lagsym.simulate.runaway import Runaway, endless_jumps  # noqa: E402

MACRO = ["macro", "examples/paper-example-4.json", "--scale", "20", "--tool-diameter", "4", "--stepover", "0.5",
         "--step", "0.2", "--safe-z", "100", "--dialect", "fanuc", "--program", "1001"]


# ---------------------------------------------------------------- the peer: the interpreter lagsym had before

def interpret(text: str, dialect: str = "fanuc", precision: int = 8, stop_after: int = 0):
    """The moves and the blocks executed, running each block's closures in turn (``stop_after`` > 0: that many)."""
    blocks = _match_loops(read_blocks(text, dialect))
    labels = _labels(blocks)
    m = ControlState(dialect, precision)
    handlers = [_RUN[type(b)] for b in blocks]
    runaway = Runaway(endless=endless_jumps(blocks, labels, dialect, precision), blocks=blocks)
    pc, executed = 0, 0
    while pc < len(blocks) and executed != stop_after:
        b = blocks[pc]
        executed += 1
        try:
            nxt = handlers[pc](m, blocks, pc, b, labels)
        except BlockAlarm as e:
            raise ControlAlarm(e.alarm, e.message, b.line, b.text) from None
        except ArithmeticError as e:
            raise ControlAlarm("111", f"calculated data out of range ({type(e).__name__})", b.line, b.text) from None
        if nxt is None:
            break
        if nxt <= pc:
            runaway.check(m, executed, nxt, b)
        pc = nxt
    return m.moves, executed


def _jump(labels, n):
    if n not in labels:
        raise BlockAlarm("128", f"sequence number or label {n} not found")
    return labels[n]


def _if(m, blocks, pc, b, labels):
    j, branch = pc, b
    while not branch.cond(m):
        j = branch.next
        branch = blocks[j]
        if not isinstance(branch, OElseIf):
            break
    return j + 1


def _words(m, blocks, pc, b, labels):
    values, gs, ms = {}, [], []
    for letter, f in b.words:
        v = f(m)
        if letter == "G":
            gs.append(v)
        elif letter == "M":
            ms.append(v)
        else:
            values[letter] = v
    for g in gs:
        if g in (0, 1, 2, 3):
            m.motion = f"G{int(g)}"
        elif g == 90:
            m.absolute = True
        elif g == 91:
            m.absolute = False
    if "F" in values:
        m.feed = values["F"]
    if m.motion in ("G2", "G3") and any(a in values for a in "XYZ"):
        raise BlockAlarm("arc", "arcs are outside what the simulator runs")
    m.move(b.line, values)
    return None if any(v in (2, 30, 99) for v in ms) else pc + 1


def _assign(m, blocks, pc, b, labels):
    m.set(b.target(m), b.value(m))
    return pc + 1


def _named(m, blocks, pc, b, labels):
    m.names[b.name] = m.ctx.plus(b.value(m))
    return pc + 1


_RUN = {
    Assign: _assign, AssignNamed: _named, Words: _words,
    While: lambda m, bl, pc, b, lb: b.end + 1 if b.cond is not None and not b.cond(m) else pc + 1,
    OWhile: lambda m, bl, pc, b, lb: b.end + 1 if not b.cond(m) else pc + 1,
    End: lambda m, bl, pc, b, lb: b.start, OEndWhile: lambda m, bl, pc, b, lb: b.start,
    IfThen: lambda m, bl, pc, b, lb: _assign(m, bl, pc, b.then, lb) if b.cond(m) else pc + 1,
    Goto: lambda m, bl, pc, b, lb: _jump(lb, m.index(b.number(m))),
    IfGoto: lambda m, bl, pc, b, lb: _jump(lb, m.index(b.number(m))) if b.cond(m) else pc + 1,
    IfGotoLabel: lambda m, bl, pc, b, lb: _jump(lb, b.label) if b.cond(m) else pc + 1,
    Label: lambda m, bl, pc, b, lb: pc + 1, Nop: lambda m, bl, pc, b, lb: pc + 1,
    OEndIf: lambda m, bl, pc, b, lb: pc + 1, Stop: lambda m, bl, pc, b, lb: None, OIf: _if,
    OElseIf: lambda m, bl, pc, b, lb: b.endif + 1, OElse: lambda m, bl, pc, b, lb: b.endif + 1,
}


# ---------------------------------------------------------------- the runs

def _cli(args: list[str]) -> tuple[float, float]:
    """Wall and CPU (user + system) seconds of ``python -m lagsym ARGS`` in a fresh process."""
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    before, t = resource.getrusage(resource.RUSAGE_CHILDREN), time.perf_counter()
    subprocess.run([sys.executable, "-m", "lagsym", *args], cwd=ROOT, env=env, check=True, capture_output=True)
    wall, after = time.perf_counter() - t, resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime


def _timed(f):
    """``f()``, its wall and its CPU seconds."""
    t, c = time.perf_counter(), time.process_time()
    out = f()
    return out, time.perf_counter() - t, time.process_time() - c


def _row(name: str, runs: list[tuple[float, float]], per: float = 1.0, unit: str = "s") -> str:
    wall, cpu = [w * per for w, _ in runs], [c * per for _, c in runs]
    return (f"| {name} | {min(wall):.3f} {unit} | {statistics.median(wall):.3f} {unit} | {min(cpu):.3f} {unit} | "
            f"{statistics.median(cpu):.3f} {unit} |")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--peer-blocks", type=int, default=300_000, help="blocks the peer runs (0: all)")
    recorded.add_option(p)
    a = p.parse_args(argv)
    load = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        program = Path(tmp) / "O1001.nc"
        _cli(MACRO + ["-o", str(program)])
        text = program.read_text()
        ours, peer = [], []
        for _ in range(a.runs):
            sim, *t = _timed(lambda: simulate(text, "fanuc", 8))
            ours.append(t)
            (moves, done), *t = _timed(lambda: interpret(text, stop_after=a.peer_blocks))
            peer.append(t)
        same = list(moves) == list(sim.moves)[:len(moves)] and (a.peer_blocks or done == sim.blocks)
        if not same or (a.peer_blocks == 0 and len(moves) != len(sim.moves)):
            raise SystemExit("the interpreter and the compiled run gave different moves")
        cli = [_cli(["simulate", str(program), "--precision", "8", "-o", str(Path(tmp) / "moves.csv")])
               for _ in range(a.runs)]
    per_ours, per_peer = 1e9 / sim.blocks, 1e9 / done
    print(f"## `lagsym simulate` of the README's 4 mm ball macro, 8 digits: {sim.blocks:,} blocks, "
          f"{len(sim.moves):,} moves; {a.runs} runs each, load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}\n")
    print(f"The peer ran {done:,} blocks ({len(moves):,} moves, the same as the compiled run's first ones).\n")
    print("| run | wall, min | wall, median | CPU, min | CPU, median |")
    print("|---|---:|---:|---:|---:|")
    print(_row("`simulate()`, compiled (the whole program)", ours))
    print(_row("`simulate()`, compiled, per block", ours, per_ours, "ns"))
    print(_row("the block-by-block interpreter, per block", peer, per_peer, "ns"))
    print(_row("`lagsym simulate ... -o moves.csv`, fresh process", cli))
    for k, kind in enumerate(("wall", "CPU")):
        ts, tp = [r[k] for r in ours], [r[k] for r in peer]
        ratio_min = min(tp) * per_peer / (min(ts) * per_ours)
        ratio_med = statistics.median(tp) * per_peer / (statistics.median(ts) * per_ours)
        print(f"\n{kind}: the interpreter takes {ratio_min:.1f}x (min) / {ratio_med:.1f}x (median) as long per block; "
              f"at its rate the whole program would take {statistics.median(tp) / done * sim.blocks:.1f} s.")
    cpu_ours, cpu_peer = statistics.median(r[1] for r in ours), statistics.median(r[1] for r in peer)
    recorded.record("simulate", task=f"simulating the README's 4 mm ball macro ({sim.blocks:,} blocks), per block",
                    peer="the block-by-block interpreter it replaced", ratio=cpu_peer * per_peer / (cpu_ours * per_ours),
                    detail=f"CPU medians of {a.runs} runs: {cpu_ours * per_ours:.0f} against {cpu_peer * per_peer:.0f} ns "
                    f"a block; the whole command {statistics.median(r[0] for r in cli):.2f} s", argv=argv, path=a.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
