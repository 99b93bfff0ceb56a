"""A third round of hostile input: each case here failed before its fix (an internal error, an option ignored,
air cut above the block, a refusal that came only after minutes, a traceback at the end of a command)."""

from __future__ import annotations

import json
import time
from fractions import Fraction

import pytest

from lagsym import LagsymError
from lagsym.cad.patch import BSplinePatch
from lagsym.conditioning import lebesgue_maximum
from lagsym.export.patchjson import parse_patch_json, write_patch_json
from lagsym.machine import RasterSpec
from lagsym.polytext import fraction_text

from conftest import EXAMPLES, ROOT


def test_a_patch_with_rationals_past_pythons_4300_digits_is_written_and_read_back_exactly(tmp_path):
    """``export -o x.json`` of a 70x70 grid of three-decimal nodes ended in an internal error: str() of a
    Fraction stops at 4,300 digits."""
    huge = Fraction(3 ** 20000 + 1, 7 ** 6000)
    patch = BSplinePatch("Lagrange", 1, 1, (Fraction(0), Fraction(0), Fraction(1), Fraction(1)),
                         (Fraction(0), Fraction(0), Fraction(1), Fraction(1)),
                         (((Fraction(0), Fraction(0), huge), (Fraction(0), Fraction(1), Fraction(1))),
                          ((Fraction(1), Fraction(0), -huge), (Fraction(1), Fraction(1), Fraction(2)))))
    path = tmp_path / "p.json"
    with path.open("w") as f:
        write_patch_json(f, patch)
    assert parse_patch_json(path.read_text()) == patch
    with pytest.raises(LagsymError, match="not a valid"):
        parse_patch_json(path.read_text().replace(fraction_text(huge)[:50], "12x4", 1))


def _job(tmp_path, finish: str = "stepover = 0.5\nstep = 0.2\n", rough_leave: str = "0.3"):
    text = (EXAMPLES / "example-4-job.toml").read_text()
    text = text[:text.rindex("stepover = 0.5")] + finish
    text = text.replace("stock_to_leave = 0.3", f"stock_to_leave = {rough_leave}")
    (tmp_path / "paper-example-4.json").write_text((EXAMPLES / "paper-example-4.json").read_text())
    (tmp_path / "job.toml").write_text(text)
    return tmp_path / "job.toml"


@pytest.mark.parametrize("finish, words", [
    ("stepover = 0.5\nscallop = 0.01\nstep = 0.2\n", "give a side step (stepover 0.5 mm) or a scallop height "
                                                       "(scallop 0.01 mm), not both"),
    ("scallop = 0.000001\nstep = 0.2\n", "operations[1].scallop = 1e-06 is out of range: give a number above 1e-06"),
])
@pytest.mark.slow
def test_a_job_refuses_a_scallop_it_would_have_ignored_or_the_command_line_refuses(tmp_path, run_cli, finish, words):
    """Both a side step and a scallop height: the scallop was ignored in silence; 1e-6 passed in a job file while
    --scallop refuses it."""
    status, _, err = run_cli("job", _job(tmp_path, finish), "-o", tmp_path / "j.ngc")
    assert status == 2 and err.count("\n") == 1 and words in err, err
    assert not (tmp_path / "j.ngc").exists()
    with pytest.raises(LagsymError, match="not both"):
        RasterSpec("x", 0.5, 0.2, 0.01)


def test_roughing_with_more_stock_to_leave_than_the_block_holds_is_refused_not_cut_in_air(tmp_path, run_cli):
    """``stock_to_leave = 100`` roughed at Z108 to Z171, above the block's top (73.56) and the safe height."""
    job = _job(tmp_path, rough_leave="100")
    status, _, err = run_cli("job", job, "-o", tmp_path / "j.ngc")
    assert status == 2 and err.count("\n") == 1, err
    assert "operations[0] (rough): nothing to rough: the lowest the tool goes, 108.677 mm with the stock to leave " \
           "(100 mm), is at or above the stock top 73.561 mm" in err


def test_a_grid_too_large_to_make_is_refused_before_its_conditioning_is_measured(tmp_path, run_cli):
    """A 1500x3 grid: the Lebesgue constants of 1500 nodes took 13-26 s and 2.2 GB and overflowed to 'inf times'
    before the size limit refused the surface."""
    path = tmp_path / "g.json"
    path.write_text(json.dumps({"points": [[f"{i / 10:.1f}", j, (i * j) % 10] for i in range(1500) for j in range(3)]}))
    for command in (["export", path, "-o", tmp_path / "e.step"],
                    ["toolpath", path, "--safe-z", "80", "--feed", "500", "-o", tmp_path / "t.nc"]):
        started = time.monotonic()
        status, _, err = run_cli(*command)
        assert status == 2 and err.count("\n") == 1, err
        assert "1500 x 3 nodes would take an estimated" in err and "(--max-exact-mb" in err, err
        assert time.monotonic() - started < 30


def test_a_lebesgue_constant_beyond_a_float_is_said_so():
    value, _ = lebesgue_maximum(list(range(39)) + [10 ** 10])  # about 1e333 between the last two nodes
    assert value == float("inf")
    from lagsym.conditioning import Amplification

    text = Amplification(value, value, 1.25, (0.0, 1.5)).text()
    assert "inf" not in text and "more than 1.798e+308 times" in text, text


def test_ctrl_c_as_the_command_ends_gives_one_line_and_no_traceback(monkeypatch, capsys):
    """A Ctrl-C that arrived while the background compile was being started printed a 40-line traceback."""
    import lagsym.cli as cli
    import lagsym.toolpath.warmup as warmup

    def interrupted():
        raise KeyboardInterrupt

    monkeypatch.setattr(warmup, "start_in_background", interrupted)
    monkeypatch.setattr(cli, "main", lambda: 0)
    with pytest.raises(SystemExit) as ended:
        cli.run_console()
    assert ended.value.code == 130
    assert capsys.readouterr().err == "lagsym: interrupted\n"


@pytest.mark.slow
def test_a_long_program_of_expressions_is_compiled_in_pieces_and_its_alarm_names_its_line():
    """11 MB of long expressions took 3.6 GB in Python's compiler (about 35 KB a block, all at once); the code
    is now compiled a few thousand lines at a time, and an alarm far down still names its own line."""
    import subprocess
    import sys

    code = ("from lagsym.simulate import simulate, ControlAlarm\n"
            "e = '#100=[[[[#100+1.]*[#101+2.]]/[[#102+3.]+4.]]-[[[#103+1.]*2.]+[#104*3.]]+[#105+#106+#107+#108+#109]]'\n"
            "lines = ['%', 'O1000'] + [e] * 20000 + ['#102=[#100/0]', 'M30', '%']\n"
            "try:\n    simulate('\\n'.join(lines) + '\\n', 'fanuc', 8, max_lines=None)\nexcept ControlAlarm as e:\n    print(e)\n"
            # VmHWM, this process's own peak: ru_maxrss keeps the forking parent's across exec
            "print([l.split()[1] for l in open('/proc/self/status') if l.startswith('VmHWM')][0])\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    alarm, peak_kb = done.stdout.splitlines()
    assert "division by zero at line 20003: '#102=[#100/0]'" in alarm, done.stdout + done.stderr
    assert int(peak_kb) < 400_000  # all at once took 690 MB for this program


def test_a_program_of_more_bracketed_expressions_than_lines_allowed_is_refused_before_it_is_read(tmp_path, run_cli):
    """99,990 lines of a 109-character expression (11 MB, within --max-lines) took 123 s and 3.6 GB."""
    from lagsym.simulate.runaway import EXPRESSIONS_PER_LINE

    e = "#100=[[[[#100+1.]*[#101+2.]]/[[#102+3.]+4.]]-[[[#103+1.]*2.]+[#104*3.]]+[#105+#106+#107]]"
    program = tmp_path / "p.nc"
    program.write_text("%\nO1000\n" + (e + "\n") * 100 + "M30\n%\n")
    brackets = program.read_text().count("[")
    status, _, err = run_cli("simulate", program, "--max-lines", brackets // EXPRESSIONS_PER_LINE - 1)
    assert status == 2 and err.count("\n") == 1, err
    assert f"p.nc: {brackets:,} bracketed expressions, more than the limit of {brackets - 1:,}" in err, err
    status, _, err = run_cli("simulate", program, "--max-lines", brackets // EXPRESSIONS_PER_LINE)
    assert status == 0, err
    formats = " ".join((ROOT / "docs" / "formats.md").read_text().split())
    assert "at most 100000 lines (`--max-lines`) and as many bracketed expressions" in formats
    assert EXPRESSIONS_PER_LINE == 1  # "as many" in the docs


def test_the_time_limit_counts_a_commands_exact_work_together(monkeypatch):
    """``check`` of a 100x100 grid took 15.5 s with the limit at 15 s: each of its two exact computations was within
    the limit on its own.  Within ``exact_time_limit`` the clock counts from the block's start."""
    import lagsym.exactsize as es

    now = [100.0]
    monkeypatch.setattr(es.time, "perf_counter", lambda: now[0])
    with es.exact_time_limit(15.0):
        now[0] += 10.0  # ten seconds of exact work already done in this command
        clock = es.ExactClock("surface through 3 x 3 nodes")
        now[0] += 1.0
        with pytest.raises(LagsymError, match="would take about 17 s here"):
            clock.foresee(1, 7, 1.0, 0)  # one row of seven in one second: six more to come
    clock = es.ExactClock("surface through 3 x 3 nodes")  # outside: a computation's own 15 s
    now[0] += 1.0
    clock.foresee(1, 7, 1.0, 0)
