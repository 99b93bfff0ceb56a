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
