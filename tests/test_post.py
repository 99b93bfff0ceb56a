"""Point-list programs: every dialect's output is read by LinuxCNC's real interpreter and moves as planned."""

from __future__ import annotations

import re
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lagsym.errors import InputError, ProgramError, ToolpathError
from lagsym.grid import grid_from_table
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import MachineSettings, RasterSpec, Tool
from lagsym.post.program import PointProgram, format_moves, iso_comment, point_program, write_program, writer
from lagsym.toolpath import plan_toolpath

from conftest import EXAMPLES
from gcheck import check_feeds, interpret

POINT_DIALECTS = ("fanuc", "linuxcnc", "grbl")
NUMBER_WORD = re.compile(r"([XYZF])(-?[0-9.]+)")


@pytest.fixture(scope="module")
def path4():
    surf = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
    return plan_toolpath(surf, Tool("ball", 6.0), RasterSpec("x", 4.0, 2.0), MachineSettings(mm_per_unit=20.0))


def program_text(tp, **kw):
    s = MachineSettings(**{"safe_z_mm": 80.0, "mm_per_unit": 20.0, **kw})
    return write_program(point_program(tp, s, title="Paper example 4")), s


@pytest.mark.parametrize("dialect", POINT_DIALECTS)
@pytest.mark.parametrize("units", ["mm", "inch"])
@pytest.mark.parametrize("line_ending", ["lf", "crlf"])
def test_interpreter_feeds_are_the_planned_cutter_locations(rs274, path4, dialect, units, line_ending):
    text, s = program_text(path4, dialect=dialect, units=units, line_ending=line_ending)
    feeds, travs = interpret(rs274, text)
    check_feeds(feeds, path4.points_mm, s)
    # Up to safe Z at the start and at the end only: the zig-zag keeps the tool down between rows.
    assert np.count_nonzero(np.isclose(travs[:, 2], 80.0, atol=0.01)) == 2
    assert text.count("\r\n") == (text.count("\n") if line_ending == "crlf" else 0)


@pytest.mark.parametrize("dialect", POINT_DIALECTS)
def test_every_number_has_a_point_and_no_exponent(path4, dialect):
    text, s = program_text(path4, dialect=dialect, origin_mm=(0.0, 0.0, -60.0))  # values around 0.000x
    assert text.isascii()
    for word, value in NUMBER_WORD.findall(text):
        assert "." in value, f"{word}{value}"
        if word != "F":
            assert len(value.split(".")[1]) == s.digits
    assert not re.search(r"\d[eE][-+]?\d", text)


def test_small_values_are_fixed_point():
    lines = format_moves(np.array([[0.0008, -0.0001, 12.0]]), MachineSettings(decimals=4))
    assert lines == ["G01 X0.0008 Y-0.0001 Z12.0000"]
    assert format_moves(np.array([[0.0, 0.0, -0.00049]]), MachineSettings())[0].endswith("Z0.000")  # never "-0.000"


def test_fanuc_framing_and_program_number(path4):
    text, _ = program_text(path4, dialect="fanuc", program_number=42)
    lines = text.splitlines()
    assert lines[0] == "%" and lines[-1] == "%"
    assert lines[1].startswith("O0042 (PAPER EXAMPLE 4)")
    assert "M30" in lines[-2]


def test_linuxcnc_has_no_percent_or_o_word(path4):
    text, _ = program_text(path4, dialect="linuxcnc")
    assert "%" not in text and not re.search(r"^O\d", text, re.M)
    assert text.rstrip().endswith("M02")


def test_grbl_blocks_are_short_and_need_no_tool_change(path4):
    text, _ = program_text(path4, dialect="grbl")
    assert "M06" not in text and "G43" not in text
    assert max(len(line) for line in text.splitlines()) <= 80


def test_comments_are_iso():
    assert iso_comment("Überfläche (x) ;y") == "BERFL CHE X Y"


def test_safe_z_must_clear_the_path(path4):
    with pytest.raises(ProgramError, match="safe Z"):
        program_text(path4, safe_z_mm=10.0)


def test_unknown_dialect_names_the_choices():
    with pytest.raises(InputError, match="fanuc"):
        MachineSettings(dialect="sinumerik")
    with pytest.raises(ProgramError, match="point-list writer"):
        writer("heidenhain")


def test_the_program_model_is_read_only():
    p = PointProgram(np.zeros((2, 3)), MachineSettings())
    with pytest.raises(ValueError):
        p.points_mm[0, 0] = 1.0


@st.composite
def small_surfaces(draw):
    n, m = draw(st.integers(2, 4)), draw(st.integers(2, 3))
    zs = draw(st.lists(st.lists(st.integers(-5, 5), min_size=m, max_size=m), min_size=n, max_size=n))
    xs = [Fraction(i) for i in range(n)]
    ys = [Fraction(i) for i in range(m)]
    return lagrange_surface(grid_from_table(xs, ys, zs))


@settings(max_examples=12)
@given(small_surfaces(), st.sampled_from(POINT_DIALECTS), st.sampled_from(["mm", "inch"]),
       st.floats(0.0, 12.0), st.sampled_from(["ball", "flat"]), st.floats(-50.0, 50.0), st.integers(1, 9999))
def test_every_emitted_program_passes_rs274(rs274, surf, dialect, units, diameter, shape, oz, number):
    s = MachineSettings(dialect=dialect, units=units, mm_per_unit=10.0, origin_mm=(1.5, -2.25, oz), safe_z_mm=200.0,
                        program_number=number)
    tp = plan_toolpath(surf, Tool(shape, diameter), RasterSpec("y", 4.0, None, None, 0.05), s)
    text = write_program(point_program(tp, s, title="hypothesis"))
    feeds, _ = interpret(rs274, text)
    check_feeds(feeds, tp.points_mm, s)


def test_the_interpreter_check_catches_a_bad_program(rs274):
    """The check is only worth something if rs274 refuses what a control would: a stray word, a missing end."""
    with pytest.raises(AssertionError, match="refused"):
        interpret(rs274, "G21 G90\nG1 X1. F100.\nG1 X2. Q5.\nM2\n")
    with pytest.raises(AssertionError, match="no percent sign or program end"):
        interpret(rs274, "G21 G90\nG1 X1. F100.\n")


def test_the_dialect_modules_do_not_import_the_writer_table():
    """lagsym.post.program imports the dialects for WRITERS; nothing below it imports it back."""
    import grimp

    graph = grimp.build_graph("lagsym")
    for module in ("fanuc", "linuxcnc", "grbl", "model", "moves"):
        assert not graph.find_shortest_chain(importer=f"lagsym.post.{module}", imported="lagsym.post.program")
