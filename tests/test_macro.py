"""Macro programs: the raster they cut equals the one computed on the PC, through rs274 and the simulator."""

from __future__ import annotations

import dataclasses
import json
import random
import re
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import assume, given, settings as hsettings, strategies as st

from conftest import EXAMPLES
from lagsym.errors import InputError, ProgramError, ToolpathError
from lagsym.evaluate import evaluate_points
from lagsym.grid import grid_from_table
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import MachineSettings, RasterSpec, Tool
from lagsym.macro import (
    macro_loops,
    macro_program,
    macro_raster,
    planned_points,
    point_list_size,
    predicted_error,
    program_stats,
    raster_positions,
    row_form,
    transfer_seconds,
)
from lagsym.simulate import simulate
from test_simulate import feeds

FLAT = Tool("flat", 0.0)


def machine(**settings) -> MachineSettings:
    """Machine settings with a safe height above every test surface."""
    settings.setdefault("safe_z_mm", 1000.0)
    return MachineSettings(**settings)


def surface(name: str):
    return lagrange_surface(read_points(EXAMPLES / f"{name}.json"))


def rough_grid(n: int, seed: int = 0, span: int = 60, zmax: int = 50):
    """An n x n grid of random heights 0..zmax mm over a span x span mm box: the hard case for a control."""
    rng = random.Random(seed)
    nodes = [Fraction(span * i, n - 1) for i in range(n)]
    z = [[Fraction(rng.randint(0, 100 * zmax), 100) for _ in range(n)] for _ in range(n)]
    return lagrange_surface(grid_from_table(nodes, nodes, z, source=f"rough{n}x{n}"))


CASES = [
    ("paper-example-1", dict(mm_per_unit=5.0), RasterSpec("x", 1.5, 0.7)),
    ("paper-example-2", dict(mm_per_unit=2.0, origin_mm=(-10.0, 5.0, -3.0)), RasterSpec("y", 2.5, 1.1)),
    ("paper-example-3", dict(mm_per_unit=7.5), RasterSpec("x", 3.0, 1.3)),
    ("paper-example-4", dict(mm_per_unit=20.0, origin_mm=(1.5, -2.25, 10.0)), RasterSpec("y", 5.0, 2.0)),
]


# ---------------------------------------------------------------- the proof

@pytest.mark.parametrize("name, options, raster", CASES, ids=[c[0] for c in CASES])
def test_linuxcnc_macro_through_rs274_equals_the_pc_raster(rs274, tmp_path, name, options, raster):
    s = surface(name)
    settings = machine(dialect="linuxcnc", **options)
    program = macro_program(s, settings, raster, FLAT)
    path = tmp_path / "macro.ngc"
    path.write_text(program.text)
    result = rs274.run(path)
    assert result.returncode == 0, result.stdout[-500:] + result.stderr[-500:]
    got = feeds(result.stdout)
    want = planned_points(s, settings, raster, FLAT)
    assert got.shape == (len(want) + 1, 3)
    np.testing.assert_allclose(got[0], want[0], atol=1e-3)  # the plunge
    np.testing.assert_allclose(got[1:], want, atol=1e-3, rtol=0)


@pytest.mark.parametrize("dialect", ["fanuc", "heidenhain", "linuxcnc"])
@pytest.mark.parametrize("name, options, raster", CASES, ids=[c[0] for c in CASES])
def test_every_dialect_through_the_simulator_equals_the_pc_raster(dialect, name, options, raster):
    s = surface(name)
    settings = machine(dialect=dialect, **options)
    program = macro_program(s, settings, raster, FLAT)
    sim = simulate(program.text, dialect, program.precision)
    want = planned_points(s, settings, raster, FLAT)
    got = sim.feed_points()
    assert got.shape == (len(want) + 1, 3)
    np.testing.assert_allclose(got[1:], want, atol=1e-3, rtol=0)


def test_fanuc_and_linuxcnc_programs_agree_with_rs274_and_each_other(rs274, tmp_path):
    """A family of equivalent programs: rs274 runs the LinuxCNC one, the simulator runs both."""
    for n, direction in ((3, "x"), (5, "y"), (6, "x")):
        s = rough_grid(n, seed=n, zmax=20)
        raster = RasterSpec(direction, 6.0, 2.5)
        progs = {d: macro_program(s, machine(dialect=d), raster, FLAT, precision=15)
                 for d in ("fanuc", "linuxcnc")}
        path = tmp_path / f"m{n}.ngc"
        path.write_text(progs["linuxcnc"].text)
        real = feeds(rs274.run(path).stdout)
        ours = simulate(progs["linuxcnc"].text, "linuxcnc", 15).feed_points()
        fanuc = simulate(progs["fanuc"].text, "fanuc", 15).feed_points()
        np.testing.assert_allclose(ours, real, atol=6e-5, rtol=0)
        np.testing.assert_allclose(fanuc, ours, atol=1e-9, rtol=0)


@st.composite
def grids(draw):
    n, m = draw(st.integers(2, 6)), draw(st.integers(2, 6))
    gaps = st.integers(1, 40).map(lambda v: Fraction(v, 4))
    xs = np.cumsum([Fraction(draw(st.integers(-20, 20)))] + draw(st.lists(gaps, min_size=n - 1, max_size=n - 1)))
    ys = np.cumsum([Fraction(draw(st.integers(-20, 20)))] + draw(st.lists(gaps, min_size=m - 1, max_size=m - 1)))
    z = [[Fraction(draw(st.integers(-2000, 2000)), 100) for _ in range(m)] for _ in range(n)]
    return lagrange_surface(grid_from_table(list(xs), list(ys), z))


@hsettings(max_examples=12, deadline=None)
@given(s=grids(), scale=st.sampled_from([0.5, 1.0, 2.5]), direction=st.sampled_from(["x", "y"]),
       dialect=st.sampled_from(["linuxcnc", "fanuc"]))
def test_any_grid_runs_through_rs274_or_the_simulator_onto_the_pc_raster(rs274, tmp_path_factory, s, scale,
                                                                         direction, dialect):
    x0, x1, y0, y1 = (float(v) * scale for v in s.grid.bounds)
    raster = RasterSpec(direction, max(x1 - x0, y1 - y0) / 7, max(x1 - x0, y1 - y0) / 11)
    settings = machine(dialect=dialect, mm_per_unit=scale, origin_mm=(3.0, -4.0, 1.5), safe_z_mm=9e4)
    try:
        program = macro_program(s, settings, raster, FLAT, precision=15, tolerance_mm=1e-3)
    except (ProgramError, ToolpathError) as e:
        # A grid whose polynomial swings between its points past what the control reads or past the safe
        # height is refused, in one line that says so; the property is about the programs written.
        assert "\n" not in str(e) and (" control reads " in str(e) or str(e).startswith("safe Z")), e
        assume(False)
    if dialect == "linuxcnc":
        path = tmp_path_factory.mktemp("any") / "any.ngc"
        path.write_text(program.text)
        result = rs274.run(path)
        assert result.returncode == 0, result.stdout[-300:]
        got = feeds(result.stdout)
    else:
        got = simulate(program.text, "fanuc", 15).feed_points()
    np.testing.assert_allclose(got[1:], planned_points(s, settings, raster, FLAT), atol=1e-3, rtol=0)


# ---------------------------------------------------------------- accuracy on the control

@pytest.mark.parametrize("n", [3, 4, 5, 6, 7])
def test_eight_digits_stay_within_a_micrometre_up_to_7x7(n):
    loops = macro_loops(rough_grid(n, seed=n), machine(), RasterSpec("x", 1.0, 1.0), FLAT, form="lagrange")
    assert predicted_error(loops, 8, rows=7, points=11) <= 1e-3


@pytest.mark.parametrize("n", [8, 10, 12])
def test_fifteen_digits_stay_within_a_micrometre_up_to_12x12(n):
    loops = macro_loops(rough_grid(n, seed=n), machine(), RasterSpec("x", 1.0, 1.0), FLAT, form="horner")
    assert predicted_error(loops, 15, rows=5, points=9) <= 1e-3


def test_simulated_error_at_eight_digits_matches_the_prediction():
    s = rough_grid(7, seed=7)
    settings = machine(dialect="fanuc")
    raster = RasterSpec("x", 6.0, 3.0)
    program = macro_program(s, settings, raster, FLAT)
    got = simulate(program.text, "fanuc", 8).feed_points()[1:]
    err = np.abs(got - planned_points(s, settings, raster, FLAT)).max()
    assert err <= 1e-3
    assert err <= 3 * program.predicted_error_mm + 2e-6


def test_the_expanded_horner_form_fails_where_the_basis_form_holds():
    s = rough_grid(8, seed=8)
    raster = RasterSpec("x", 1.0, 1.0)
    horner = predicted_error(macro_loops(s, machine(), raster, FLAT, "horner"), 8, 7, 11)
    basis = predicted_error(macro_loops(s, machine(), raster, FLAT, "lagrange"), 8, 7, 11)
    assert horner > 1e-3 > basis


def test_a_program_that_misses_the_tolerance_is_refused_with_the_prediction():
    s = rough_grid(9, seed=9)
    with pytest.raises(ProgramError, match=r"predicted to be off by [0-9.e-]+ mm, more than the tolerance 0.001 mm"):
        macro_program(s, machine(dialect="fanuc"), RasterSpec("x", 5.0, 5.0), FLAT, form="horner")


def test_a_constant_the_control_cannot_read_is_refused():
    s = rough_grid(12, seed=12)
    with pytest.raises(ProgramError, match=r"has 9 digits, more than the 8 the control reads"):
        macro_program(s, machine(dialect="fanuc"), RasterSpec("x", 5.0, 5.0), FLAT, form="horner",
                      tolerance_mm=100.0)


# ---------------------------------------------------------------- size

@pytest.mark.slow
@pytest.mark.parametrize("dialect", ["fanuc", "linuxcnc"])
@pytest.mark.parametrize("n", [3, 5, 7])
def test_macro_stays_under_4kb_up_to_7x7_at_any_step(dialect, n):
    s = rough_grid(n, seed=n, zmax=10)
    # the finest raster is 72 million points, past the default --max-points: lifted, as the size is the question
    sizes = [macro_program(s, machine(dialect=dialect), RasterSpec("x", step, step / 2), FLAT, max_points=None).size
             for step in (5.0, 0.5, 0.01)]
    assert max(sizes) < 4096
    assert max(sizes) - min(sizes) <= 40  # only the loop counts and steps change


def test_stats_compare_with_the_point_list():
    s = surface("paper-example-4")
    settings = machine(dialect="fanuc", mm_per_unit=20.0)
    raster = RasterSpec("x", 0.5, 0.2)
    program = macro_program(s, settings, raster, FLAT)
    pts = planned_points(s, settings, raster, FLAT)
    stats = program_stats(program, pts, settings)
    assert stats.points == len(pts) == 161 * 401
    assert stats.macro_bytes == program.size < 4096
    assert stats.point_list_bytes > 1_000_000
    assert stats.point_list_seconds == pytest.approx(stats.point_list_bytes * 11 / 9600)
    assert "9600 baud 7E2" in stats.text()


def test_stats_from_a_sample_are_close_to_the_full_count():
    from lagsym.macro import points_at, sample_positions

    s = surface("paper-example-4")
    settings = machine(dialect="fanuc", mm_per_unit=20.0)
    raster = RasterSpec("x", 0.5, 0.2)
    program = macro_program(s, settings, raster, FLAT)
    full = program_stats(program, planned_points(s, settings, raster, FLAT), settings)
    sample = points_at(s, settings, FLAT, *sample_positions(program.loops.raster, 101))
    estimate = program_stats(program, sample, settings, count=full.points)
    assert estimate.points == full.points
    assert estimate.point_list_bytes == pytest.approx(full.point_list_bytes, rel=0.01)


def test_point_list_size_counts_what_fixed_would_write():
    from lagsym.gcode.numbers import fixed

    pts = np.array([[0.0, -1.2345, 100.0], [12.5, 0.0004, -0.0004], [-3.0, 99.9996, 7.0]])
    text = "".join(f"G1 X{fixed(float(x), 3)} Y{fixed(float(y), 3)} Z{fixed(float(z), 3)}\n" for x, y, z in pts)
    assert point_list_size(pts, 3) == len(text)
    assert transfer_seconds(960) == pytest.approx(1.1)


# ---------------------------------------------------------------- the raster

def test_raster_is_counted_and_clamped_to_the_box():
    s = surface("paper-example-1")  # x 1..5, y 2..4
    counted = macro_raster(s, machine(mm_per_unit=10.0), RasterSpec("x", 7.0, 3.0))
    assert (counted.points.count, counted.rows.count) == (14, 3)  # 40 mm / 3 -> 14 steps, 20 mm / 7 -> 3
    assert counted.points.clamped and counted.rows.clamped
    x, y = raster_positions(counted)
    assert x[14] == 50.0 and x[13] == 49.0 and x[15] == 50.0  # clamped, then the reversed row starts there
    assert sorted(set(y)) == [20.0, 27.0, 34.0, 40.0]


def test_no_drift_over_many_points(rs274, tmp_path):
    s = surface("paper-example-1")
    settings = machine(dialect="linuxcnc", mm_per_unit=10.0)
    raster = RasterSpec("x", 10.0, 0.1)  # 400 points a row
    path = tmp_path / "fine.ngc"
    path.write_text(macro_program(s, settings, raster, FLAT).text)
    got = feeds(rs274.run(path).stdout)[1:]
    want = planned_points(s, settings, raster, FLAT)
    np.testing.assert_allclose(got, want, atol=1e-3, rtol=0)
    assert got[400, 0] == 50.0  # the 401st point of the first row is the box edge


def test_row_form_is_exact():
    s = surface("paper-example-3")
    settings = machine(mm_per_unit=3.0, origin_mm=(1.0, 2.0, 3.0))
    for direction in ("x", "y"):
        f = row_form(s, settings, direction)
        for xi, yk, z in s.grid.points()[::3]:
            X, Y = xi * 3 + 1, yk * 3 + 2
            p, r = (X, Y) if direction == "x" else (Y, X)
            u, v = (p - f.pc) * f.pk, (r - f.rc) * f.rk
            value = sum(c * u**a * v**b for a, row in enumerate(f.coefficients) for b, c in enumerate(row))
            assert value + f.z0 == z * 3 + 3


def test_macro_needs_fixed_steps():
    with pytest.raises(ToolpathError, match="fixed side step"):
        macro_raster(surface("paper-example-1"), machine(), RasterSpec("x", None, 0.2, scallop_mm=0.01))


# ---------------------------------------------------------------- what each control requires

def _depth(line: str) -> int:
    d = best = 0
    for ch in line:
        d += ch == "["
        d -= ch == "]"
        best = max(best, d)
    return best


@pytest.mark.slow
@pytest.mark.parametrize("form", ["horner", "lagrange"])
def test_fanuc_program_follows_macro_b_rules(form):
    program = macro_program(rough_grid(7, seed=1), machine(dialect="fanuc", program_number=42),
                            RasterSpec("y", 1.0, 0.5), FLAT, form=form, tolerance_mm=1.0)
    lines = program.text.split("\n")
    assert lines[0] == "%" and lines[1].startswith("O0042 ") and lines[-2] == "%"
    body = [re.sub(r"\([^)]*\)", "", line) for line in lines]
    assert all(_depth(line) <= 5 for line in body)
    assert not any(re.search(r"\d[eE][-+]?\d", line) for line in body)
    for line in body:  # every constant in an expression or on an axis word has a decimal point
        if "#" in line or line.startswith(("G0", "G1 X")):
            for num in re.findall(r"(?<![#\w.])(\d+\.?\d*)", line.split(" DO")[0]):
                if not re.match(r"G\d", line) or line.find(num) > 2:
                    assert "." in num, (num, line)
    numbers = {int(v) for v in re.findall(r"#(\d+)", program.text)}
    assert min(numbers) >= 100 and max(numbers) <= 199
    assert max(int(d) for d in re.findall(r"DO(\d)", program.text)) == 2
    assert all(len(line) <= 128 for line in lines)


def test_fanuc_variable_base():
    s = surface("paper-example-4")
    text = macro_program(s, machine(dialect="fanuc"), RasterSpec(), FLAT, variable_base=500).text
    numbers = {int(v) for v in re.findall(r"#(\d+)", text)}
    assert min(numbers) == 500 and max(numbers) < 600
    assert simulate(text, "fanuc", 8, max_blocks=50_000_000).moves
    with pytest.raises(ProgramError, match="outside the ranges"):
        macro_program(s, machine(dialect="fanuc"), RasterSpec(), FLAT, variable_base=190)


def test_heidenhain_program_shape():
    text = macro_program(surface("paper-example-2"), machine(dialect="heidenhain", program_number=7),
                         RasterSpec("x", 1.0, 1.0), FLAT).text
    lines = text.splitlines()
    assert lines[0] == "0 BEGIN PGM 7 MM" and lines[-1].endswith("END PGM 7 MM")
    assert [int(line.split()[0]) for line in lines] == list(range(len(lines)))
    assert all(re.match(r"\d+ (FN \d+: |LBL |L |;|TOOL CALL|BEGIN|END)", line) for line in lines)
    assert max(int(q) for q in re.findall(r"Q(\d+)", text)) <= 99


def test_safe_z_below_the_path_is_refused():
    with pytest.raises(ToolpathError, match=r"safe Z 50 mm is less than the feed height 2 mm above the highest point "
                                            r"of the path, 71.38\d mm"):
        macro_program(surface("paper-example-4"), MachineSettings(mm_per_unit=20.0), RasterSpec("x", 5.0, 5.0), FLAT)


def test_program_is_immutable_and_uses_line_ending():
    program = macro_program(surface("paper-example-1"), machine(dialect="fanuc", line_ending="crlf"),
                            RasterSpec(), FLAT)
    with pytest.raises(dataclasses.FrozenInstanceError):
        program.text = ""
    assert program.text.count("\r\n") == program.text.count("\n")


def test_inch_programs_are_in_inches():
    s = surface("paper-example-1")
    settings = machine(dialect="linuxcnc", units="inch", mm_per_unit=25.4)
    raster = RasterSpec("x", 12.7, 6.35)
    program = macro_program(s, settings, raster, FLAT)
    assert "G20" in program.text
    got = simulate(program.text, "linuxcnc", 15).feed_points()[1:]
    want = planned_points(s, settings, raster, FLAT)
    np.testing.assert_allclose(got, want, atol=1e-4)
    # Surface units are inches at scale 25.4; Z is raised by half the last decimal (0.00005 inch).
    assert want[0].tolist() == pytest.approx([1.0, 2.0, 7.00005])


def test_unknown_dialect_names_the_choices():
    with pytest.raises(InputError, match="macro dialect 'grbl' is not one of fanuc, haas, linuxcnc, heidenhain"):
        macro_program(surface("paper-example-1"), machine(dialect="grbl"), RasterSpec(), FLAT)


def test_unknown_precision_and_form_name_the_choices():
    with pytest.raises(InputError, match="precision 9 is not one of 8, 15"):
        macro_program(surface("paper-example-1"), machine(), RasterSpec(), FLAT, precision=9)
    with pytest.raises(InputError, match="horner, lagrange"):
        macro_program(surface("paper-example-1"), machine(), RasterSpec(), FLAT, form="monomial")


def test_the_macro_modules_import_one_way():
    """No module of lagsym.macro imports one above it, not even inside a function."""
    import grimp

    graph = grimp.build_graph("lagsym")
    order = ["model", "_placement", "raster", "form", "ballend", "points", "loops", "accuracy", "program"]
    for low, module in enumerate(order):
        for high in order[low + 1:]:
            assert not graph.direct_import_exists(importer=f"lagsym.macro.{module}",
                                                  imported=f"lagsym.macro.{high}"), (module, high)


# ---------------------------------------------------------------- command line

def test_cli_macro_then_simulate(run_cli, tmp_path):
    prog, moves = tmp_path / "O1000.nc", tmp_path / "moves.csv"
    status, out, err = run_cli("macro", EXAMPLES / "paper-example-4.json", "--scale", 20, "--tool-diameter", 0,
                               "--safe-z", 100,
                               "--stepover", 2, "--step", 1, "--dialect", "fanuc", "--program", 1000,
                               "-o", prog, "--stats")
    assert status == 0, err
    assert "macro program:" in out and "point-list program:" in out and "9600 baud" in out
    assert prog.read_text().startswith("%\nO1000 ")
    status, out, err = run_cli("simulate", prog, "--precision", 8, "-o", moves)
    assert status == 0, err
    rows = moves.read_text().splitlines()
    assert rows[0] == "line,motion,x,y,z,feed" and "no alarm" in err
    assert sum(1 for r in rows if ",G1," in r) == 41 * 81 + 1


def test_cli_simulate_reports_an_alarm(run_cli, tmp_path):
    prog = tmp_path / "bad.nc"
    prog.write_text("%\nO1\nWHILE [1. LT 2.] DO1\nG1 X1. Y1. Z1. F1.\n%\n")
    status, out, err = run_cli("simulate", prog)
    assert status == 2 and "alarm 124" in err


def test_cli_macro_refuses_with_exit_2(run_cli, tmp_path):
    rng = random.Random(3)
    pts = [[i * 5, k * 5, rng.randint(0, 5000) / 100] for i in range(9) for k in range(9)]
    f = tmp_path / "big.json"
    f.write_text(json.dumps({"points": pts}))
    args = ("--dialect", "fanuc", "--form", "horner", "--tool-diameter", 0, "--safe-z", 900, "--stepover", 5, "--step", 5)
    # 9x9 even nodes amplify errors in the points 120 times: that is the first cause named.
    status, out, err = run_cli("macro", f, *args)
    assert status == 2 and "amplified up to 119.8 times" in err and "lagsym fit" in err
    status, out, err = run_cli("macro", f, *args, "--accept-conditioning")
    assert status == 2 and "predicted to be off by" in err


# ---------------------------------------------------------------- ball-end cutter

BALL = Tool("ball", 4.0)


@pytest.mark.slow
@pytest.mark.parametrize("direction", ["x", "y"])
def test_ball_end_macro_through_rs274_equals_the_pc_offset(rs274, tmp_path, direction):
    s = surface("paper-example-4")
    settings = machine(dialect="linuxcnc", mm_per_unit=20.0, stock_to_leave_mm=0.2, origin_mm=(1.0, 2.0, 3.0))
    raster = RasterSpec(direction, 5.0, 2.0)
    path = tmp_path / "ball.ngc"
    path.write_text(macro_program(s, settings, raster, BALL).text)
    got = feeds(rs274.run(path).stdout)[1:]
    want = planned_points(s, settings, raster, BALL)
    np.testing.assert_allclose(got, want, atol=1e-3, rtol=0)


@pytest.mark.parametrize("form", ["horner", "lagrange"])
@pytest.mark.parametrize("dialect", ["fanuc", "heidenhain"])
def test_ball_end_macro_through_the_simulator(dialect, form):
    s = surface("paper-example-3")
    settings = machine(dialect=dialect, mm_per_unit=25.0)
    raster = RasterSpec("y", 12.0, 5.0)
    program = macro_program(s, settings, raster, BALL, form=form)
    got = simulate(program.text, dialect, 8).feed_points()[1:]
    np.testing.assert_allclose(got, planned_points(s, settings, raster, BALL), atol=1e-3, rtol=0)


@pytest.mark.parametrize("dialect", ["fanuc", "heidenhain"])
def test_ball_end_7x7_program_raises_no_alarm(dialect):
    """The largest program lagsym writes at 8 digits keeps every control limit (brackets, blocks, digits, variables)."""
    nodes = [Fraction(10 * i) for i in range(7)]
    z = [[Fraction(round(300 * np.sin(i / 2) + 200 * np.cos(k / 3)), 100) for k in range(7)] for i in range(7)]
    s = lagrange_surface(grid_from_table(nodes, nodes, z))
    settings = machine(dialect=dialect)
    raster = RasterSpec("y", 5.0, 3.0)
    program = macro_program(s, settings, raster, Tool("ball", 6.0))
    got = simulate(program.text, dialect, 8).feed_points()[1:]
    np.testing.assert_allclose(got, planned_points(s, settings, raster, Tool("ball", 6.0)), atol=1e-3, rtol=0)


def test_cli_simulate_missing_file(run_cli, tmp_path):
    status, out, err = run_cli("simulate", tmp_path / "nope.nc")
    assert status == 2 and out == "" and err.strip().endswith("nope.nc: no such file")


def test_ball_end_tip_is_one_radius_off_the_surface():
    s = surface("paper-example-4")
    settings = machine(mm_per_unit=20.0)
    tips = planned_points(s, settings, RasterSpec("x", 10.0, 4.0), BALL)
    centres = tips + [0.0, 0.0, 2.0]
    xs = np.linspace(20.0, 100.0, 401)
    X, Y = np.meshgrid(xs, xs)
    cloud = np.column_stack([X.ravel(), Y.ravel(), 20.0 * evaluate_points(s, X.ravel() / 20.0, Y.ravel() / 20.0)])
    # away from the box edges, where the sampled surface ends
    inner = [c for c in centres if 25 < c[0] < 95 and 25 < c[1] < 95]
    near = [np.min(np.linalg.norm(cloud - c, axis=1)) for c in inner[::4]]
    assert len(near) > 20
    assert min(near) == pytest.approx(2.0, abs=0.01)  # never closer than the radius: no gouge
    assert max(near) == pytest.approx(2.0, abs=0.01)  # and touching


def test_ball_end_slopes_on_the_control_are_the_exact_derivatives():
    from lagsym.macro.model import decimal_context, run
    from lagsym.lagrange import X, Y

    s = surface("paper-example-3")
    loops = macro_loops(s, machine(mm_per_unit=1.0), RasterSpec("x", 1.0, 1.0), Tool("ball", 0.01), "horner")
    ctx = decimal_context(30)
    env = run(loops.row_code, {"r": ctx.create_decimal("2.5")}, ctx)
    env["p"] = ctx.create_decimal("1.75")
    run(loops.point_code, env, ctx)
    fx = s.derivative(1, 0).as_expr().subs({X: Fraction(7, 4), Y: Fraction(5, 2)})
    fy = s.derivative(0, 1).as_expr().subs({X: Fraction(7, 4), Y: Fraction(5, 2)})
    assert float(env["zp"]) == pytest.approx(float(fx), rel=1e-20, abs=1e-20)
    assert float(env["zr"]) == pytest.approx(float(fy), rel=1e-20, abs=1e-20)


def test_ball_end_gouge_is_refused_with_a_suggestion():
    s = surface("paper-example-4")
    expected = r"concave with a radius of curvature of 2.5971 mm.*at most 5.194 mm.*toolpath"
    with pytest.raises(ToolpathError, match=expected):
        macro_program(s, machine(dialect="fanuc", mm_per_unit=20.0), RasterSpec("x", 0.5, 0.2), Tool("ball", 6.0))


def _tightest_radius_ex4() -> tuple[float, float, float]:
    """Brute force on the interpolating polynomial by its Lagrange basis (test_rough's, not lagsym's evaluator):
    the smallest concave radius of curvature of Example 4 at scale 20 (mm) and where, from a 401 x 401 lattice
    refined by zooming around its 40 best points, the derivatives by central differences."""
    from test_rough import EX4, exact_heights

    def kmax(x, y, h=1e-3):
        f = lambda a, b: exact_heights(EX4, a, b)  # noqa: E731
        z0 = f(x, y)
        fx, fy = (f(x + h, y) - f(x - h, y)) / (2 * h), (f(x, y + h) - f(x, y - h)) / (2 * h)
        fxx, fyy = (f(x + h, y) - 2 * z0 + f(x - h, y)) / h ** 2, (f(x, y + h) - 2 * z0 + f(x, y - h)) / h ** 2
        fxy = (f(x + h, y + h) - f(x + h, y - h) - f(x - h, y + h) + f(x - h, y - h)) / (4 * h * h)
        g = 1 + fx ** 2 + fy ** 2
        mean = ((1 + fx ** 2) * fyy - 2 * fx * fy * fxy + (1 + fy ** 2) * fxx) / (2 * g ** 1.5)
        return mean + np.sqrt(np.maximum(mean ** 2 - (fxx * fyy - fxy ** 2) / g ** 2, 0))

    xs = np.linspace(20, 100, 401)
    gx, gy = np.meshgrid(xs, xs, indexing="ij")
    k = kmax(gx, gy)
    best = (0.0, 0.0, 0.0)
    for i in np.argsort(k.ravel())[::-1][:40]:
        x, y, step = gx.ravel()[i], gy.ravel()[i], 0.2
        for _ in range(14):
            g = np.linspace(-step, step, 9)
            ax, ay = np.meshgrid(np.clip(x + g, 20, 100), np.clip(y + g, 20, 100))
            kk = kmax(ax, ay)
            j = int(np.argmax(kk))
            x, y, step = ax.ravel()[j], ay.ravel()[j], step / 3
        best = max(best, (float(kmax(np.array(x), np.array(y))), float(x), float(y)))
    return 1.0 / best[0], best[1], best[2]


@pytest.mark.slow
def test_the_largest_ball_is_stated_from_the_safe_side_and_never_contradicts_the_refusal():
    """Example 4's tightest hollow, 2.5971 mm by brute force at the box edge, lies between the 1001 x 1001
    samples (2.61 mm there): the ball allowed is 2 x 2.5971 rounded down, a 5.2 mm ball is refused, and the
    figures of the refusal are below the refused ones."""
    rc, x, y = _tightest_radius_ex4()
    assert 2.597 < rc < 2.5972 and x == 100.0 and abs(y - 20.19) < 0.01
    s = surface("paper-example-4")
    raster = RasterSpec("x", 0.5, 0.2)
    for diameter, stock in ((5.2, 0.0), (5.0, 0.2), (6.0, 0.0)):
        with pytest.raises(ToolpathError) as e:
            macro_program(s, machine(dialect="fanuc", mm_per_unit=20.0, safe_z_mm=90.0, stock_to_leave_mm=stock),
                          raster, Tool("ball", diameter))
        text = str(e.value)
        shown = float(re.search(r"radius of curvature of ([\d.]+) mm", text).group(1))
        offset = float(re.search(r"below the offset radius ([\d.]+) mm", text).group(1))
        allowed = float(re.search(r"diameter at most ([\d.]+) mm", text).group(1))
        assert shown <= rc and rc - shown < 1e-4, (shown, rc)
        assert offset == diameter / 2 + stock and shown < offset
        assert allowed <= 2 * (rc - stock) and 2 * (rc - stock) - allowed < 1e-3 and allowed < diameter, text
    # the ball stated is accepted, one a thousandth larger is not
    ok = np.floor(2 * rc * 1000) / 1000
    macro_program(s, machine(dialect="fanuc", mm_per_unit=20.0, safe_z_mm=90.0), raster, Tool("ball", ok))
    with pytest.raises(ToolpathError, match="at most 5.194 mm"):
        macro_program(s, machine(dialect="fanuc", mm_per_unit=20.0, safe_z_mm=90.0), raster, Tool("ball", ok + 0.001))


def test_a_raster_the_control_would_run_for_days_is_refused_with_its_figures(run_cli):
    """``--step 0.001 --stepover 0.001`` on Example 4 at scale 20: the box is 80 mm a side (the points file
    spans 1 to 5 units), so 80,001 rows of 80,001 points, 6.4 billion points and 6,400 km... of path at
    600 mm/min: refused before anything is planned, with the figures and the option that lifts the limit."""
    pts = np.array(json.loads((EXAMPLES / "paper-example-4.json").read_text())["points"], dtype=float)
    side = float(np.ptp(pts[:, 0])) * 20
    n = round(side / 0.001) + 1
    length_m = (n * side + side) / 1000
    hours = length_m * 1000 / 600 / 60
    status, out, err = run_cli("macro", EXAMPLES / "paper-example-4.json", "--scale", "20", "--tool-diameter", "5",
                               "--safe-z", "90", "--step", "0.001", "--stepover", "0.001")
    assert status == 2 and not out and err.count("\n") == 1, err
    assert f"{n:,} rows of {n:,} points, {n * n:,} points, more than the limit of 20,000,000" in err, err
    assert f"{length_m:,.2f} m of path, about {hours:,.1f} hours at the feed 600 mm/min" in err, err
    assert "--max-points" in err
    status, _, err = run_cli("macro", EXAMPLES / "paper-example-4.json", "--scale", "20", "--tool-diameter", "5",
                             "--safe-z", "90", "--max-points", "1000")
    assert status == 2 and "161 rows of 401 points, 64,561 points, more than the limit of 1,000" in err, err


# ---------------------------------------------------------------- issue 13: programs a machinist can trust

def _disc_max(coeffs, x0, y0, radius, box, n=81):
    """Brute force: the highest point of the exact polynomial under a flat disc, over an n x n lattice in the box."""
    xs = np.linspace(x0 - radius, x0 + radius, n)
    gx, gy = np.meshgrid(xs, np.linspace(y0 - radius, y0 + radius, n))
    inside = (np.hypot(gx - x0, gy - y0) <= radius) & (gx >= box[0]) & (gx <= box[1]) & (gy >= box[2]) & (gy <= box[3])
    z = sum(float(c) * gx[inside] ** a * gy[inside] ** b for a, row in enumerate(coeffs) for b, c in enumerate(row))
    return float(z.max())


@pytest.mark.parametrize("dialect", ["fanuc", "linuxcnc", "heidenhain"])
def test_a_flat_end_is_refused_naming_the_point_list_path(dialect):
    s = surface("paper-example-1")
    settings = machine(dialect=dialect, mm_per_unit=10.0)
    with pytest.raises(ToolpathError, match=r"flat-end cutter \(diameter 6 mm\).*lagsym toolpath --tool-shape flat"):
        macro_program(s, settings, RasterSpec("x", 5.0, 5.0), Tool("flat", 6.0))
    # Why: the height at the centre (what the program would have cut) lies far below the flat end's
    # cutter location, the maximum of the exact polynomial under its disc (brute force, surface units).
    box = [float(v) for v in s.grid.bounds]
    x, y = (box[0] + box[1]) / 2, (box[2] + box[3]) / 2
    centre = sum(float(c) * x ** a * y ** b for a, row in enumerate(s.coefficients) for b, c in enumerate(row))
    worst = max(_disc_max(s.coefficients, px, py, 0.3, box) - sum(
        float(c) * px ** a * py ** b for a, row in enumerate(s.coefficients) for b, c in enumerate(row))
        for px in np.linspace(box[0], box[1], 9) for py in np.linspace(box[2], box[3], 9))
    assert worst * 10.0 > 25.0 and np.isfinite(centre)  # 29 mm on this 9 x 9 sample


def test_cli_flat_end_macro_exits_2(run_cli):
    status, out, err = run_cli("macro", EXAMPLES / "paper-example-1.json", "--scale", 10, "--tool-shape", "flat",
                               "--tool-diameter", 6, "--safe-z", 500)
    assert status == 2 and out == "" and "lagsym toolpath" in err and "Traceback" not in err


@pytest.mark.parametrize("coolant, on", [("off", None), ("flood", "FLOOD_ON"), ("mist", "MIST_ON")])
def test_macro_start_clearance_first_then_feed_height(rs274, tmp_path, coolant, on):
    s = surface("paper-example-4")
    settings = machine(dialect="linuxcnc", mm_per_unit=20.0, safe_z_mm=100.0, coolant=coolant,
                       work_offset="G56", tool_number=3, length_offset=7, feed_height_mm=1.5)
    program = macro_program(s, settings, RasterSpec("x", 5.0, 5.0), FLAT)
    path = tmp_path / "m.ngc"
    path.write_text(program.text)
    r = rs274.run(path, tool_table="T3 P3 Z0 D6\nT7 P7 Z0.5 D6\n")
    assert r.returncode == 0, r.stderr[-400:]
    canon = [ln.split("N..... ", 1)[1] for ln in r.stdout.splitlines() if "N..... " in ln]
    travs = [c for c in canon if c.startswith("STRAIGHT_TRAVERSE")]
    first = [float(v) for v in travs[0][18:].split(",")[:3]]
    assert first[:2] == [0.0, 0.0] and first[2] == 100.0  # Z first, straight up from where the machine is
    want = planned_points(s, settings, RasterSpec("x", 5.0, 5.0), FLAT)
    down = [float(v) for v in travs[2][18:].split(",")[:3]]
    np.testing.assert_allclose(down, want[0] + [0, 0, 1.5], atol=1e-3)  # rapid to 1.5 mm above the first point
    assert "SET_G5X_OFFSET(3," in r.stdout  # G56
    assert "USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 12.7000" in r.stdout  # H7, not H3
    assert (on in r.stdout) if on else ("FLOOD_ON" not in r.stdout and "MIST_ON" not in r.stdout)
    if on:
        assert canon.index(next(c for c in canon if c.startswith(("FLOOD_OFF", "MIST_OFF")))) > canon.index(travs[-1])


@pytest.mark.parametrize("options, match", [
    (dict(work_offset="G54\nM30"), "work offset"),
    (dict(tool_number=-1), "tool number -1"),
    (dict(length_offset=0), "length offset H0"),
    (dict(line_ending="cr"), "one block"),
    (dict(coolant="water"), "coolant"),
])
def test_program_settings_are_validated(options, match):
    with pytest.raises(InputError, match=match):
        machine(**options)


def test_safe_z_needs_a_feed_height_above_the_path():
    s, raster = surface("paper-example-4"), RasterSpec("x", 5.0, 5.0)
    with pytest.raises(ToolpathError, match=r"safe Z 71.5 mm is less than the feed height 2 mm above"):
        macro_program(s, MachineSettings(mm_per_unit=20.0, safe_z_mm=71.5), raster, FLAT)


@pytest.mark.parametrize("dialect, options, match", [
    ("fanuc", dict(work_offset="G59.1"), "not one a fanuc control has"),
    ("heidenhain", dict(work_offset="G55"), "active preset"),
    ("fanuc", dict(length_offset=401), "H400"),
    ("fanuc", dict(safe_z_mm=150000.0), r"beyond the 99999.999"),
])
def test_what_the_control_does_not_have_is_refused_with_the_limit(dialect, options, match):
    with pytest.raises(ProgramError, match=match):
        macro_program(surface("paper-example-1"), machine(dialect=dialect, **options), RasterSpec("x", 5.0, 5.0), FLAT)


def test_constants_keep_8_digits_leading_zeros_counted():
    """Every constant of an 8-digit Fanuc program has at most 8 digits, leading zeros included (a 0i's limit)."""
    text = macro_program(rough_grid(7, seed=7), machine(), RasterSpec("x", 1.0, 1.0), FLAT).text
    body = [ln for ln in text.splitlines() if ln.startswith("#")]
    numbers = re.findall(r"(?<![#\w])(\d*\.\d*)", "\n".join(body))
    assert numbers and max(len(n.replace(".", "")) for n in numbers) <= 8
    assert not re.search(r"\b0\.\d{8}", text)  # the 9-digit 0.66666667 of old


def test_comments_are_iso_840_without_commas():
    for d in ("fanuc", "linuxcnc"):
        text = macro_program(surface("paper-example-1"), machine(dialect=d), RasterSpec("x", 5.0, 5.0), FLAT).text
        for comment in re.findall(r"\(([^)]*)\)", text):
            assert re.fullmatch(r"[A-Z0-9 .+\-/]*", comment), comment


@pytest.mark.slow
def test_the_small_variable_profile_refuses_what_does_not_fit():
    s = surface("paper-example-4")
    ok = macro_program(s, machine(mm_per_unit=20.0), RasterSpec("x", 5.0, 5.0), FLAT, variables="small")
    assert max(int(v) for v in re.findall(r"#(\d+)", ok.text)) <= 149
    big = rough_grid(7, seed=7, zmax=1)
    with pytest.raises(ProgramError, match=r"51 needed.*#100-#149, #500-#531"):
        macro_program(big, machine(), RasterSpec("x", 1.0, 1.0), Tool("ball", 2.0), variables="small")
    macro_program(big, machine(), RasterSpec("x", 1.0, 1.0), Tool("ball", 2.0), variables="full")


def test_a_step_below_the_resolution_is_refused():
    with pytest.raises(ToolpathError, match=r"forward step 0.0005 is below the program's resolution 0.001"):
        macro_program(surface("paper-example-1"), machine(), RasterSpec("x", 5.0, 0.0005), FLAT)


def test_an_inch_surface_is_25_4_mm_a_unit_and_the_header_says_so(run_cli, tmp_path):
    f = tmp_path / "inch.json"
    data = json.loads((EXAMPLES / "paper-example-4.json").read_text())
    data["units"] = "inch"
    f.write_text(json.dumps(data))
    status, out, err = run_cli("macro", f, "--dialect", "linuxcnc", "--tool-diameter", 0, "--safe-z", 100)
    assert status == 0, err
    assert "(SURFACE IN INCH 25.4 MM PER UNIT PROGRAM IN MM)" in out
    mm = run_cli("macro", EXAMPLES / "paper-example-4.json", "--dialect", "linuxcnc", "--tool-diameter", 0,
                 "--scale", 25.4, "--safe-z", 100)[1]
    assert out.replace("INCH", "MM") == mm  # the same part, said to be in inches
    data["units"] = "furlongs"
    f.write_text(json.dumps(data))
    status, out, err = run_cli("macro", f, "--tool-diameter", 0, "--safe-z", 100)
    assert status == 2 and "mm" in err and "inch" in err


# ---------------------------------------------------------------- positions rounded on the control

def _lagrange_at(grid, x: Fraction, y: Fraction) -> Fraction:
    """The interpolating polynomial at (x, y), exact, by the basis products (not lagsym's evaluators)."""
    def basis(nodes, t):
        out = []
        for i, n in enumerate(nodes):
            b = Fraction(1)
            for j, m in enumerate(nodes):
                if j != i:
                    b *= (t - m) / (n - m)
            out.append(b)
        return out

    bx, by = basis(grid.x, x), basis(grid.y, y)
    return sum(bx[i] * by[k] * grid.z[i][k] for i in range(len(bx)) for k in range(len(by)))


def _control_positions(moves, dialect, decimals=3):
    """Where the control goes: a Fanuc rounds an axis word to its least input increment, LinuxCNC does not."""
    return np.round(moves, decimals) if dialect == "fanuc" else moves


@pytest.mark.parametrize("dialect", ["fanuc", "linuxcnc"])
def test_a_surface_macro_computes_z_at_the_position_the_control_goes_to(rs274, tmp_path, dialect):
    """A 7x7 grid whose box starts at 1/3 mm: before rounding on the control, Z was 2.86 mm off there.

    Every move's X and Y are on the program's last decimal (so the control has
    nothing left to round), inside the box, and Z is the exact polynomial there
    raised by at most one unit of the last decimal, never below it.
    """
    rng = random.Random(7)
    nodes = [Fraction(1, 3) + Fraction(i, 3) for i in range(7)]
    z = [[Fraction(rng.randint(0, 5000), 100) for _ in range(7)] for _ in range(7)]
    s = lagrange_surface(grid_from_table(nodes, nodes, z, source="thirds"))
    settings = machine(dialect=dialect, safe_z_mm=9e4)
    program = macro_program(s, settings, RasterSpec("x", 0.2, 0.1), FLAT, precision=15, tolerance_mm=1e-3)
    if dialect == "linuxcnc":
        path = tmp_path / "thirds.ngc"
        path.write_text(program.text)
        got = feeds(rs274.run(path).stdout)
    else:
        got = simulate(program.text, "fanuc", 15).feed_points()
    at = _control_positions(got, dialect)
    exact = np.array([float(_lagrange_at(s.grid, Fraction(str(x)), Fraction(str(y)))) for x, y in at[:, :2]])
    dz = got[:, 2] - exact
    assert dz.min() >= -1e-6 and dz.max() <= 1e-3 + 1e-6, (dz.min(), dz.max())
    assert np.abs(got[:, :2] * 1000 - np.rint(got[:, :2] * 1000)).max() < 1e-6
    assert got[:, :2].min() >= 1 / 3 and got[:, :2].max() <= 7 / 3


@pytest.mark.slow
@pytest.mark.parametrize("dialect", ["fanuc", "linuxcnc"])
def test_a_ball_end_macro_never_goes_below_the_cutter_location_where_the_control_goes(rs274, tmp_path, dialect):
    """The README's 4 mm ball on Example 4 (scale 20): Z at or above a brute-force drop-cutter at the rounded X, Y.

    Before the tip was rounded on the control, the tool went to the rounded
    position with the height of the unrounded one, up to 2.5 um into the part.
    """
    from cutters import brute_ball
    from test_rough import exact_heights

    s = surface("paper-example-4")
    settings = machine(dialect=dialect, mm_per_unit=20.0, safe_z_mm=100.0)
    program = macro_program(s, settings, RasterSpec("x", 4.0, 1.0), BALL)
    if dialect == "linuxcnc":
        path = tmp_path / "ball.ngc"
        path.write_text(program.text)
        got = feeds(rs274.run(path).stdout)
    else:
        got = simulate(program.text, "fanuc", 8).feed_points()
    at = _control_positions(got, dialect)
    f = lambda x, y: exact_heights(EXAMPLES / "paper-example-4.json", x, y)  # noqa: E731
    below = brute_ball(f, (20.0, 100.0, 20.0, 100.0), at[:, 0], at[:, 1], 2.0, n=25, rounds=10) - got[:, 2]
    assert below.max() <= 2e-5, f"{below.max() * 1000:.2f} um below at {at[np.argmax(below)]}"
    assert np.abs(got[:, :2] * 1000 - np.rint(got[:, :2] * 1000)).max() < 1e-6  # nothing left to round


def _within_a_unit(at, unit=1e-3):
    """The four positions within a unit of each ``(x, y)`` a control that rounds or truncates may go to."""
    lo_x, lo_y = np.floor(at[:, 0] / unit + 1e-9) * unit, np.floor(at[:, 1] / unit + 1e-9) * unit
    return [(lo_x + i * unit, lo_y + k * unit) for i in (0, 1) for k in (0, 1)]


def test_a_heidenhain_surface_macro_stays_above_the_surface_where_the_tnc_goes():
    """FN arithmetic cannot round: Z is raised by the slope bound, so at any position within a unit it is above F.

    Checked with the TNC's arithmetic (the simulator) against the exact
    polynomial at the positions the control may go to (X and Y rounded or
    truncated to the last decimal) and Z truncated there; without the raise
    the 7x7 thirds grid of the Fanuc test goes 0.82 mm into its steep surface (and the ball of the next
    test 4.5 um into Example 4).
    """
    from lagsym.macro.rounding import slope_lift

    rng = random.Random(7)
    nodes = [Fraction(1, 3) + Fraction(i, 3) for i in range(7)]
    z = [[Fraction(rng.randint(0, 5000), 100) for _ in range(7)] for _ in range(7)]
    s = lagrange_surface(grid_from_table(nodes, nodes, z, source="thirds"))
    settings = machine(dialect="heidenhain", safe_z_mm=9e4)
    program = macro_program(s, settings, RasterSpec("x", 0.2, 0.1), FLAT, precision=15, tolerance_mm=1e-3)
    got = simulate(program.text, "heidenhain", 15).feed_points()
    inside = (got[:, 0] >= 1 / 3 + 1e-3) & (got[:, 0] <= 7 / 3 - 1e-3) & (got[:, 1] >= 1 / 3 + 1e-3) \
        & (got[:, 1] <= 7 / 3 - 1e-3)
    got = got[inside]
    z_tnc = np.floor(got[:, 2] * 1000 + 1e-9) / 1000
    worst = np.full(len(got), -np.inf)
    for x, y in _within_a_unit(got):
        exact = np.array([float(_lagrange_at(s.grid, Fraction(str(round(a, 3))), Fraction(str(round(b, 3)))))
                          for a, b in zip(x, y)])
        worst = np.maximum(worst, exact - z_tnc)
    lift = float(slope_lift(s, settings))
    assert worst.max() <= 1e-6, f"{worst.max() * 1000:.2f} um below the surface"
    assert worst.min() >= -(lift + 2e-3)  # the raise is the bound, no more
    plain = np.array([float(_lagrange_at(s.grid, Fraction(str(a)), Fraction(str(b)))) for a, b, _ in got[:200]])
    assert np.all(got[:200, 2] - plain >= lift - 2e-6)  # every Z raised by the bound


@pytest.mark.slow
def test_a_heidenhain_ball_macro_stays_above_the_cutter_location_where_the_tnc_goes():
    """The README's 4 mm ball on Example 4 (scale 20) as a Heidenhain macro: above a brute-force drop-cutter
    at every position within a unit of the one computed, Z truncated to the last decimal."""
    from cutters import brute_ball
    from test_rough import exact_heights

    s = surface("paper-example-4")
    settings = machine(dialect="heidenhain", mm_per_unit=20.0, safe_z_mm=100.0)
    program = macro_program(s, settings, RasterSpec("x", 4.0, 1.0), BALL)
    got = simulate(program.text, "heidenhain", 8).feed_points()
    from lagsym.macro.rounding import slope_lift

    lift = float(slope_lift(s, settings))
    z_tnc = np.floor(got[:, 2] * 1000 + 1e-9) / 1000
    f = lambda x, y: exact_heights(EXAMPLES / "paper-example-4.json", x, y)  # noqa: E731
    cl = np.full(len(got), -np.inf)
    for x, y in _within_a_unit(got):
        cl = np.maximum(cl, brute_ball(f, (20.0, 100.0, 20.0, 100.0), x, y, 2.0, n=25, rounds=10))
    below = cl - z_tnc
    assert below.max() <= 2e-5, f"{below.max() * 1000:.2f} um below at {got[np.argmax(below)]}"
    unraised = (cl - np.floor((got[:, 2] - lift) * 1000 + 1e-9) / 1000).max()  # the same program without the raise
    doc = " ".join((EXAMPLES.parent / "docs" / "macros.md").read_text().split())
    assert f"{lift:.6f} mm for Example 4 at scale 20" in doc
    assert f"without the raise, the 4 mm ball on Example 4 went {unraised * 1000:.1f} um into the part" in doc
