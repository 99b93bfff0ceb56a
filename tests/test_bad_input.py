"""Bad input and faults: each answered in one line with exit 2, nothing run as code, no quiet wrong output.

Each case here failed before it was answered: generated code that ran what a file name said, NaN and
infinities that switched safety checks off, internal errors (exit 70) for bad input, work that ran away,
and quiet wrong output with exit 0.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
EX4 = ROOT / "examples" / "paper-example-4.json"
FLAT = {"points": [[0, 0, 1], [0, 1, 2], [1, 0, 3], [1, 1, 4]]}


def one_line_error(status, out, err, needle=""):
    assert status == 2, err
    assert err.count("\n") == 1 and err.startswith("lagsym: error:") and "Traceback" not in err, err
    assert needle in err, err


@pytest.fixture
def flat(tmp_path):
    p = tmp_path / "flat.json"
    p.write_text(json.dumps(FLAT))
    return p


# 1. Generated code never runs what a file name says.

def test_a_file_name_in_the_python_docstring_stays_text(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # where a shell command that got through would leave its file
    name = 'a"""+__import__("os").system("touch pwned2")+""".json'
    (tmp_path / name).write_text(json.dumps(FLAT))
    proc = subprocess.run([sys.executable, "-m", "lagsym", "equation", name, "--format", "python"], cwd=tmp_path,
                          capture_output=True, text=True, check=True, env={**os.environ, "PYTHONPATH": str(ROOT)})
    namespace = {}
    exec(compile(proc.stdout, "F.py", "exec"), namespace)  # the real interpreter is the independent check
    assert not (tmp_path / "pwned2").exists()
    assert namespace["F"](1, 1) == 4 and name in namespace["F"].__doc__


def test_the_work_offset_is_one_word_not_a_block(run_cli, flat):
    status, out, err = run_cli("macro", flat, "--work-offset", "G54\nM30")
    one_line_error(status, out, err, "--work-offset")
    status, out, _ = run_cli("macro", flat, "--work-offset", "g55")
    assert status == 0 and "\nG55\n" in out


# 4. NaN and infinities never switch a check off.

@pytest.mark.parametrize("argv", [
    ["verify", "{flat}", "{prog}", "--gouge-limit", "nan"],
    ["verify", "{flat}", "{prog}", "--cell", "inf"],
    ["macro", "{flat}", "--tolerance", "nan"],
    ["toolpath", "{flat}", "--tolerance", "nan"],
    ["toolpath", "{flat}", "--scallop=-inf"],
    ["compare", "{flat}", "--tolerance", "nan"],
    ["sample", "{flat}", "--step", "nan"],
    ["sample", "{flat}", "--x0", "inf"],
    ["toolpath", "{flat}", "--origin", "0,nan,0"],
])
def test_nan_and_infinity_options_are_refused(run_cli, flat, tmp_path, argv):
    prog = tmp_path / "p.nc"
    prog.write_text("%\nO1\nG0 X0 Y0 Z10\nG1 Z0 F100\nX1\nM30\n%\n")
    status, out, err = run_cli(*[a.format(flat=flat, prog=prog) for a in argv])
    one_line_error(status, out, err)
    assert "finite" in err or "not a number" in err or "out of range" in err


# 5. Bad input is exit 2 and one line, never an internal error.

def test_cr_only_line_endings_read_as_lines(run_cli, tmp_path):
    p = tmp_path / "cr.csv"
    p.write_bytes(b"x,y,z\r0,0,1\r0,1,2\r1,0,3\r1,1,4\r")
    status, out, _ = run_cli("equation", p)
    assert status == 0 and out == "z = 2*x + y + 1\n"


def test_an_over_long_csv_cell_is_refused(run_cli, tmp_path):
    p = tmp_path / "long.csv"
    p.write_text("x,y,z\n0,0," + "1" * 140_000 + "\n0,1,2\n1,0,3\n1,1,4\n")
    one_line_error(*run_cli("equation", p), "long.csv: line 2")


@pytest.mark.parametrize("text", ["1e999999999999999999999", "1" * 400])
def test_numbers_beyond_range_are_refused(run_cli, tmp_path, text):
    p = tmp_path / "big.csv"
    p.write_text(f"x,y,z\n0,0,{text}\n0,1,2\n1,0,3\n1,1,4\n")
    one_line_error(*run_cli("equation", p), "out of range")


def test_a_thousand_term_formula_is_refused(run_cli, flat):
    one_line_error(*run_cli("compare", flat, "--reference", "+".join(["x"] * 1000)), "operations in a chain")


@pytest.mark.parametrize("argv", [
    ["equation", "{flat}", "--digits", "999999999999999999"],
    ["toolpath", "{flat}", "--scale", "1e308"], ["toolpath", "{flat}", "--scale", "1e-308"],
    ["toolpath", "{flat}", "--step", "1e308"], ["toolpath", "{flat}", "--step", "1e-308"],
    ["toolpath", "{flat}", "--tool-diameter", "1e308"], ["toolpath", "{flat}", "--safe-z", "1e308"],
    ["toolpath", "{flat}", "--feed", "1e308"], ["toolpath", "{flat}", "--feed", "1e-308"],
    ["macro", "{flat}", "--scale", "1e308"], ["macro", "{flat}", "--step", "1e-308"],
    ["macro", "{flat}", "--safe-z", "1e308"], ["macro", "{flat}", "--feed", "1e-308"],
    ["verify", "{flat}", "{flat}", "--tool-diameter", "1e308"], ["verify", "{flat}", "{flat}", "--scale", "1e-308"],
    ["verify", "{flat}", "{flat}", "--cell", "1e-6"],
    ["simulate", "{flat}", "--max-blocks", "0"],
])
def test_out_of_range_options_say_the_range(run_cli, flat, argv):
    status, out, err = run_cli(*[a.format(flat=flat) for a in argv])
    one_line_error(status, out, err, "is out of range: give a")


def test_verify_of_a_move_far_away_is_estimated_not_allocated(run_cli, flat, tmp_path):
    prog = tmp_path / "far.nc"
    prog.write_text("%\nO1\nG0 X0 Y0 Z10\nG1 X1000000000 Y0 Z0 F100\nM30\n%\n")
    one_line_error(*run_cli("verify", flat, prog), "--max-contacts")


# 6. Work is estimated first and refused with the figure and the option that lifts it.

def test_toolpath_refuses_a_plan_beyond_max_points(run_cli):
    status, out, err = run_cli("toolpath", EX4, "--scale", "20", "--step", "0.0001", "--decimals", "5",
                               "--safe-z", "100")
    one_line_error(status, out, err, "--max-points")
    assert "201 rows" not in err and "drop-cutter points" in err


def test_sample_refuses_beyond_max_points(run_cli, flat):
    one_line_error(*run_cli("sample", flat, "--nx", "10000000", "--ny", "10000000"), "1e+14 points")
    status, out, _ = run_cli("sample", flat, "--nx", "3", "--max-points", "9")
    assert status == 0 and len(out.splitlines()) == 10
    one_line_error(*run_cli("sample", flat, "--nx", "4", "--max-points", "9"), "--max-points")


def test_verify_refuses_a_huge_tool_or_map(run_cli, flat, tmp_path):
    prog = tmp_path / "p.nc"
    prog.write_text("%\nO1\nG0 X0 Y0 Z10\nG1 Z0 F100\nX1\nM30\n%\n")
    one_line_error(*run_cli("verify", flat, prog, "--scale", "10", "--cell", "0.001"), "--max-cells")
    one_line_error(*run_cli("verify", flat, prog, "--tool-diameter", "1000"), "--max-contacts")


def test_equation_of_a_large_grid_is_estimated(run_cli, tmp_path):
    n = 60
    p = tmp_path / "g.json"
    p.write_text(json.dumps({"points": [[i, k, (i * 7 + k * 3) % 5] for i in range(n) for k in range(n)]}))
    one_line_error(*run_cli("equation", p), "--max-terms")
    status, out, err = run_cli("equation", p, "--digits", "3", "--max-terms", "10")
    assert status == 0 and out.startswith("z = ")


@pytest.mark.slow
def test_sample_refuses_heights_whose_rounding_exceeds_the_data(run_cli, tmp_path):
    n = 60
    p = tmp_path / "g.json"
    p.write_text(json.dumps({"points": [[i, k, (i * 7 + k * 3) % 7] for i in range(n) for k in range(n)]}))
    one_line_error(*run_cli("sample", p, "--nx", "5"), "--accept-rounding")
    one_line_error(*run_cli("sample", p, "--nx", "5", "--accept-rounding"), "--accept-conditioning")
    assert run_cli("sample", p, "--nx", "5", "--accept-rounding", "--accept-conditioning")[0] == 0


# 8. No quiet wrong output.

def test_feed_spindle_and_safe_z_that_no_word_can_say_are_refused(run_cli, flat):
    one_line_error(*run_cli("toolpath", flat, "--feed", "1e-308"), "mm/min")
    one_line_error(*run_cli("toolpath", flat, "--spindle", "1e308"), "rpm")
    one_line_error(*run_cli("toolpath", flat, "--spindle", "0.4"), "rpm")
    one_line_error(*run_cli("toolpath", flat, "--safe-z", "1e23"), "mm")


def test_reference_x_is_the_formula_even_beside_a_file_named_x(run_cli, flat, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    Path("x").write_text("{}")
    status, out, err = run_cli("compare", flat, "--reference", "x")
    assert status == 0 and "f(x, y) = x" in out


def test_rms_of_heights_near_1e300_is_finite(tmp_path):
    from lagsym.compare import deviation_measures

    m = deviation_measures([[1e300, 3e300]], [[0.0, 0.0]])
    assert m.rms_deviation == pytest.approx(math.sqrt((1 + 9) / 2) * 1e300, rel=1e-15)
    assert m.deviation_percentage == pytest.approx(200 * 1e300, rel=1e-15)


def test_stl_of_heights_beyond_float32_is_refused(run_cli, tmp_path):
    p = tmp_path / "h.json"
    p.write_text(json.dumps({"points": [[0, 0, 1e300], [0, 1, 2], [1, 0, 3], [1, 1, 4]]}))
    one_line_error(*run_cli("sample", p, "--nx", "3", "-o", tmp_path / "h.stl"), "32-bit")
    assert not (tmp_path / "h.stl").exists()


@pytest.mark.parametrize("digit", ["\u0667", "\uff17"])
def test_non_ascii_digits_are_no_number_anywhere(run_cli, tmp_path, flat, digit):
    p = tmp_path / "d.csv"
    p.write_text(f"x,y,z\n0,0,{digit}\n0,1,2\n1,0,3\n1,1,4\n")
    one_line_error(*run_cli("equation", p), "not a number")
    one_line_error(*run_cli("compare", flat, "--reference", f"x+{digit}"))
    one_line_error(*run_cli("toolpath", flat, "--feed", digit), "not a number")


def test_duplicate_json_keys_are_refused(run_cli, tmp_path):
    p = tmp_path / "dup.json"
    p.write_text('{"points": [[0,0,1],[0,1,2],[1,0,3],[1,1,4]], "points": [[0,0,1],[0,1,2],[1,0,3],[1,1,5]]}')
    one_line_error(*run_cli("equation", p), "'points' appears twice")


def test_verify_of_an_empty_program_is_refused(run_cli, flat, tmp_path):
    prog = tmp_path / "empty.nc"
    prog.write_text("%\nO1000\nM30\n%\n")
    one_line_error(*run_cli("verify", flat, prog), "no move")


def test_the_documented_limits_are_the_ones_in_force():
    from lagsym.equation import MAX_TERMS
    from lagsym.formula import MAX_DEPTH, MAX_HEIGHT, MAX_LENGTH
    from lagsym.io.table import MAX_CELL
    from lagsym.sampling import MAX_POINTS
    from lagsym.toolpath.plan import MAX_PLAN_POINTS
    from lagsym.values import MAX_EXPONENT
    from lagsym.verify import MAX_CELLS, MAX_CONTACTS

    cli = " ".join((ROOT / "docs" / "cli.md").read_text().split())
    formats = (ROOT / "docs" / "formats.md").read_text()
    assert (MAX_POINTS, MAX_PLAN_POINTS, MAX_CELLS, MAX_CONTACTS, MAX_TERMS) == (10**8, 5 * 10**6, 16 * 10**6,
                                                                                2 * 10**10, 2500)
    for text in ("`sample --max-points` (default 1e8 points)", "`toolpath --max-points` (5e6 fine",
                 "`verify --max-cells` (1.6e7 height-map cells)", "(2e10 segments swept", "(2500 terms)"):
        assert text in cli
    assert f"at most {MAX_EXPONENT} digits and a decimal exponent within +-{MAX_EXPONENT}" in formats
    assert f"at most {MAX_CELL} characters" in formats
    assert f"at most {MAX_LENGTH} characters, {MAX_DEPTH} levels of brackets, {MAX_HEIGHT} chained" in formats


def test_the_documented_runaway_and_line_limits_are_the_ones_in_force():
    from lagsym.cli.receive import MAX_WAIT_S
    from lagsym.simulate import BYTES_PER_MOVE, MAX_BLOCKS, MAX_IDLE_BLOCKS
    from lagsym.toolpath.rough import MAX_ROUGH_SAMPLES

    cli = " ".join((ROOT / "docs" / "cli.md").read_text().split())
    formats = " ".join((ROOT / "docs" / "formats.md").read_text().split())
    macros = " ".join((ROOT / "docs" / "macros.md").read_text().split())
    dnc = " ".join((ROOT / "docs" / "dnc.md").read_text().split())
    assert (MAX_BLOCKS, MAX_IDLE_BLOCKS, BYTES_PER_MOVE, MAX_ROUGH_SAMPLES, MAX_WAIT_S) == (
        5_000_000, 200_000, 37, 100_000, 86_400.0)
    assert 4 + 1 + 4 * 8 == BYTES_PER_MOVE  # array('i') line, array('b') rapid, four doubles
    for text in (f"`--max-idle-blocks` ({MAX_IDLE_BLOCKS} blocks without a move) or `--max-blocks` "
                 f"({MAX_BLOCKS:.0e} blocks, {BYTES_PER_MOVE} bytes a move at most)".replace("e+06", "e6"),
                 f"`--max-samples` ({MAX_ROUGH_SAMPLES:.0e} drop-cutter samples".replace("e+05", "e5"),
                 f"`--idle-timeout` are at most {MAX_WAIT_S:.0f} s"):
        assert text in cli, text
    assert f"`--max-idle-blocks` ({MAX_IDLE_BLOCKS}) blocks without a move or `--max-blocks` ({MAX_BLOCKS})" in formats
    assert f"`--max-idle-blocks` blocks in a row without a move (default {MAX_IDLE_BLOCKS};" in macros
    assert (f"`--max-blocks` blocks in all (default {MAX_BLOCKS}, {MAX_BLOCKS / 2_525_622:.1f} times the 2.53 "
            f"million") in macros  # 2525622: test_simulate.test_the_readme_ball_macro_runs_under_the_default_limit
    assert (f"{BYTES_PER_MOVE} bytes a move, so a run takes at most {BYTES_PER_MOVE} bytes times `--max-blocks` for "
            f"them ({BYTES_PER_MOVE * MAX_BLOCKS / 1e6:.0f} MB at the default)") in macros
    assert f"(default 60, at most {MAX_WAIT_S:.0f})" in dnc and f"(default 5, at most {MAX_WAIT_S:.0f})" in dnc


# 5 and 6. The serial line's options: one line naming the option and the value, exit 2, before any port opens.

PROG = "%\nO0010\nG21 G90\nG0 X1. Y2.\nG1 Z-1. F100.\nM30\n%\n"


@pytest.fixture
def prog(tmp_path):
    p = tmp_path / "small.nc"
    p.write_text(PROG)
    return p


@pytest.mark.parametrize("argv, needle", [
    (["send", "{prog}", "--port", "loop://?x=1"], "--port: 'loop://?x=1': 'x' is not an option of loop://"),
    (["send", "{prog}", "--port", "loop://?logging=loud"], "logging=loud must be one of"),
    (["send", "{prog}", "--port", "socket://127.0.0.1:99999"],
     "'socket://127.0.0.1:99999': the port number must be 1 to 65535"),
    (["send", "{prog}", "--port", "socket://127.0.0.1:0"], "the port number must be 1 to 65535"),
    (["send", "{prog}", "--port", "rfc2217://host:4001?timeout=nan"], "timeout=nan must be"),
    (["send", "{prog}", "--port", "socket://127.0.0.1"], "give the host and port number"),
    (["send", "{prog}", "--port", "ftp://127.0.0.1:21"], "ftp:// is not a serial URL"),
    (["send", "{prog}", "--port", "loop://", "--leader", "\u00b2*NUL"], "--leader '\u00b2*NUL'"),
    (["send", "{prog}", "--port", "loop://", "--trailer", "\u0667"], "--trailer '\u0667'"),
    (["receive", "--port", "loop://", "--timeout", "inf"], "--timeout: 'inf' is not a finite number"),
    (["receive", "--port", "loop://", "--timeout", "nan"], "--timeout: 'nan' is not a finite number"),
    (["receive", "--port", "loop://", "--timeout", "-1"], "--timeout: '-1' is out of range: give a number above 0"),
    (["receive", "--port", "loop://", "--timeout", "0"], "--timeout: '0' is out of range"),
    (["receive", "--port", "loop://", "--timeout", "86401"], "up to 86400 s"),
    (["receive", "--port", "loop://", "--idle-timeout", "inf"], "--idle-timeout: 'inf' is not a finite number"),
    (["send", "{prog}", "--port", "loop://", "--log", "/dev/full"], "--log /dev/full: cannot write the log file"),
    (["receive", "--port", "loop://", "--log", "/dev/full"], "--log /dev/full: cannot write the log file"),
])
def test_line_options_are_checked_before_the_port_opens(run_cli, prog, argv, needle):
    import time

    start = time.monotonic()
    status, out, err = run_cli(*[a.format(prog=prog) for a in argv])
    one_line_error(status, out, err, needle)
    assert time.monotonic() - start < 120  # refused, not waited on (receive --timeout inf waited for ever)
    assert not out


def test_a_good_url_still_sends(run_cli, prog, tmp_path):
    log = tmp_path / "send.log"
    status, out, err = run_cli("send", prog, "--port", "loop://?logging=error", "--baud", "115200", "--log", log)
    assert status == 0 and out.startswith("sent 5 blocks"), err
    assert [line.split(" ", 1)[1] for line in log.read_text().splitlines()][:2] == [
        "log opened", "sending 47 bytes, 5 blocks, at 10472.7 characters/s"]


def test_a_dnc_config_with_a_bad_device_url_names_the_key(run_cli, tmp_path):
    (tmp_path / "progs").mkdir()
    cfg = tmp_path / "dnc.toml"
    cfg.write_text('[[port]]\nname = "mill"\ndevice = "socket://127.0.0.1:70000"\nprograms = "progs"\n'
                   'received = "in"\n')
    one_line_error(*run_cli("dnc", "serve", cfg, "--check"), "port[0].device 'socket://127.0.0.1:70000'")


def test_a_log_lost_part_way_is_not_a_transfer_done(prog, tmp_path):
    # A file-size limit of 60 bytes: the log's first line is written, the next ones fail (EFBIG), as on a
    # disk that fills during the transfer.
    log = tmp_path / "send.log"
    code = ("import resource, signal, sys\nsignal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
            "resource.setrlimit(resource.RLIMIT_FSIZE, (60, 60))\nfrom lagsym.cli import main\n"
            f"sys.exit(main(['send', {str(prog)!r}, '--port', 'loop://', '--baud', '115200', '--log', {str(log)!r}]))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert proc.returncode == 3, proc.stderr
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert f"sent 5 blocks to loop://, but the log {log} was lost (File too large after 1 lines)" in proc.stderr
    assert "not on record" in proc.stderr and "sent 5 blocks (" not in proc.stdout
    assert log.read_text().splitlines()[0].endswith(" log opened") and len(log.read_bytes()) == 60


# 5. An output under something that is not a folder (it used to be exit 70, NotADirectoryError).

@pytest.mark.parametrize("argv", [
    ["sample", "{flat}", "--nx", "3", "-o", "{flat}/out.csv"], ["toolpath", "{flat}", "-o", "{flat}/x.nc"],
    ["export", "{flat}", "-o", "{flat}/x.step"], ["equation", "{flat}", "-o", "{flat}/x.txt"],
    ["receive", "--port", "loop://", "--timeout", "600", "-o", "{flat}/x.nc"],
])
def test_an_output_under_a_file_is_one_line(run_cli, flat, argv):
    import time

    start = time.monotonic()
    one_line_error(*run_cli(*[a.format(flat=flat) for a in argv]), "flat.json is not a folder")
    assert time.monotonic() - start < 120  # receive says so before it waits (600 s) for the control


# 4 and 6 for rough and job: their numbers checked as toolpath's are, their work estimated first.

@pytest.mark.parametrize("option, value, needle", [
    ("--scale", "1e308", "is out of range"), ("--step", "1e-308", "is out of range"),
    ("--stepdown", "1e-308", "is out of range"), ("--stepover", "nan", "not a finite number"),
    ("--feed", "1e-308", "mm/min"), ("--spindle", "1e308", "rpm"), ("--safe-z", "1e23", "mm"),
    ("--margin", "1e308", "is out of range"), ("--tool-diameter", "1e9", "is out of range"),
    ("--block", "0,1e308,0,1", "--block X1 = '1e308' is out of range"),
    ("--block", "0,100000,0,100000", "--max-samples"), ("--max-samples", "10", "62 points, more than the limit of 10"),
    ("--tool-diameter", "1e-308", "--max-samples"),
])
def test_rough_options_are_checked_and_its_work_estimated(run_cli, flat, option, value, needle):
    one_line_error(*run_cli("rough", flat, "--stock-above", "1", option, value), needle)


@pytest.mark.parametrize("old, new, needle", [
    ("feed = 1200", "feed = 1e-308", "operations[0].feed = 1e-308 is out of range"),
    ("spindle = 8000", "spindle = 1e308", "operations[0].spindle"),
    ("safe_z = 90", "safe_z = 1e23", "safe_z = 1e+23 is out of range"),
    ("stepdown = 2", "stepdown = 1e-308", "operations[0].stepdown"),
    ("scale = 20", "scale = 1e308", "scale = 1e+308 is out of range"),
    ("top_above = 2", 'top_above = "x"', "stock.top_above = 'x' must be a number"),
])
def test_job_file_numbers_are_checked(run_cli, tmp_path, old, new, needle):
    text = (ROOT / "examples" / "example-4-job.toml").read_text()
    assert old in text
    job = tmp_path / "job.toml"
    job.write_text(text.replace(old, new).replace('points = "paper-example-4.json"', f'points = "{EX4}"'))
    one_line_error(*run_cli("job", job), needle)
