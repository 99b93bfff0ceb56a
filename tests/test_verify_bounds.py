"""Verify never understates: gouge, rapid depth and material left against a brute-force swept ball at 0.01 mm.

The reference (``swept_check``) is the polynomial in the power basis evaluated
by NumPy and a ball swept along each move by golden-section search, on a grid
of 0.01 mm over a window around each defect; it imports nothing from
``lagsym.verify``.
"""

from __future__ import annotations

import numpy as np
import pytest

from lagsym.gcode import parse_moves
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import MachineSettings, Placement, RasterSpec, Tool
from lagsym.toolpath import plan_toolpath
from lagsym.verify import program_resolution_mm, simulate_cut

from conftest import EXAMPLES, README_FINISHING, ROOT, run_example
from swept_check import polynomial_heights, swept_ball_window, window_check

EX2 = EXAMPLES / "paper-example-2.json"
EX4 = EXAMPLES / "paper-example-4.json"
BOX2 = (10.0, 40.0, 10.0, 40.0)  # Example 2 at 10 mm a unit


def program(points, gaps=(), safe_z=60.0):
    """A plain program through ``points`` (mm) at feed, retracting to ``safe_z`` before every index in ``gaps``."""
    lines = ["G21 G90", f"G00 Z{safe_z:.3f}", f"G00 X{points[0][0]:.3f} Y{points[0][1]:.3f}"]
    for k, (x, y, z) in enumerate(points):
        if k in gaps:
            lines += [f"G00 Z{safe_z:.3f}", f"G00 X{x:.3f} Y{y:.3f}"]
        lines.append(f"G01 X{x:.3f} Y{y:.3f} Z{z:.3f} F600.")
    lines += [f"G00 Z{safe_z:.3f}", "M30"]
    return "\n".join(lines) + "\n"


def feed_moves(moves):
    known = np.asarray(moves.z_known)
    use = np.flatnonzero(known & np.concatenate([[False], known[:-1]]) & ~np.asarray(moves.rapid))
    return moves.path_mm[use], moves.path_mm[use + 1]


@pytest.fixture(scope="module")
def ex2_plan():
    surf = lagrange_surface(read_points(EX2))
    s = MachineSettings(dialect="linuxcnc", mm_per_unit=10.0, safe_z_mm=60.0)
    tp = plan_toolpath(surf, Tool("ball", 6.0), RasterSpec("x", 1.0, 0.5), s.placement, s.program,
                       stock_to_leave_mm=s.stock_to_leave_mm)
    return surf, tp


def test_polynomial_reference_is_the_surface():
    from fractions import Fraction

    surf = lagrange_surface(read_points(EX4))
    for x, y in ((53.4, 20.008), (21.3, 97.1), (60.0, 60.0)):
        exact = float(surf.exact_value(Fraction(x) / 20, Fraction(y) / 20)) * 20
        assert abs(polynomial_heights(surf, 20.0, x, y) - exact) < 1e-9


@pytest.mark.slow
def test_a_4_um_gouge_between_the_cells_is_found(ex2_plan):
    """A point 4.5 um below its cutter location, off the cell centres: reported at least as deep as it is."""
    surf, tp = ex2_plan
    p = np.array(tp.points_mm)
    k = int(np.argmin(np.abs(p[:, 0] - 23.3) + np.abs(p[:, 1] - 17.1)))
    p[k, 2] = tp.exact_mm[k] - 0.0045
    text = program(p)
    moves = parse_moves(text)
    report = simulate_cut(surf, moves, tp.tool, Placement(10.0), cell_mm=0.2,
                          program_resolution_mm=program_resolution_mm(text))
    a, b = feed_moves(moves)
    # The ball lowered there touches the slope uphill, near its rim, about 2.3 mm from the point.
    ref = window_check(surf, 10.0, a, b, 3.0, (23.71, 19.35), (0.15, 0.15), step=0.005, box=BOX2)
    assert ref["gouge"] > report.gouge_limit_mm  # a real gouge, beyond what rounding explains
    assert report.gouge_mm >= ref["gouge"] - 1e-7 and report.gouges, report.summary()
    # The deepest point is no more than a hair below what the reference finds near it.
    assert report.gouge_mm <= ref["gouge"] + 2e-4


@pytest.mark.slow
def test_a_deleted_row_shows_as_material_left(ex2_plan):
    surf, tp = ex2_plan
    p, rows = np.array(tp.points_mm), np.asarray(tp.rows)
    gone = int(rows[np.argmin(np.abs(p[:, 1] - 25.0) + np.abs(p[:, 0] - 25.0))])
    keep = rows != gone
    text = program(p[keep], gaps={int(np.flatnonzero(rows[keep] == gone + 1)[0])})
    moves = parse_moves(text)
    report = simulate_cut(surf, moves, tp.tool, Placement(10.0), cell_mm=0.2)
    a, b = feed_moves(moves)
    y_gone = float(np.median(p[rows == gone, 1]))
    ref = window_check(surf, 10.0, a, b, 3.0, (25.0, y_gone), (0.3, 0.6), box=BOX2)
    assert report.left_mm >= ref["left_normal"] - 1e-7 and report.left_height_mm >= ref["left_height"] - 1e-7
    assert report.scallop_mm >= ref["left_normal"] - 1e-7  # the gap is inside, a tool radius from the edges
    assert report.leaves_material and report.fails, report.summary()
    # The same window with the row in place: the missing row's cusp is far above the cusps there.
    full = window_check(surf, 10.0, *feed_moves(parse_moves(program(p))), 3.0, (25.0, y_gone), (0.3, 0.6), box=BOX2)
    assert ref["left_normal"] > 2 * full["left_normal"]


@pytest.mark.slow
def test_a_rapid_through_the_part_is_not_understated(ex2_plan):
    surf, tp = ex2_plan
    p = np.array(tp.points_mm)
    z = float(p[:, 2].max()) - 5.0
    text = program(p[:40]).replace("M30", f"G00 Z{z:.3f}\nG00 X25.117 Y24.913\nG00 Z60.000\nM30")
    moves = parse_moves(text)
    report = simulate_cut(surf, moves, tp.tool, Placement(10.0), cell_mm=0.2)
    assert report.crashes
    # The rapid's own swept ball over a strip around it, then finely around its deepest point.
    start = moves.path_mm[-3]
    a, b = start[None, :], np.array([[25.117, 24.913, z]])
    gx, gy = np.arange(10.0, 40.0, 0.05), np.arange(10.0, 40.0, 0.05)
    near = [gx[(gx >= min(a[0, 0], b[0, 0]) - 3) & (gx <= max(a[0, 0], b[0, 0]) + 3)],
            gy[(gy >= min(a[0, 1], b[0, 1]) - 3) & (gy <= max(a[0, 1], b[0, 1]) + 3)]]
    cut = swept_ball_window(a, b, 3.0, *near)
    X, Y = np.meshgrid(*near, indexing="ij")
    depth = polynomial_heights(surf, 10.0, X, Y) - cut
    i = int(np.argmax(depth))
    fx, fy = np.arange(X.flat[i] - 0.1, X.flat[i] + 0.1, 0.01), np.arange(Y.flat[i] - 0.1, Y.flat[i] + 0.1, 0.01)
    fine = polynomial_heights(surf, 10.0, *np.meshgrid(fx, fy, indexing="ij")) - swept_ball_window(a, b, 3.0, fx, fy)
    assert fine.max() > 1.0
    assert report.rapid_mm >= fine.max() - 1e-7, (report.rapid_mm, fine.max())


@pytest.mark.slow
def test_readme_finishing_material_left_is_not_understated(tmp_path, tmp_path_factory, monkeypatch):
    """The README's finishing program: the cusp on the 76 degree flank at the edge y = 20 is not understated."""
    surf = lagrange_surface(read_points(EX4))
    (tmp_path / "examples").symlink_to(EX4.parent)
    monkeypatch.chdir(tmp_path)
    run_example(README_FINISHING, tmp_path_factory)
    prog = tmp_path / "O1000.nc"
    moves = parse_moves(prog.read_text())
    report = simulate_cut(surf, moves, Tool("ball", 6.0), Placement(20.0))
    a, b = feed_moves(moves)
    box = (20.0, 100.0, 20.0, 100.0)
    ref = window_check(surf, 20.0, a, b, 3.0, (53.4, 20.2), (0.4, 0.2), box=box)
    assert ref["left_normal"] > 0.1  # over verify's default limit
    assert report.left_mm >= ref["left_normal"] and report.left_height_mm >= ref["left_normal_height"] - 0.05
    assert report.leaves_material
    assert report.gouge_mm >= ref["gouge"]
    # Inside, between the passes on the flank.
    inner = window_check(surf, 20.0, a, b, 3.0, (53.6, 23.3), (0.2, 0.2), box=box)
    assert report.scallop_mm >= inner["left_normal"]
    # docs/toolpaths.md quotes the figure and the limit the README's verify line accepts.
    text = " ".join((ROOT / "docs" / "toolpaths.md").read_text().split())
    assert (f"bounds it at {report.left_mm:.4f} mm normal to the surface "
            f"({report.left_height_mm:.4f} mm above it)") in text
    assert 0.1 < report.left_mm <= 0.12
