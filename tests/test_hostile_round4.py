"""A fourth round of hostile input: each case here failed before its fix (an internal error, memory past the
machine's, a wrong answer with exit 0, a traceback at start-up, a job with no bound on its work)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time
from fractions import Fraction

import numpy as np
import pytest

from lagsym import ConditioningError, FormulaError
from lagsym.evaluate import surface_evaluator
from lagsym.formula import parse_formula
from lagsym.grid import grid_from_table
from lagsym.lagrange import lagrange_surface
from lagsym.machine import Tool
from lagsym.simulate import simulate
from lagsym.simulate.alarms import ControlAlarm

from conftest import EXAMPLES, ROOT

LAGSYM = [sys.executable, "-m", "lagsym"]


def _huge_grid():
    """Nodes crowded near 0 and heights up to 4e300 (a file may hold them): a Chebyshev coefficient beyond any
    float."""
    n = 12
    return grid_from_table([Fraction(1, i + 2) for i in range(n)], [Fraction(1, i + 3) for i in range(n)],
                           [[(i * j % 5) * 10 ** 300 for j in range(n)] for i in range(n)], source="huge.json")


def test_a_surface_beyond_floating_point_is_refused_in_one_line_not_an_overflow(tmp_path, run_cli):
    """``check``, ``sample`` and ``export`` of a 100x100 grid on nodes 1/(i+2) ended in exit 70 (OverflowError:
    integer division result too large for a float)."""
    with pytest.raises(ConditioningError, match=r"huge.json: the surface through 12 x 12 nodes has a coefficient of "
                                                r"3\d\d digits in the Chebyshev basis of its box, beyond any float"):
        surface_evaluator(lagrange_surface(_huge_grid()))
    g = _huge_grid()
    path = tmp_path / "huge.json"
    path.write_text(json.dumps({"x": [str(v) for v in g.x], "y": [str(v) for v in g.y],
                                "z": [[f"{int(v) // 10 ** 300}e300" for v in row] for row in g.z]}))
    status, out, err = run_cli("sample", path, "-o", tmp_path / "s.csv", "--accept-rounding")
    assert status == 2 and err.count("\n") == 1 and "beyond any float" in err and str(path) in err, err
    assert not (tmp_path / "s.csv").exists()


def _peak_rss(argv) -> tuple[int, int, str]:
    """Exit status, peak resident memory (bytes) and standard error of a fresh process running ``argv``."""
    proc = subprocess.Popen(argv, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    return os.waitstatus_to_exitcode(status), usage.ru_maxrss * 1024, proc.stderr.read().decode()


@pytest.mark.slow
def test_verify_with_a_large_tool_over_small_cells_stays_within_memory(tmp_path):
    """Two moves of a 24 mm tool over Example 1 (cells of 0.01 mm) asked for arrays of 2.8 GiB and ended in
    exit 70; an 8 mm tool took 3.1 GB.  The footprint is now swept in bands."""
    program = tmp_path / "two.nc"
    program.write_text("G90 G21\nG01 X1. Y2. Z5. F100.\nX5. Y4.\nM30\n")
    status, peak, err = _peak_rss(LAGSYM + ["verify", str(EXAMPLES / "paper-example-1.json"), str(program),
                                            "--tool-diameter", "24"])
    assert status in (0, 1), err
    # The contract's 2 GB: a fresh install compiles its kernels in this process too (about 1 GB more than the
    # 0.3 GB the sweep takes with them compiled).
    assert peak < 2 << 30, f"{peak / 2 ** 30:.2f} GiB"


def test_a_footprint_swept_in_bands_cuts_what_it_cuts_at_once(monkeypatch):
    """The bands of a large footprint give the height map of the footprint taken whole."""
    from lagsym.verify import heightmap

    xs, ys = np.linspace(0, 10, 161), np.linspace(0, 8, 129)
    a = np.array([[1.0, 2.0, 1.0], [6.0, 3.5, 0.5], [2.0, 7.0, 2.5]])
    b = np.array([[6.0, 3.5, 0.5], [9.0, 6.0, 1.5], [2.5, 1.0, 0.0]])
    maps = []
    for cells in (1 << 30, 257, 1 << 20):  # the whole footprint at once, one row a band, the default
        monkeypatch.setattr(heightmap, "_FEW_CELLS", cells)
        for tool in (Tool("ball", 12.0), Tool("flat", 12.0)):
            cut = np.full((len(xs), len(ys)), 10.0)
            heightmap.press_moves(cut, xs, ys, a, b, tool)
            maps.append(cut)
    for whole, banded in zip(maps[:2], maps[2:4]):
        assert np.array_equal(whole, banded)
    for whole, banded in zip(maps[:2], maps[4:]):
        assert np.array_equal(whole, banded)
    assert maps[0].min() < 1.0 and maps[1].min() < 1.0  # the tools cut


@pytest.mark.parametrize("shell", ["> /dev/full", ">&-"])
def test_a_standard_output_that_cannot_be_written_is_one_line_and_exit_2(shell):
    """``lagsym equation P > /dev/full`` and a closed standard output ended in exit 70."""
    if shell == "> /dev/full" and not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full on this system")
    r = subprocess.run(" ".join(LAGSYM + ["equation", str(EXAMPLES / "paper-example-1.json")]) + " " + shell,
                       shell=True, cwd=ROOT, stderr=subprocess.PIPE, text=True)
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    assert ("no space left on the device" if "full" in shell else "standard output is closed") in r.stderr


def test_ctrl_c_while_the_command_loads_is_one_line():
    """A Ctrl-C in the first tens of milliseconds, while ``lagsym.cli`` was still being imported, printed a
    traceback through the imports; now the start-up's own handler says one line."""
    code = ("import sys; sys.argv[0] = '-m'; import lagsym, os, signal; os.kill(os.getpid(), signal.SIGINT); "
            "import time; time.sleep(30)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 130 and r.stderr == "lagsym: interrupted; nothing was written\n", r
    # Imported as a library, lagsym leaves Ctrl-C alone.
    code = "import lagsym, signal; print(signal.getsignal(signal.SIGINT) is signal.default_int_handler)"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout == "True\n"
    # The command puts Python's own handler back once its own are in place.
    code = ("import sys; sys.argv[0] = '-m'; import lagsym, signal; from lagsym.cli import main; "
            "main(['--version']); print(signal.getsignal(signal.SIGINT) is signal.default_int_handler)")
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout.endswith("True\n")


@pytest.mark.parametrize("value, words", [
    (float("nan"), "x = nan is not a finite number"), (float("inf"), "x = inf is not a finite number"),
    ("abc", "'abc' is not a number"), (None, "x = None is not a number"),
    ("1e999999999", "'1e999999999' is out of range"),
])
def test_a_formulas_exact_value_refuses_what_is_no_number_at_once(value, words):
    """A plain ValueError, OverflowError or TypeError, and a hang for 1e999999999."""
    t = time.perf_counter()
    with pytest.raises(FormulaError, match=words):
        parse_formula("x*y").exact_value(value, 1)
    assert time.perf_counter() - t < 5
    assert parse_formula("x*y").exact_value("1/3", 0.5) == Fraction(1, 6)


@pytest.mark.parametrize("block, alarm", [("G01 X--1. F100.", "114"), ("G01 X+-1. F100.", "114"),
                                          ("G01 X1. F0.", "11"), ("G01 X1.", "11")])
def test_a_block_a_fanuc_alarms_on_alarms_in_the_simulator(block, alarm):
    """``X--1.`` moved to X1 and ``X+-1.`` to X-1 with "no alarm"; a feed move at F0 or with no F ran."""
    with pytest.raises(ControlAlarm) as e:
        simulate(f"%\nO1000\nG90 G00 X0. Y0. Z5.\n{block}\nM30\n%\n", "fanuc", 8)
    assert (e.value.alarm, e.value.line) == (alarm, 4)
    sim = simulate("%\nO1000\nG90 G00 X0. Y0. Z5.\nG01 X-1. F100.\nX+1. Z-[-2.]\nM30\n%\n", "fanuc", 8)
    assert [(m.x, m.z, m.feed) for m in sim.moves[1:]] == [(-1.0, 5.0, 100.0), (1.0, 2.0, 100.0)]


def test_linuxcnc_refuses_a_feed_move_with_no_feed():
    with pytest.raises(ControlAlarm) as e:
        simulate("G21 G90\nG0 X0 Y0 Z5\nG1 X1\nM2\n", "linuxcnc", 15)
    assert e.value.alarm == "11" and e.value.line == 3


def test_a_job_of_thousands_of_operations_is_refused_at_once(tmp_path, run_cli):
    """2001 finishing operations, each within the point limit, ran past a minute with nothing refusing the sum."""
    from lagsym.job.spec import MAX_OPERATIONS

    text = (EXAMPLES / "example-4-job.toml").read_text().replace(
        'points = "paper-example-4.json"', f'points = "{(EXAMPLES / "paper-example-4.json").as_posix()}"')
    finish = text[text.rindex("[[operations]]"):]
    job = tmp_path / "many.toml"
    job.write_text(text + ("\n" + finish) * 2000)
    t = time.perf_counter()
    status, out, err = run_cli("job", job, "-o", tmp_path / "x.ngc")
    assert status == 2 and err.count("\n") == 1, err
    assert f"2,002 operations, more than the {MAX_OPERATIONS} a job plans" in err and str(job) in err
    assert time.perf_counter() - t < 10 and not (tmp_path / "x.ngc").exists()
    formats = " ".join((ROOT / "docs" / "formats.md").read_text().split())
    assert f"at most {MAX_OPERATIONS} operations" in formats


@pytest.mark.slow
def test_the_basis_of_a_thousand_nodes_is_foreseen_and_refused_within_the_time_limit(tmp_path):
    """A curve of 1,000 points with --max-exact-mb 3000 ran 55 s building its basis (no clock there) and past
    4 GB, until GMP aborted."""
    path = tmp_path / "c1000.json"
    path.write_text(json.dumps({"points": [[i / 10, (i * 7) % 13] for i in range(1000)]}))
    t = time.perf_counter()
    status, peak, err = _peak_rss(LAGSYM + ["curve", str(path), "--max-exact-mb", "3000"])
    assert status == 2 and err.count("\n") == 1, err
    assert f"{path}: the exact Lagrange basis on 1000 nodes would take about" in err
    assert "more than the limit of 15 s" in err
    assert time.perf_counter() - t < 30 and peak < 2 << 30, (time.perf_counter() - t, peak)
    assert math.isfinite(peak)


def test_a_nul_in_a_jobs_points_path_names_the_job_file(tmp_path, run_cli):
    """The message named the points path alone, not the job file and key it came from."""
    job = tmp_path / "nul.toml"
    job.write_text((EXAMPLES / "example-4-job.toml").read_text().replace(
        'points = "paper-example-4.json"', 'points = "paper-example-4\\u0000.json"'))
    status, out, err = run_cli("job", job, "-o", tmp_path / "x.ngc")
    assert status == 2 and err.count("\n") == 1, err
    assert f"{job}: points = 'paper-example-4\\x00.json': a file name cannot hold a NUL character" in err, err


def test_a_simulated_alarm_names_the_program_file(tmp_path, run_cli):
    program = tmp_path / "p.nc"
    program.write_text("%\nO1000\nG01 X--1. F100.\nM30\n%\n")
    status, out, err = run_cli("simulate", program)
    assert status == 2 and err == f"lagsym: error: {program}: alarm 114: X--1.: two signs in a row, which a control " \
                                  f"reads as no number at line 3: 'G01 X--1. F100.'\n"


@pytest.mark.parametrize("lines, odd, like", [(["1,2,3,", "4,5,6", "7,8,9"], 2, 3),
                                              (["1,2,3", "4,5,6,", "7,8,9"], 3, 2)])
def test_the_odd_line_of_a_table_is_the_one_named(tmp_path, run_cli, lines, odd, like):
    """A trailing comma on the first data line blamed the next line (its width was taken as the rule)."""
    path = tmp_path / "t.csv"
    path.write_text("x,y,z\n" + "\n".join(lines) + "\n")
    status, _, err = run_cli("fit", path)
    assert status == 2 and f"{path}: line {odd} has 4 columns, expected 3 like line {like}" in err, err


SMALL_JOB = f"""points = "{(EXAMPLES / 'paper-example-1.json').as_posix()}"
dialect = "fanuc"
safe_z = 60
title = "TITLE"

[stock]
top_above = 1

[tools.ball]
number = 1
shape = "ball"
diameter = 6

[[operations]]
kind = "finish"
tool = "ball"
stepover = 2
step = 1
"""


def test_an_accented_title_keeps_its_letters_and_one_with_none_is_refused(tmp_path, run_cli):
    """A title of accented letters only was dropped silently (the header read ``O1000 ()``)."""
    job = tmp_path / "t.toml"
    job.write_text(SMALL_JOB.replace("TITLE", "Pièce façonnée"))
    status, _, err = run_cli("job", job, "-o", tmp_path / "t.nc")
    assert status == 0, err
    assert "O1000 (PIECE FACONNEE)" in (tmp_path / "t.nc").read_text()
    job.write_text(SMALL_JOB.replace("TITLE", "日本"))
    status, _, err = run_cli("job", job, "-o", tmp_path / "u.nc")
    assert status == 2 and f"{job}: title = '日本' has no character a control prints" in err, err
    assert not (tmp_path / "u.nc").exists()


@pytest.mark.parametrize("text, words", [("1e-400", "too small: below 1e-300"), ("1e400", "overflow"),
                                         ("1e-9999999", "too small"), ("1e9999999", "overflow")])
def test_a_number_too_small_is_not_called_an_overflow(text, words):
    from lagsym.values import NotANumber, exact_number

    with pytest.raises(NotANumber, match=words):
        exact_number(text)


def test_a_snap_that_joins_nodes_says_so(tmp_path, run_cli):
    """``--snap 1e300`` said "duplicated grid point (2, 2) at points 1 and 2", with no word of the snap."""
    path = tmp_path / "g.csv"
    path.write_text("x,y,z\n1,1,1\n1,2,2\n2,1,3\n2,2,4\n")
    status, _, err = run_cli("equation", path, "--snap", "1e300")
    assert status == 2 and err.count("\n") == 1, err
    assert f"{path}: --snap 1e+300 takes points 1 (1, 1) and 2 (1, 2) to one place" in err, err
    assert "a tolerance wider than the nodes' spacing (give a smaller one)" in err
    status, out, err = run_cli("equation", path, "--snap", "0.5")
    assert status == 0 and "z = 2*x + y - 2" in out


def test_a_point_with_both_x_and_capital_x_is_named(tmp_path, run_cli):
    """``{"x": 1, "X": 2, ...}`` kept the later value and ended in "no point at (x, y) = ...", far from the cause."""
    path = tmp_path / "p.json"
    path.write_text(json.dumps([{"x": 1, "X": 2, "y": 1, "z": 0}, {"x": 2, "y": 1, "z": 0},
                                {"x": 1, "y": 2, "z": 0}, {"x": 2, "y": 2, "z": 0}]))
    status, _, err = run_cli("equation", path)
    assert status == 2 and "point 1 " in err and "should have keys x, y, z once each" in err, err
