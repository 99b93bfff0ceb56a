"""Cut simulation: lagsym's programs do not gouge, a normal-offset path and a doctored program do."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from lagsym.evaluate import evaluate_points
from lagsym.gcode import parse_moves
from lagsym.grid import grid_from_table
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import MachineSettings, Placement, RasterSpec, Tool
from lagsym.post.program import PointProgram, point_program, write_program
from lagsym.toolpath import plan_toolpath
from lagsym.verify import gouge_limit, program_resolution_mm, simulate_cut

from conftest import EXAMPLES, README_FINISHING, run_example
from cutters import exact_heights, swept_ball, swept_tool

EX2 = EXAMPLES / "paper-example-2.json"


def valley():
    """z = (x - 2)**2 / 2 + 1 over [0, 4] x [0, 2] (surface units): curvature radius 1 at the floor."""
    xs = [Fraction(i) for i in range(5)]
    ys = [Fraction(0), Fraction(2)]
    return lagrange_surface(grid_from_table(xs, ys, [[(x - 2) ** 2 / 2 + 1] * 2 for x in xs]))


@pytest.fixture(scope="module")
def ex2_program():
    surf = lagrange_surface(read_points(EX2))
    s = MachineSettings(dialect="linuxcnc", mm_per_unit=10.0, safe_z_mm=60.0)
    tp = plan_toolpath(surf, Tool("ball", 6.0), RasterSpec("x", 1.0, 0.5), s.placement, s.program, stock_to_leave_mm=s.stock_to_leave_mm)
    return surf, tp, s, write_program(point_program(tp, s))


@pytest.mark.slow
def test_lagsyms_program_does_not_gouge(ex2_program):
    surf, tp, _, text = ex2_program
    report = simulate_cut(surf, parse_moves(text), tp.tool, Placement(10.0), cell_mm=0.25)
    assert not report.gouges
    # Within the program's rounding: X and Y are rounded to the nearest unit of the last decimal over the box.
    assert report.gouge_mm <= 0.0005
    assert report.unreached_mm2 == 0.0
    assert 0.0 < report.scallop_mm < 10.0
    assert not report.crashes and report.rapid_mm == 0.0
    with pytest.raises(ValueError):
        report.cut_mm[0, 0] = 0.0


@pytest.mark.slow
def test_a_lowered_point_is_found(ex2_program):
    surf, tp, s, _ = ex2_program
    p = np.array(tp.points_mm)
    k = len(p) // 2
    p[k, 2] -= 0.3
    moves = parse_moves(write_program(PointProgram(p, s)))
    report = simulate_cut(surf, moves, tp.tool, Placement(10.0), cell_mm=0.25)
    assert report.gouges
    assert 0.2 <= report.gouge_mm <= 0.3 + 1e-9
    assert np.hypot(report.gouge_at[0] - p[k, 0], report.gouge_at[1] - p[k, 1]) <= 3.0


@pytest.mark.slow
def test_normal_offset_gouges_where_the_valley_is_tighter_than_the_tool():
    """The textbook offset (tip = surface point + R n - R z) against drop-cutter.

    The valley's curvature radius is 10 mm at the floor, the ball's radius 15 mm.
    """
    surf = valley()
    scale, r = 10.0, 15.0
    x = np.linspace(0.0, 4.0, 161)
    y = np.full_like(x, 1.0)
    z = evaluate_points(surf, x, y)
    slope = (x - 2.0)  # dF/dx, surface units
    n = np.stack([-slope, np.zeros_like(x), np.ones_like(x)]) / np.sqrt(1 + slope**2)
    centre = np.stack([x * scale, y * scale, z * scale]) + r * n
    offset = np.stack([centre[0], centre[1], centre[2] - r], axis=1)
    inside = (offset[:, 0] >= 0) & (offset[:, 0] <= 40.0)
    s = MachineSettings(mm_per_unit=scale, safe_z_mm=200.0)
    bad = parse_moves(write_program(PointProgram(offset[inside], s)))
    tool = Tool("ball", 2 * r)
    assert simulate_cut(surf, bad, tool, Placement(scale), cell_mm=0.25).gouge_mm > 1.0
    tp = plan_toolpath(surf, tool, RasterSpec("x", 20.0, 0.25), s.placement, s.program, stock_to_leave_mm=s.stock_to_leave_mm)
    good = parse_moves(write_program(point_program(tp, s)))
    assert not simulate_cut(surf, good, tool, Placement(scale), cell_mm=0.25).gouges


@pytest.mark.parametrize("shape, corner", [("ball", 1.5), ("flat", 0.0), ("bull", 0.5)])
@pytest.mark.parametrize("seed", [1, 2])
def test_the_height_map_is_the_swept_tool_within_the_resolution(shape, corner, seed):
    """Random moves in every direction, short and long, level, climbing and plunging, against a brute-force sweep."""
    from lagsym.verify import press_moves

    rng = np.random.default_rng(seed)
    xs, ys = np.linspace(0.0, 6.0, 25), np.linspace(0.0, 4.0, 17)
    a = rng.uniform([-2.0, -2.0, -1.0], [8.0, 6.0, 1.0], (12, 3))
    b = a + rng.uniform(-3.0, 3.0, (12, 3)) * rng.choice([0.05, 1.0], (12, 1))
    b[0, :2] = a[0, :2]  # a plunge
    b[1, 2] = a[1, 2]  # a level move
    tool = Tool(shape, 3.0, corner_radius_mm=corner) if shape == "bull" else Tool(shape, 3.0)
    cut = np.full((len(xs), len(ys)), np.inf)
    count, resolution = press_moves(cut, xs, ys, a, b, tool)
    ref = swept_tool(zip(a, b), 1.5, corner if shape != "ball" else 1.5, xs, ys)
    assert count >= 12 and resolution <= 1e-4
    assert np.array_equal(np.isfinite(cut), np.isfinite(ref)) and np.isfinite(ref).mean() > 0.3
    both = np.isfinite(ref)
    # Never below the tool (no cut invented), never above the lowest point the search found by more than the resolution.
    assert (cut[both] >= ref[both] - 1e-7).all(), float((ref - cut)[both].max())
    assert (cut[both] <= ref[both] + resolution + 1e-9).all(), float((cut - ref)[both].max())


def test_moves_before_the_first_z_do_not_cut():
    surf = lagrange_surface(read_points(EX2))
    moves = parse_moves("G00 X10. Y10.\nG00 Z30.\nG01 X40. Y40. F100.\n")
    report = simulate_cut(surf, moves, Tool("ball", 6.0), Placement(10.0), cell_mm=0.5)
    assert report.gouge_mm == 0.0 and report.unreached_mm2 > 0.0


@pytest.mark.slow
def test_verify_command_exit_statuses(run_cli, tmp_path, ex2_program):
    _, _, _, text = ex2_program
    good = tmp_path / "good.ngc"
    good.write_text(text)
    status, out, err = run_cli("verify", EX2, good, "--scale", "10", "--tool-diameter", "6", "--cell", "0.3",
                               "--max-left", "1")
    assert status == 0, out + err
    assert "worst gouge" in out and "none" in out
    status, out, _ = run_cli("verify", EX2, good, "--scale", "10", "--tool-diameter", "8", "--cell", "0.3")
    assert status == 1 and "GOUGE" in out  # the program was made for a smaller ball
    arcs = tmp_path / "arcs.ngc"
    arcs.write_text("G0 X0 Y0 Z5\nG2 X1 Y1 R1\n")  # an arc by its radius: not read
    status, _, err = run_cli("verify", EX2, arcs, "--scale", "10")
    assert status == 2 and "arcs.ngc, line 2" in err and "I, J, K" in err
    status, _, err = run_cli("verify", EX2, tmp_path / "missing.nc")
    assert status == 2 and "missing.nc" in err


@pytest.mark.slow
def test_toolpath_command_writes_a_program_the_interpreter_accepts(run_cli, tmp_path, rs274):
    from gcheck import interpret

    out_file = tmp_path / "O1000.nc"
    status, out, err = run_cli("toolpath", EX2, "--scale", "10", "--tool-diameter", "6", "--stepover", "2",
                               "--step", "1", "--feed", "600", "--safe-z", "80", "--dialect", "fanuc",
                               "--line-ending", "crlf", "-o", out_file)
    assert status == 0, err
    text = out_file.read_bytes().decode("ascii")
    assert text.startswith("%\r\nO1000 (PAPER-EXAMPLE-2.JSON)\r\n")
    feeds, _ = interpret(rs274, text)
    assert len(feeds) > 100
    status, out, err = run_cli("toolpath", EX2, "--origin", "1,2")
    assert status == 2 and "--origin" in err
    status, out, err = run_cli("toolpath", EX2, "--tool-shape", "flat", "--scallop", "0.01")
    assert status == 2 and "ball" in err
    status, out, _ = run_cli("toolpath", EX2, "--scale", "5", "--stepover", "3", "--step", "2", "--dialect", "grbl")
    assert status == 0 and out.startswith("(PAPER-EXAMPLE-2.JSON)")


@pytest.mark.slow
def test_a_5_um_gouge_at_one_point_fails_under_the_default_limit(ex2_program):
    # Regression: the default limit was the program's rounding plus the simulation's resolution, 5.5 um here.
    surf, tp, s, _ = ex2_program
    p = np.array(tp.points_mm)
    k = int(np.argmin(np.abs(p[:, 0] - 25.0) + np.abs(p[:, 1] - 25.0)))
    p[k, 2] = tp.exact_mm[k] - 0.005  # 5 um below its cutter location (the plan may have lifted it)
    text = write_program(PointProgram(p, s))
    report = simulate_cut(surf, parse_moves(text), tp.tool, Placement(10.0), cell_mm=0.1,
                          program_resolution_mm=program_resolution_mm(text))
    assert report.gouges and report.fails, report.summary()
    assert 0.003 <= report.gouge_mm <= 0.005 + 0.001
    # The limit is what the rounding of a correct program can cause, computed here on its own.
    t, h = np.linspace(1.0, 4.0, 31), 1e-5
    lo, hi = np.clip(t - h, 1.0, 4.0), np.clip(t + h, 1.0, 4.0)
    fx = (exact_heights(surf, hi, t) - exact_heights(surf, lo, t)) / (hi - lo)[:, None]
    fy = (exact_heights(surf, t, hi) - exact_heights(surf, t, lo)) / (hi - lo)[None, :]
    slope = np.hypot(fx, fy).max()
    assert report.gouge_limit_mm == pytest.approx(0.0005 * (1 + np.sqrt(2) * slope), rel=0.05)
    assert report.gouge_limit_mm < 0.003


def test_program_resolution_and_limit():
    assert program_resolution_mm("(TOOL 6.00000)\nG21 G90\nG01 X1.000 Y2.000 Z-0.125 F600.0\n") == 0.0005
    assert program_resolution_mm("G20\nG01 X1.0000 Y2.0000\n") == pytest.approx(0.00127)
    # Words are read as the point-list reader reads them: "G90G20" is inch, an unclosed comment ends at its line.
    assert program_resolution_mm("G90G20\nG01 X1.0000 Y2.0000\n") == pytest.approx(0.00127)
    assert program_resolution_mm("(NOTE\nG20\nG01 X1.0000 (A)\n") == pytest.approx(0.00127)
    assert program_resolution_mm("%\nG21\nG01 X 1.000\n%\nG01 X1.00000\n") == 0.0005
    assert gouge_limit(0.0005, 0.0) == 0.0005


@pytest.mark.slow
def test_a_rapid_into_the_part_is_a_rapid_crash_with_its_line(ex2_program, run_cli, tmp_path):
    surf, tp, s, text = ex2_program
    lines = text.splitlines()
    # A rapid straight across the part at 5 mm below its top, after the program's first moves.
    k = next(i for i, ln in enumerate(lines) if ln.startswith("G01")) + 1
    z = float(tp.points_mm[:, 2].max()) - 5.0
    lines[k:k] = [f"G00 Z{z:.3f}", "G00 X25.000 Y25.000", "G00 Z60.000"]
    bad = "\n".join(lines) + "\n"
    report = simulate_cut(surf, parse_moves(bad), tp.tool, Placement(10.0), cell_mm=0.3)
    assert report.crashes and report.fails
    assert report.rapid_line in (k + 1, k + 2)
    assert report.rapid_mm > 1.0
    f = tmp_path / "crash.ngc"
    f.write_text(bad)
    status, out, _ = run_cli("verify", EX2, f, "--scale", "10", "--tool-diameter", "6", "--cell", "0.3")
    assert status == 1 and "RAPID CRASH" in out and f"(line {report.rapid_line})" in out


@pytest.mark.slow
def test_material_left_is_reported_apart_from_the_gouge(run_cli, tmp_path):
    surf = lagrange_surface(read_points(EX2))
    s = MachineSettings(dialect="linuxcnc", mm_per_unit=10.0, safe_z_mm=60.0, stock_to_leave_mm=0.3)
    tp = plan_toolpath(surf, Tool("ball", 6.0), RasterSpec("x", 1.0, 0.5), s.placement, s.program, stock_to_leave_mm=s.stock_to_leave_mm)
    text = write_program(point_program(tp, s))
    report = simulate_cut(surf, parse_moves(text), tp.tool, Placement(10.0), cell_mm=0.3)
    assert not report.gouges and not report.crashes and report.leaves_material
    # Independently: a ball swept along the program's points over the exact surface, on a row of cells.
    xs, ys = np.linspace(10.0, 40.0, 61), np.array([24.5, 25.0, 25.5])
    above = swept_ball(tp.points_mm, 3.0, xs, ys) - exact_heights(surf, xs / 10, ys / 10) * 10
    assert above.min() >= 0.3 - 0.01 and report.left_height_mm >= above.max() - 0.01
    assert 0.3 * 0.5 <= report.left_mm <= report.left_height_mm
    f = tmp_path / "stock.ngc"
    f.write_text(text)
    status, out, _ = run_cli("verify", EX2, f, "--scale", "10", "--tool-diameter", "6", "--cell", "0.3")
    assert status == 1 and "TOO MUCH" in out and "worst gouge" in out and "GOUGE" not in out
    status, out, _ = run_cli("verify", EX2, f, "--scale", "10", "--tool-diameter", "6", "--cell", "0.3",
                             "--max-left", "2")
    assert status == 0, out


@pytest.mark.slow
def test_readme_finishing_example(run_cli, tmp_path, tmp_path_factory, monkeypatch):
    """The README's finishing example finishes the part's edges; the figures docs/toolpaths.md quotes."""
    import re

    ex4 = EXAMPLES / "paper-example-4.json"
    (tmp_path / "examples").symlink_to(EXAMPLES)
    monkeypatch.chdir(tmp_path)
    err = run_example(README_FINISHING, tmp_path_factory)
    prog = tmp_path / "O1000.nc"
    status, out, _ = run_cli("verify", ex4, prog, "--scale", "20", "--tool-diameter", "6")
    num = r"([0-9.]+)"
    predicted = re.search(rf"worst predicted cusp {num} mm normal to the surface at X{num} Y{num}", err).groups()
    gouge, limit = map(float, re.search(rf"worst gouge +{num} mm at .* \(limit {num} mm\): none", out).groups())
    assert re.search(r"rapid into part +0\.0000 mm .*: none", out)
    left, height, y = map(float, re.search(
        rf"material left +{num} mm normal to the surface \({num} mm above it\) at X[0-9.]+ Y{num}", out).groups())
    scallop = float(re.search(rf"scallop \(normal\) +{num} mm", out).group(1))
    doc = " ".join((EXAMPLES.parent / "docs" / "toolpaths.md").read_text().split())
    assert f"no gouge ({gouge * 1000:.1f} um, limit {limit * 1000:.1f} um)" in doc, out
    assert f"at most {left:.2f} mm of material normal to the surface ({height:.2f} mm above it)" in doc, out
    assert (f"on the {np.degrees(np.arccos(left / height)):.0f} degree flanks (at Y{y:.1f}, beside the edge "
            f"y = {20 if y < 60 else 100})") in doc, out
    assert left > 0.1 and "exceed verify's default `--max-left` of 0.1 mm" in doc
    assert f"in the interior the scallop is {scallop:.3f} mm" in doc, out
    assert (f"worst predicted cusp of {predicted[0]} mm normal to the surface for these rows, at "
            f"X{float(predicted[1]):.1f} Y{float(predicted[2]):.1f} on that edge") in doc, err
    assert float(predicted[2]) == 20.0
    assert status == (0 if left <= 0.1 else 1)
    # Independently: a ball swept along the program's moves, against the exact polynomial, on the cells of
    # the four box edges: nothing is left there beyond a cusp between passes (on flat ground 0.010 mm).
    moves = parse_moves(prog.read_text())
    known = np.asarray(moves.z_known)
    feed = int((known & np.concatenate([[False], known[:-1]]) & ~np.asarray(moves.rapid)).sum())
    assert f"{feed:,} feed moves, 401 x 401 cells" in doc
    assert "simulated 401 x 401 cells" in out
    p = moves.points_mm[np.asarray(moves.z_known)]
    p = p[p[:, 2] < 79.0]
    surf = lagrange_surface(read_points(ex4))
    t = np.linspace(20.0, 100.0, 321)
    for a, b in ((t, np.array([20.0, 20.25])), (t, np.array([99.75, 100.0])),
                 (np.array([20.0, 20.25]), t), (np.array([99.75, 100.0]), t)):
        above = swept_ball(p, 3.0, a, b) - exact_heights(surf, a / 20, b / 20) * 20
        edge = above[:, 0 if b[0] == 20.0 else 1] if len(b) == 2 and len(a) > 2 else above[0 if a[0] == 20.0 else 1]
        assert edge.min() >= -0.002  # no gouge (the swept ball's sampling errs by about 1 um)
        assert edge.max() <= height + 0.01


@pytest.mark.slow
def test_verify_simulates_a_program_with_arcs(run_cli, tmp_path):
    """An arc program (G18 arcs) is simulated: no gouge, and its cut within the tolerance of the same plan's lines."""
    surf = lagrange_surface(read_points(EX2))
    s = MachineSettings(dialect="linuxcnc", mm_per_unit=10.0, safe_z_mm=60.0)
    tp = plan_toolpath(surf, Tool("ball", 6.0), RasterSpec("x", 1.0, None, None, 0.005, arcs=True), s.placement, s.program, stock_to_leave_mm=s.stock_to_leave_mm)
    text = write_program(point_program(tp, s))
    assert "G18 G0" in text and len(tp.arcs) > 50
    f = tmp_path / "arcs.ngc"
    f.write_text(text)
    status, out, err = run_cli("verify", EX2, f, "--scale", "10", "--tool-diameter", "6", "--cell", "0.25",
                               "--max-left", "1")
    assert status == 0, out + err
    arcs = simulate_cut(surf, parse_moves(text), tp.tool, Placement(10.0), cell_mm=0.25)
    lines = simulate_cut(surf, parse_moves(write_program(PointProgram(tp.points_mm, s))), tp.tool, Placement(10.0),
                         cell_mm=0.25)
    assert arcs.gouge_mm <= 0.0005 and not arcs.gouges
    both = np.isfinite(arcs.cut_mm) & np.isfinite(lines.cut_mm)
    assert np.abs(arcs.cut_mm - lines.cut_mm)[both].max() <= 0.005 + 0.001


@pytest.mark.slow
def test_a_finishing_program_with_a_subprogram_call_is_refused_not_verified(run_cli, tmp_path, ex2_program, rs274):
    """``M98 P2000`` inserted into a good program: the call moves the tool (rs274 runs the subprogram after the
    end), so verify refuses it in one line naming the block instead of passing the program without it."""
    from gcheck import interpret

    _, _, _, text = ex2_program
    lines = text.splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("G01")) + 5
    called = lines[:k] + ["M98 P2000"] + lines[k:] + ["O2000", "G01 Z-20. F100.", "M99"]
    doctored = tmp_path / "called.ngc"
    doctored.write_text("\n".join(called) + "\n")
    feeds, _ = interpret(rs274, doctored.read_text())
    assert feeds[:, 2].min() == -20.0  # the subprogram's move, deep in the part
    status, out, err = run_cli("verify", EX2, doctored, "--scale", "10", "--tool-diameter", "6", "--cell", "0.3")
    assert status == 2 and not out, out
    assert err.count("\n") == 1 and f"called.ngc, line {k + 1}: M98 calls a subprogram" in err, err
