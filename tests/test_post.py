"""Point-list programs: every dialect's output is read by LinuxCNC's real interpreter and moves as planned."""

from __future__ import annotations

import re
import tempfile
from pathlib import Path
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lagsym.errors import InputError, ProgramError
from lagsym.grid import grid_from_table
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import MachineSettings, Placement, RasterSpec, Tool
from lagsym.controls import names
from lagsym.post.program import PointProgram, format_moves, iso_comment, point_program, write_program
from lagsym.toolpath import plan_toolpath

from conftest import EXAMPLES
from gcheck import check_feeds, interpret, resolution_mm

POINT_DIALECTS = names(point_lists=True)
NUMBER_WORD = re.compile(r"([XYZF])(-?[0-9.]+)")


@pytest.fixture(scope="module")
def path4():
    surf = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
    return plan_toolpath(surf, Tool("ball", 6.0), RasterSpec("x", 4.0, 2.0), Placement(20.0))


def program_text(tp, **kw):
    s = MachineSettings(**{"safe_z_mm": 80.0, "mm_per_unit": 20.0, **kw})
    return write_program(point_program(tp, s, title="Paper example 4")), s


@pytest.mark.slow
@pytest.mark.parametrize("dialect", POINT_DIALECTS)
@pytest.mark.parametrize("units", ["mm", "inch"])
@pytest.mark.parametrize("line_ending", ["lf", "crlf"])
def test_interpreter_feeds_are_the_planned_cutter_locations(rs274, path4, dialect, units, line_ending):
    text, s = program_text(path4, dialect=dialect, units=units, line_ending=line_ending)
    feeds, travs = interpret(rs274, text)
    check_feeds(feeds, path4.points_mm, s)
    # Straight up to the clearance plane first, over the first point, rapid down to the feed height (2 mm)
    # above it, up again at the end only: the zig-zag keeps the tool down between rows.
    first = path4.points_mm[0]
    np.testing.assert_allclose(travs[0], [0.0, 0.0, 80.0], atol=resolution_mm(s))
    np.testing.assert_allclose(travs[1], [first[0], first[1], 80.0], atol=resolution_mm(s))
    np.testing.assert_allclose(travs[2], first + [0.0, 0.0, 2.0], atol=2 * resolution_mm(s))
    assert len(travs) == 4 and np.isclose(travs[3, 2], 80.0, atol=1e-3)
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
    assert iso_comment("Überfläche (x) ;y") == "UBERFLACHE X Y"  # the accents dropped, the letters kept


def test_safe_z_must_clear_the_path(path4):
    with pytest.raises(ProgramError, match="safe Z"):
        program_text(path4, safe_z_mm=10.0)


def test_unknown_dialect_names_the_choices():
    with pytest.raises(InputError, match="fanuc"):
        MachineSettings(dialect="sinumerik")
    with pytest.raises(ProgramError, match="heidenhain.*no point-list writer; use one of fanuc, haas, linuxcnc, grbl"):
        write_program(PointProgram(np.zeros((2, 3)), MachineSettings(dialect="heidenhain")))


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


@pytest.mark.slow
@settings(max_examples=12)
@given(small_surfaces(), st.sampled_from(POINT_DIALECTS), st.sampled_from(["mm", "inch"]),
       st.floats(0.0, 12.0), st.sampled_from(["ball", "flat"]), st.floats(-50.0, 50.0), st.integers(1, 9999))
def test_every_emitted_program_passes_rs274(rs274, surf, dialect, units, diameter, shape, oz, number):
    s = MachineSettings(dialect=dialect, units=units, mm_per_unit=10.0, origin_mm=(1.5, -2.25, oz), safe_z_mm=200.0,
                        program_number=number)
    tp = plan_toolpath(surf, Tool(shape, diameter), RasterSpec("y", 4.0, None, None, 0.05), s.placement, s.program, stock_to_leave_mm=s.stock_to_leave_mm)
    text = write_program(point_program(tp, s, title="hypothesis"))
    feeds, _ = interpret(rs274, text)
    check_feeds(feeds, tp.points_mm, s)


def test_the_interpreter_check_catches_a_bad_program(rs274):
    """The check is only worth something if rs274 refuses what a control would: a stray word, a missing end."""
    with pytest.raises(AssertionError, match="refused"):
        interpret(rs274, "G21 G90\nG1 X1. F100.\nG1 X2. Q5.\nM2\n")
    with pytest.raises(AssertionError, match="no percent sign or program end"):
        interpret(rs274, "G21 G90\nG1 X1. F100.\n")


@pytest.mark.parametrize("dialect", POINT_DIALECTS)
def test_program_start_and_end_as_a_machinist_expects(rs274, path4, dialect):
    """rs274's canonical calls: clearance Z before any XY move, coolant on after it and off after the retract,
    the plunge feed only over the feed height, the work offset and length offset asked for."""
    options = dict(coolant="flood", work_offset="G55", feed_height_mm=3.0)
    if dialect != "grbl":
        options.update(tool_number=3, length_offset=7)
    text, s = program_text(path4, dialect=dialect, **options)
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "p.ngc"
        path.write_text(text)
        r = rs274.run(path, tool_table="T1 P1 Z0 D6\nT3 P3 Z0 D6\nT7 P7 Z0.5 D6\n")
    assert r.returncode == 0, r.stderr[-400:]
    canon = [ln.split("N..... ", 1)[1] for ln in r.stdout.splitlines() if "N..... " in ln]
    moves = [c for c in canon if c.startswith(("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"))]
    xyz = np.array([[float(v) for v in c[c.index("(") + 1:].split(",")[:3]] for c in moves])
    assert moves[0].startswith("STRAIGHT_TRAVERSE") and xyz[0].tolist() == [0.0, 0.0, 80.0]
    plunge = xyz[3] - xyz[2]
    assert moves[3].startswith("STRAIGHT_FEED") and plunge[:2].tolist() == [0.0, 0.0]
    assert -plunge[2] == pytest.approx(3.0, abs=2e-3)  # 3 mm at plunge feed, not the 60 from safe Z
    assert canon.index("FLOOD_ON()") < canon.index(moves[1]) and canon.index("FLOOD_OFF()") > canon.index(moves[-1])
    assert "SET_G5X_OFFSET(2," in r.stdout
    if dialect != "grbl":
        assert "USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 12.7000" in r.stdout and "SELECT_TOOL(3)" in r.stdout


@pytest.mark.parametrize("options, error, match", [
    (dict(safe_z_mm=None), ProgramError, r"less than the feed height 2 mm above the highest cutter location"),
    (dict(work_offset="G54 (X)"), InputError, "work offset"),
    (dict(tool_number=-1), InputError, "tool number -1"),
    (dict(line_ending="cr"), InputError, "one block"),
    (dict(dialect="fanuc", work_offset="G59.2"), ProgramError, "not one a fanuc control has"),
    (dict(dialect="grbl", length_offset=2), ProgramError, "no tool length offset"),
    (dict(origin_mm=(0.0, 0.0, 149900.0), safe_z_mm=150000.0), ProgramError, r"beyond the 99999.999"),
])
def test_what_a_control_would_refuse_is_refused_with_the_limit(path4, options, error, match):
    if options.get("safe_z_mm", 1) is None:  # 57 um above the highest cutter location
        options["safe_z_mm"] = float(path4.points_mm[:, 2].max()) + 0.057
    with pytest.raises(error, match=match):
        program_text(path4, **options)


def test_the_header_says_the_surface_units():
    p = PointProgram(np.array([[0.0, 0.0, 1.0], [2.0, 0.0, 1.0]]),
                     MachineSettings(mm_per_unit=25.4, surface_units="inch", units="inch"))
    assert "(SURFACE IN INCH 25.4 MM PER UNIT PROGRAM IN INCH)" in write_program(p)


@pytest.mark.slow
def test_cli_inch_surface_is_programmed_at_25_4_mm_a_unit(rs274, run_cli, tmp_path):
    import json

    data = json.loads((EXAMPLES / "paper-example-4.json").read_text())
    data["units"] = "inch"
    f = tmp_path / "inch.json"
    f.write_text(json.dumps(data))
    args = ("--stepover", 5, "--step", 5, "--safe-z", 120, "--dialect", "linuxcnc", "--boundary", "centre")
    status, text, err = run_cli("toolpath", f, *args)
    assert status == 0, err
    same = run_cli("toolpath", EXAMPLES / "paper-example-4.json", "--scale", 25.4, *args)[1]
    assert text.replace("INCH 25.4", "MM 25.4").replace("INCH.JSON", "PAPER-EXAMPLE-4.JSON") == same
    feeds, _ = interpret(rs274, text)
    x0, x1, y0, y1 = (float(v) for v in read_points(EXAMPLES / "paper-example-4.json").bounds)
    assert feeds[:, 0].min() == pytest.approx(x0 * 25.4, abs=1e-3) and feeds[:, 0].max() == pytest.approx(x1 * 25.4, abs=1e-3)


@pytest.mark.slow
@pytest.mark.parametrize("units", ["mm", "inch"])
def test_every_written_z_is_at_or_above_the_cutter_location_at_the_written_x_y(rs274, units):
    """On a 67-76 degree flank, the cutter height at the X, Y rs274 goes to is never above the Z it is given.

    Checked against a brute-force drop-cutter on the polynomial itself.  Before
    X and Y were placed on the program's resolution ahead of the drop-cutter,
    the tool went up to 1.4 um (mm) below the cutter path at the rounded X, Y.
    """
    from cutters import brute_ball, steep_flank

    surf, f = steep_flank()
    s = MachineSettings(units=units, safe_z_mm=60.0)
    tol = 0.002 if units == "mm" else 0.003  # at least the 0.00254 mm an inch program writes positions in
    tp = plan_toolpath(surf, Tool("ball", 2.0), RasterSpec("y", 0.35, None, None, tol), s.placement, s.program,
                       stock_to_leave_mm=s.stock_to_leave_mm)
    feeds, _ = interpret(rs274, write_program(point_program(tp, s)))
    unit = 10.0 ** -s.digits / s.unit_factor
    assert np.abs(feeds[:, :2] / unit - np.rint(feeds[:, :2] / unit)).max() < 1e-6  # on the grid: nothing to round
    below = brute_ball(f, (0.0, 6.0, 0.0, 6.0), feeds[:, 0], feeds[:, 1], 1.0) - feeds[:, 2]
    assert below.max() <= 1e-7, f"{below.max() * 1000:.2f} um below at {feeds[np.argmax(below)]}"
