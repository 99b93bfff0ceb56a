"""Lengths and feeds on the command line are read in the program's units unless they name their own."""

from __future__ import annotations

import re

import pytest

from conftest import EXAMPLES

EX1 = EXAMPLES / "paper-example-1.json"
# A small plan: Example 1 at 1 mm a unit, a quarter-inch ball, two rows.
SMALL = [EX1, "--tool-diameter", "0.25in", "--stepover", "0.5in", "--step", "0.25in"]


def program(run_cli, tmp_path, name, *argv):
    out = tmp_path / name
    status, _, err = run_cli("toolpath", *SMALL, *argv, "-o", out)
    assert status == 0, err
    return out.read_text()


def words(text: str, letter: str) -> list[float]:
    return [float(v) for v in re.findall(rf"\b{letter}(-?[0-9.]+)", text)]


def test_an_inch_program_reads_safe_z_and_feeds_in_inches(run_cli, tmp_path):
    text = program(run_cli, tmp_path, "inch.nc", "--units", "inch", "--safe-z", "2", "--feed", "24",
                   "--plunge-feed", "10")
    assert "G20" in text
    assert set(words(text, "F")) == {10.0, 24.0}
    first_z = words(text, "Z")[0]  # the retract before the first move
    assert first_z == 2.0
    assert max(words(text, "Z")) == 2.0


def test_a_unit_given_with_the_number_wins(run_cli, tmp_path):
    plain = program(run_cli, tmp_path, "a.nc", "--units", "inch", "--safe-z", "2", "--feed", "24")
    named = program(run_cli, tmp_path, "b.nc", "--units", "inch", "--safe-z", "50.8mm", "--feed", "609.6mm/min")
    assert named == plain


@pytest.mark.slow
def test_a_millimetre_program_is_as_before(run_cli, tmp_path):
    plain = program(run_cli, tmp_path, "a.nc", "--safe-z", "80", "--feed", "600")
    named = program(run_cli, tmp_path, "b.nc", "--safe-z", "80mm", "--feed", "600mm/min")
    assert named == plain and "G21" in plain
    assert set(words(plain, "F")) == {200.0, 600.0}  # the default plunge feed, 200 mm/min
    assert max(words(plain, "Z")) == 80.0


@pytest.mark.parametrize("argv, message", [
    (["--feed", "24furlongs"], "argument --feed: '24furlongs' is not a number"),
    (["--units", "inch", "--safe-z", "5000"], "--safe-z = '5000' (127000 mm) is out of range"),
])
def test_a_bad_length_names_the_option_and_the_value(run_cli, tmp_path, argv, message):
    status, _, err = run_cli("toolpath", *SMALL, *argv, "-o", tmp_path / "x.nc")
    assert status == 2 and message in err, err
    assert len(err.strip().splitlines()) == 1 or "usage:" in err


# The same small plan as a job file: an inch job gives its lengths in inches and its feeds in inches a minute.
INCH_JOB = f"""points = "{EX1.as_posix()}"
dialect = "linuxcnc"
units = "inch"
safe_z = 2
rapid = 200

[stock]
top_above = 0.1

[tools.ball]
number = 1
shape = "ball"
diameter = 0.25

[[operations]]
kind = "finish"
tool = "ball"
feed = 24
plunge_feed = 10
stepover = 0.5
step = 0.25
"""
# The same job with every length and feed written in millimetres, with its unit.
NAMED = {"safe_z = 2": 'safe_z = "50.8 mm"', "rapid = 200": 'rapid = "5080 mm/min"',
         "top_above = 0.1": 'top_above = "2.54mm"', "diameter = 0.25": 'diameter = "6.35 mm"',
         "feed = 24": 'feed = "609.6 mm/min"', "plunge_feed = 10": 'plunge_feed = "254 mm/min"',
         "stepover = 0.5": 'stepover = "12.7 mm"', "step = 0.25": 'step = "6.35 mm"'}


def job_program(run_cli, tmp_path, name, text):
    job = tmp_path / f"{name}.toml"
    job.write_text(text)
    out = tmp_path / f"{name}.ngc"
    status, _, err = run_cli("job", job, "-o", out)
    assert status == 0, err
    return out.read_text()


def _replaced(text: str, changes: dict) -> str:
    for old, new in changes.items():
        assert f"\n{old}\n" in text, old
        text = text.replace(f"\n{old}\n", f"\n{new}\n", 1)
    return text


def test_an_inch_job_reads_its_lengths_in_inches_and_feeds_in_inches_a_minute(run_cli, tmp_path):
    text = job_program(run_cli, tmp_path, "inch", INCH_JOB)
    blocks = re.sub(r"\(.*?\)", "", text)  # the header states the stock in mm
    assert "G20" in blocks and "G21" not in blocks
    assert set(words(blocks, "F")) == {10.0, 24.0}
    z = words(blocks, "Z")
    assert z[0] == 2.0 and max(z) == 2.0  # the retract after the tool change, and nothing above it
    assert "Z2.0000" in text and "F24.00" in text  # as docs/roughing.md quotes them
    # Every length written out in mm with its unit gives the same program, byte for byte.
    assert job_program(run_cli, tmp_path, "named", _replaced(INCH_JOB, NAMED)) == text
    # And a millimetre job is read in millimetres, as before: the same values in mm, only the units differ.
    mm = job_program(run_cli, tmp_path, "mm", _replaced(INCH_JOB, {'units = "inch"': 'units = "mm"'} | {
        k: v.replace('"', "").replace(" mm/min", "").replace(" mm", "").replace("mm", "") for k, v in NAMED.items()}))
    mm = re.sub(r"\(.*?\)", "", mm)
    assert "G21" in mm and set(words(mm, "F")) == {254.0, 609.6} and max(words(mm, "Z")) == 50.8


@pytest.mark.parametrize("change, message", [
    ({"safe_z = 2": "safe_z = 5000"}, "safe_z = 5000 (127000 mm) is out of range: give a number from -100000 "
                                      "to 100000 mm"),
    ({"safe_z = 2": 'safe_z = "2 ft"'}, "safe_z = '2 ft' must be a number, in the job's units, or a number and "
                                        "its unit, such as '2 in' or '50 mm'"),
    ({"feed = 24": 'feed = "24 in"'}, "operations[0].feed = '24 in' must be a number, in the job's units, or a "
                                      "number and its unit, such as '24 in/min' or '600 mm/min'"),
    ({"diameter = 0.25": "diameter = -0.25"}, "tools.ball.diameter = -0.25 (-6.35 mm) must be a number above 0"),
    ({"safe_z = 2": "safe_z = 0.5"}, "safe_z = 0.5000 in (12.7 mm) is not above the stock top 1.5567 in (39.54 mm)"),
])
def test_a_bad_length_in_an_inch_job_is_named_as_the_file_gave_it(run_cli, tmp_path, change, message):
    job = tmp_path / "bad.toml"
    job.write_text(_replaced(INCH_JOB, change))
    status, out, err = run_cli("job", job, "-o", tmp_path / "x.ngc")
    assert status == 2 and not out and err.count("\n") == 1, err
    assert f"{job}: {message}" in err, err
    assert not (tmp_path / "x.ngc").exists()


def test_parse_job_reads_the_units_and_leaves_the_callers_data_alone():
    import tomllib
    from fractions import Fraction

    from lagsym.job.spec import parse_job

    data = tomllib.loads((EXAMPLES / "probe-job.toml").read_text()) | {"units": "inch"}
    data["probe"] = data["probe"] | {"tip_radius": 0.1, "feed": "100 mm/min", "box": [0, 4, 0, 2.5]}
    before = repr(data)
    spec = parse_job(data, "probe.toml")
    assert repr(data) == before
    s = spec.probe.settings
    assert (s.tip_radius_mm, s.top_mm, s.feed_mm_min) == (Fraction(254, 100), Fraction(254), Fraction(100))
    assert spec.safe_z_mm == 1016.0 and spec.stock["top_above"] == 25.4 and type(spec.stock["top_above"]) is float
    assert spec.probe.plan.xs[-1] <= Fraction(1016, 10)  # within the box of 4 in
    assert spec.operations[0].feed_mm_min == 1500 * 25.4 and spec.operations[0].options["stepover"] == 2 * 25.4
    # A caller that has converted its lengths says so, and they are read as millimetres.
    data["probe"]["feed"] = 100
    assert parse_job(data, "probe.toml", lengths_in_mm=True).safe_z_mm == 40.0
