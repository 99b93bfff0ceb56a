"""Progress reports: what the long-running functions tell a ``progress`` callable, and the bars of the commands.

Each planner, the cut simulation, the simulator and the job planner are run
on small inputs with a recording callable: in every stage the counts never
go back, the last call's count is the total, the known totals are what the
result itself says (fine samples, blocks executed, operations, moves), and
the result is the one the same call gives without a listener.  The commands
are run as a user runs them, with standard error on a pseudo-terminal (a bar
is drawn) and on a pipe (nothing but what the command always writes).
"""

from __future__ import annotations

import json
import os
import pty
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from lagsym.progress import MOST_CALLS, Tally, prefixed

ROOT = Path(__file__).resolve().parent.parent
POINTS = [[x, y, 10 - ((x - 10) ** 2 + (y - 10) ** 2) // 40] for x in (0, 10, 20) for y in (0, 10, 20)]
MACRO = "#100=0.\nWHILE [#100 LT 3000.] DO1\nG1 X[#100/100.] Y0. Z0. F100.\n#100=[#100+1.]\nEND1\nM30\n"


class Recorder(list):
    """A progress callable that keeps every call."""

    def __call__(self, done, total, stage):
        self.append((done, total, stage))

    def stages(self) -> dict:
        out = {}
        for done, total, stage in self:
            out.setdefault(stage, []).append((done, total))
        return out


def check_stages(rec: Recorder) -> dict:
    """Every stage counts up to its total and ends there, in few calls; ``{stage: total}``."""
    totals = {}
    assert rec, "no progress reported"
    for stage, calls in rec.stages().items():
        done = [d for d, _ in calls]
        assert done == sorted(done), (stage, done)
        known = {t for _, t in calls if t is not None}
        assert len(known) == 1, (stage, known)  # one total; an unknown one is given at the end
        assert calls[-1] == (known.pop(),) * 2, (stage, calls[-1])
        assert len(calls) <= MOST_CALLS + 2, (stage, len(calls))
        totals[stage] = calls[-1][1]
    return totals


@pytest.fixture(scope="module")
def surface():
    from lagsym.grid import grid_from_points
    from lagsym.lagrange import lagrange_surface

    return lagrange_surface(grid_from_points([tuple(p) for p in POINTS]))


@pytest.fixture(scope="module")
def points_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("progress") / "dome.json"
    path.write_text(json.dumps({"units": "mm", "points": POINTS}))
    return path


def test_a_tally_reports_a_known_total_in_few_calls_and_ends_at_it():
    rec = Recorder()
    with Tally(rec, "rows", 1_000_000) as t:
        for _ in range(1_000_000):
            t.add(1)
    assert check_stages(rec) == {"rows": 1_000_000}
    assert rec[0] == (0, 1_000_000, "rows")
    assert MOST_CALLS // 2 <= len(rec) <= MOST_CALLS + 2


def test_a_tally_counted_from_threads_stays_in_order():
    rec = Recorder()
    t = Tally(rec, "cells", 8 * 5000)
    threads = [threading.Thread(target=lambda: [t.add(1) for _ in range(5000)]) for _ in range(8)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    t.finish()
    assert check_stages(rec) == {"cells": 40_000}


def test_pieces_give_what_one_call_gives_and_count_each():
    rec = Recorder()
    x, y = np.linspace(0, 1, 10_001), np.linspace(2, 3, 10_001)
    t = Tally(rec, "drops", len(x))
    got = t.whole(lambda a, b: np.sin(a) * b, (x, y), piece=1000)
    assert np.array_equal(got, np.sin(x) * y)
    assert [d for d, _, _ in rec] == [0] + list(range(1000, 10_001, 1000)) + [10_001]
    assert Tally(None, "drops").whole(lambda a, b: a + b, (x, y), piece=10).tolist() == (x + y).tolist()


def test_nobody_listening_costs_nothing_and_prefixes_name_the_stage():
    f = lambda a: a  # noqa: E731
    assert Tally(None, "x").counting(f) is f
    rec = Recorder()
    prefixed(rec, "finish T2")(3, 4, "checking moves")
    assert rec == [(3, 4, "finish T2: checking moves")]
    assert prefixed(None, "x") is None


@pytest.mark.slow
def test_plan_toolpath_reports_the_fine_samples_then_the_checks(surface):
    from lagsym.machine import Placement, RasterSpec, Tool
    from lagsym.toolpath import plan_toolpath

    args = (surface, Tool("ball", 4.0), RasterSpec("x", 2.0, 1.0), Placement(1.0))
    rec = Recorder()
    tp = plan_toolpath(*args, progress=rec)
    totals = check_stages(rec)
    assert list(totals) == ["dropping the tool", "checking moves"]
    assert totals["dropping the tool"] == tp.fine_points
    assert totals["checking moves"] > 0
    quiet = plan_toolpath(*args)
    assert np.array_equal(tp.points_mm, quiet.points_mm) and np.array_equal(tp.rows, quiet.rows)


@pytest.mark.slow
def test_rough_toolpath_reports_the_samples_then_the_rows(surface):
    from lagsym.machine import MachineSettings, Tool
    from lagsym.toolpath.rough import RoughSpec, Stock, rough_toolpath

    args = (surface, Tool("flat", 6.0), Stock(0, 20, 0, 20, 12.0), RoughSpec(3, 2, 1, 0.3),
            MachineSettings(mm_per_unit=1.0, safe_z_mm=40))
    rec = Recorder()
    rp = rough_toolpath(*args, progress=rec)
    totals = check_stages(rec)
    assert list(totals) == ["dropping the tool", "checking rows"]
    assert totals["checking rows"] == len(np.unique(rp.points_mm[rp.kinds == 0, 1].round(9)))  # rows along x
    assert np.array_equal(rp.points_mm, rough_toolpath(*args).points_mm)


@pytest.mark.slow
def test_simulate_cut_reports_every_segment_swept(surface):
    from lagsym.gcode import parse_moves
    from lagsym.machine import MachineSettings, RasterSpec, Tool
    from lagsym.post.program import point_program, write_program
    from lagsym.toolpath import plan_toolpath
    from lagsym.verify import simulate_cut

    st = MachineSettings(mm_per_unit=1.0, safe_z_mm=40)
    tp = plan_toolpath(surface, Tool("ball", 4.0), RasterSpec("x", 2.0, 1.0), st.placement, st.program, stock_to_leave_mm=st.stock_to_leave_mm)
    moves = parse_moves(write_program(point_program(tp, st, title="dome")))
    rec = Recorder()
    report = simulate_cut(surface, moves, Tool("ball", 4.0), st.placement, progress=rec)
    totals = check_stages(rec)
    assert list(totals) == ["sweeping moves"]
    # the feed moves no longer than a segment, each one segment: as many as the moves, at least
    assert totals["sweeping moves"] >= int((~np.asarray(moves.rapid)).sum()) - 2
    assert report.segments >= totals["sweeping moves"] - 1
    quiet = simulate_cut(surface, moves, Tool("ball", 4.0), st.placement)
    assert np.array_equal(report.cut_mm, quiet.cut_mm)


def test_simulate_reports_the_blocks_executed():
    from lagsym.simulate import simulate

    rec = Recorder()
    sim = simulate(MACRO, "fanuc", 8, max_blocks=100_000, progress=rec)
    totals = check_stages(rec)
    assert totals == {"executing blocks": sim.blocks}
    assert sim.blocks == 1 + 3000 * 4 + 1 + 1 == simulate(MACRO, "fanuc", 8).blocks  # WHILE, G1, #100, END a turn
    assert 20 <= len(rec) <= 30  # a report every 500 blocks (the limit / 200): 24, the first and the last


def _job(tmp_path, points_file) -> Path:
    job = tmp_path / "dome.toml"
    job.write_text(f"""points = "{points_file.as_posix()}"
dialect = "linuxcnc"
safe_z = 40

[stock]
top_above = 2

[tools.rougher]
number = 1
shape = "flat"
diameter = 6

[tools.ball]
number = 2
shape = "ball"
diameter = 4

[[operations]]
kind = "rough"
tool = "rougher"
stepdown = 3
stepover = 3
step = 1

[[operations]]
kind = "finish"
tool = "ball"
stepover = 2
step = 1
""")
    return job


@pytest.mark.slow
def test_plan_job_reports_each_operation_and_its_stages(tmp_path, points_file):
    from lagsym.job import job_program, plan_job, read_job
    from lagsym.machined import machine_job

    spec = read_job(_job(tmp_path, points_file))
    rec = Recorder()
    planned = plan_job(spec, progress=rec)
    totals = check_stages(rec)
    assert list(totals) == ["operations", "rough T1: dropping the tool", "rough T1: checking rows",
                            "finish T2: dropping the tool", "finish T2: checking moves"]
    assert totals["operations"] == len(planned.operations) == 2
    assert totals["finish T2: dropping the tool"] == planned.operations[1].path.fine_points
    assert [op.label for op in planned.operations] == ["rough T1", "finish T2"]
    text = job_program(planned).text
    rec = Recorder()
    part = machine_job(spec, text, progress=rec)
    totals = check_stages(rec)
    assert list(totals) == ["T1: sweeping moves", "T2: sweeping moves"]
    assert all(totals[f"T{s.tool_number}: sweeping moves"] >= s.moves for s in part.stages)  # a segment a move at least
    quiet = machine_job(spec, text)
    assert np.array_equal(part.final_mm, quiet.final_mm)


# --------------------------------------------------------------------------- the commands


def _run(argv, *, tty: bool, cwd, term: str = "xterm-256color"):
    """``python -m lagsym ARGV`` with standard error on a pseudo-terminal or a pipe: (status, stdout, stderr)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), TERM=term, COLUMNS="100")
    env.pop("NO_COLOR", None)
    if not tty:
        done = subprocess.run([sys.executable, "-m", "lagsym", *map(str, argv)], cwd=cwd, env=env,
                              capture_output=True, timeout=300)
        return done.returncode, done.stdout, done.stderr
    master, slave = pty.openpty()
    p = subprocess.Popen([sys.executable, "-m", "lagsym", *map(str, argv)], cwd=cwd, env=env,
                         stdout=subprocess.PIPE, stderr=slave, stdin=subprocess.DEVNULL)
    os.close(slave)
    got = bytearray()
    reader = threading.Thread(target=lambda: got.extend(p.stdout.read()))
    reader.start()
    err = bytearray()
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:  # EIO: the child closed its end
            break
        if not chunk:
            break
        err.extend(chunk)
    os.close(master)
    reader.join()
    return p.wait(timeout=300), bytes(got), bytes(err)


TOOLPATH = ["toolpath", "dome.json", "--tool-diameter", "4", "--stepover", "2", "--step", "1", "--safe-z", "40"]


@pytest.fixture(scope="module")
def workdir(points_file):
    return points_file.parent


@pytest.mark.slow
def test_toolpath_on_a_terminal_draws_a_bar_on_stderr_and_leaves_stdout_alone(workdir):
    status, out, err = _run(TOOLPATH, tty=True, cwd=workdir)
    assert status == 0, err
    assert b"dropping the tool" in err and b"checking moves" in err and b"100%" in err
    assert b"\x1b[" in err  # drawn and erased with terminal controls
    status, piped_out, piped_err = _run(TOOLPATH, tty=False, cwd=workdir)
    assert status == 0
    assert out == piped_out and out.startswith(b"%")  # the program, byte for byte, as without a bar
    assert piped_err == b""  # piped: nothing at all, as before bars


@pytest.mark.slow
def test_toolpath_piped_or_on_a_dumb_terminal_writes_only_its_summary(workdir):
    argv = TOOLPATH + ["-o", "dome.nc"]
    status, _, err = _run(argv, tty=False, cwd=workdir)
    assert status == 0
    lines = err.decode().splitlines()
    assert len(lines) == 1 and lines[0].startswith("dome.nc: ") and " cutter locations (from " in lines[0], err
    status, _, dumb = _run(argv, tty=True, cwd=workdir, term="dumb")
    assert status == 0
    assert dumb.replace(b"\r\n", b"\n") == err  # the terminal's own line ending apart


@pytest.mark.slow
def test_simulate_on_a_terminal_counts_the_blocks(workdir):
    (workdir / "loop.nc").write_text("%\nO1234\n" + MACRO + "%\n")
    status, out, err = _run(["simulate", "loop.nc"], tty=True, cwd=workdir)
    assert status == 0, err
    assert b"executing blocks" in err and b"12003/12003" in err
    assert _run(["simulate", "loop.nc"], tty=False, cwd=workdir)[1] == out


@pytest.mark.slow
def test_a_command_writing_to_a_pipe_does_not_load_rich(points_file):
    code = ("import io, sys; from lagsym.cli import main; "
            f"main({TOOLPATH[:1] + [str(points_file)] + TOOLPATH[2:]!r}, io.StringIO(), io.StringIO()); "
            "print('rich' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.stdout.strip() == "False", done.stderr
