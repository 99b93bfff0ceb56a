"""The plan: the Toolpath value, its zig-zag, and the steps chosen from the raster settings."""

from __future__ import annotations

import dataclasses
import re
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from lagsym.errors import ToolpathError
from lagsym.grid import grid_from_table
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import DEFAULT_TOLERANCE_MM, MachineSettings, RasterSpec, Tool
from lagsym.toolpath import Toolpath, plan_toolpath, scallop_stepover

from conftest import EXAMPLES
from cutters import big_ball_surface, brute, exact_heights, reference, surfaces, swept_ball


@pytest.fixture(scope="module")
def example4():
    return lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))


def plan(surf, tool=Tool("ball", 6.0), raster=RasterSpec("x", 2.0, 1.0), **kw):
    settings = MachineSettings(mm_per_unit=kw.pop("scale", 20.0), **kw)
    return plan_toolpath(surf, tool, raster, settings.placement, settings.program, stock_to_leave_mm=settings.stock_to_leave_mm)


@pytest.mark.slow
def test_toolpath_is_a_frozen_value_with_read_only_arrays(example4):
    tp = plan(example4)
    assert isinstance(tp, Toolpath)
    with pytest.raises(dataclasses.FrozenInstanceError):
        tp.tool = Tool()
    for a in (tp.points_mm, tp.rows, tp.exact_mm):
        with pytest.raises(ValueError):
            a[0] = 0


@pytest.mark.slow
def test_zig_zag_rows_alternate_and_stay_in_the_box(example4):
    tp = plan(example4, raster=RasterSpec("y", 2.0, 1.0, boundary="centre"), origin_mm=(5.0, -3.0, 1.0))
    p = tp.points_mm
    assert p[:, 0].min() == pytest.approx(25.0) and p[:, 0].max() == pytest.approx(105.0)
    assert p[:, 1].min() == pytest.approx(17.0) and p[:, 1].max() == pytest.approx(97.0)
    # A row's points, without the link to the next row (which the row's number also covers).
    row0, row1 = (p[(tp.rows == i) & (p[:, 0] == p[tp.rows == i][0, 0])] for i in (0, 1))
    assert np.all(np.diff(row0[:, 1]) > 0) and np.all(np.diff(row1[:, 1]) < 0)
    assert np.all(row0[:, 0] == row0[0, 0]) and row1[0, 0] - row0[0, 0] <= 2.0 + 1e-9


@pytest.mark.slow
def test_point_tool_path_lies_on_the_surface(example4):
    tp = plan(example4, tool=Tool("ball", 0.0), raster=RasterSpec("x", 10.0, 5.0))
    for x, y, z in tp.points_mm[::7]:
        assert tp.exact_mm is not None
        assert z >= float(example4.exact_value(Fraction(x / 20), Fraction(y / 20))) * 20 - 1e-9


@pytest.mark.slow
@settings(max_examples=12)
@given(surfaces(), st.floats(0.5, 8.0), st.sampled_from(["ball", "flat"]), st.floats(0.005, 0.2),
       st.sampled_from(["x", "y"]))
@example(big_ball_surface(), 7.375, "ball", 0.125, "x")
@example(lagrange_surface(grid_from_table([0, 2, 4], [0, Fraction(3, 2)], [[0, 0], [0, -1], [0, 1]])), 5.25, "flat",
         0.005859375, "y")  # the rim leaves the corner (20, 7.5) mm from an axis beyond the box in y only
@example(lagrange_surface(grid_from_table([0, 2], [0, Fraction(3, 2), 3, Fraction(9, 2)],
                                          [[0, 0, 0, 0], [0, 0, Fraction(5, 2), Fraction(-5, 2)]])), 6.0, "ball",
         0.005000000000000001, "x")  # a ball whose equator leaves the corner (10, 22.5) mm
def test_planned_points_between_exact_value_and_tolerance_above(surf, diameter, shape, tol, direction):
    tp = plan(surf, tool=Tool(shape, diameter), raster=RasterSpec(direction, 3.0, None, None, tol), scale=5.0)
    p = tp.points_mm
    exact = reference(surf, p[:, 0] / 5.0, p[:, 1] / 5.0, diameter / 2 / 5.0, shape) * 5.0
    assert np.all(p[:, 2] >= exact)
    over = p[:, 2] > exact + tol + 1e-4  # the drop-cutter margin: 1e-7 of a span of up to 100 mm
    # Past the boundary (the default) the tool axis stays within the tool radius of the box.
    x0, x1, y0, y1 = (float(v) * 5.0 for v in surf.grid.bounds)
    beyond_x = np.maximum(np.maximum(x0 - p[:, 0], p[:, 0] - x1), 0)
    beyond_y = np.maximum(np.maximum(y0 - p[:, 1], p[:, 1] - y1), 0)
    assert np.all(np.hypot(beyond_x, beyond_y) <= diameter / 2 + 1e-9)
    # More than the tolerance above only where the page says: a cutter beyond the box whose edge (a flat end's
    # rim, a ball's equator) leaves a box corner, so that its height falls by more than the tolerance within one
    # unit of the last decimal and the move cannot be split further; there the point is lifted by the dip found,
    # and no more.
    corner = np.min([np.hypot(p[over, 0] - cx, p[over, 1] - cy) for cx in (x0, x1) for cy in (y0, y1)], axis=0)
    assert np.all(np.maximum(beyond_x[over], beyond_y[over]) > 0)
    assert np.all(np.abs(corner - diameter / 2) <= 0.01)  # the rim at the corner, within ten units of 0.001 mm
    assert np.all(p[over, 2] <= exact[over] + tp.lift_mm[over] + 1e-4)


@pytest.mark.slow
def test_scallop_and_tolerance_choose_the_steps(example4):
    tp = plan(example4, raster=RasterSpec("x", None, None, 0.1, 0.01), scale=4.0)
    # On Example 4's flanks the rows close up to well under the flat floor's side step.
    assert tp.cusp_mm <= 0.1 and len(np.unique(tp.rows)) > 2 * 16 / scallop_stepover(3.0, 0.1)
    assert tp.lift_mm.max() <= 0.01
    with pytest.raises(ToolpathError, match="ball"):
        plan(example4, tool=Tool("flat", 6.0), raster=RasterSpec("x", None, 1.0, 0.02, None))


def test_stock_to_leave_raises_the_ball_by_the_stock_on_a_plane():
    xs = [Fraction(0), Fraction(10)]
    surf = lagrange_surface(grid_from_table(xs, xs, [[Fraction(1)] * 2] * 2))
    a = plan(surf, raster=RasterSpec("x", 5.0, 5.0), scale=1.0)
    b = plan(surf, raster=RasterSpec("x", 5.0, 5.0), scale=1.0, stock_to_leave_mm=0.25)
    np.testing.assert_allclose(b.points_mm[:, 2] - a.points_mm[:, 2], 0.25, atol=1e-9)


@pytest.mark.slow
def test_a_fixed_step_is_the_longest_move_and_points_are_added_where_the_path_bends(example4):
    # Regression: with stepover 2 and step 1 the moves were lifted by up to 0.418 mm where the ball
    # starts to rest on the box edge, and elsewhere by the whole surface's curvature bound.
    tp = plan(example4, raster=RasterSpec("x", 2.0, 1.0, boundary="centre"))
    p = tp.points_mm
    assert tp.lift_mm.max() <= DEFAULT_TOLERANCE_MM + 1e-12
    row = tp.rows[:-1] == tp.rows[1:]
    assert np.hypot(*np.diff(p[:, :2], axis=0)[row].T).max() <= 1.0 + 1e-9
    assert len(tp) > 41 * 81  # points were added
    # Independently: a dense lattice over the tool's disc on the exact polynomial, at points near the edges
    # and halfway along the moves there.
    near = np.flatnonzero((p[:-1, 0] < 26.0) | (p[:-1, 0] > 94.0))[::7]
    exact = reference(example4, p[near, 0] / 20, p[near, 1] / 20, 3.0 / 20) * 20
    assert np.all(p[near, 2] <= exact + DEFAULT_TOLERANCE_MM + 1e-4)  # lifted by at most the tolerance
    for k in near:
        # A lower bound of the true maximum: the points are never below it.
        assert p[k, 2] >= brute(example4, p[k, 0] / 20, p[k, 1] / 20, 3.0 / 20) * 20 - 1e-9
        mid = 0.5 * (p[k] + p[k + 1])
        assert mid[2] >= brute(example4, mid[0] / 20, mid[1] / 20, 3.0 / 20) * 20 - 1e-9  # the move stays above


@pytest.mark.slow
@pytest.mark.parametrize("boundary, reach", [("inside", -3.0), ("centre", 0.0), ("past", 3.0)])
def test_boundary_sets_where_the_tool_axis_goes(example4, boundary, reach):
    tp = plan(example4, tool=Tool("flat", 6.0), raster=RasterSpec("x", 4.0, 2.0, boundary=boundary))
    x, y = tp.points_mm[:, 0], tp.points_mm[:, 1]
    # Past the box by the radius less two units of the program's last decimal (see plan._Cutter).
    assert x.min() == pytest.approx(20.0 - reach, abs=0.0025) and x.max() == pytest.approx(100.0 + reach, abs=0.0025)
    assert y.min() == pytest.approx(20.0 - reach, abs=0.0025) and y.max() == pytest.approx(100.0 + reach, abs=0.0025)
    # Beyond a corner the rows round it: no position further than the reach from the box.
    dx = np.maximum(np.maximum(20.0 - x, x - 100.0), 0.0)
    dy = np.maximum(np.maximum(20.0 - y, y - 100.0), 0.0)
    assert np.hypot(dx, dy).max() <= max(reach, 0.0) + 1e-9


@pytest.mark.slow
def test_past_boundary_finishes_the_edges(example4):
    """Example 4 at scale 10 with a 6 mm ball: its flanks are steep at the box edges.

    With the tool axis kept in the box (``centre``) a ball centred on the edge
    cannot reach the bottom of the slope there; ``past`` finishes it.  Checked
    by a ball swept along the program's moves, written in the tests, against
    the exact polynomial on cells along the box edges.
    """
    scale = 10.0
    xs = np.linspace(10.0, 50.0, 161)
    strips = [(xs, np.array([10.0, 10.25])), (xs, np.array([49.75, 50.0])),
              (np.array([10.0, 10.25]), xs), (np.array([49.75, 50.0]), xs)]  # the swept ball wants even cells
    heights = [exact_heights(example4, a / scale, b / scale) * scale for a, b in strips]
    # The surface's slope at the cells, by central differences of the exact values (one-sided at the box).
    h = 1e-6
    cos = []
    for a, b in strips:
        u, v = a / scale, b / scale
        lo_u, hi_u, lo_v, hi_v = np.clip(u - h, 1, 5), np.clip(u + h, 1, 5), np.clip(v - h, 1, 5), np.clip(v + h, 1, 5)
        fx = (exact_heights(example4, hi_u, v) - exact_heights(example4, lo_u, v)) / (hi_u - lo_u)[:, None]
        fy = (exact_heights(example4, u, hi_v) - exact_heights(example4, u, lo_v)) / (hi_v - lo_v)[None, :]
        cos.append(1.0 / np.sqrt(1.0 + fx**2 + fy**2))
    for boundary in ("centre", "past"):
        tp = plan(example4, raster=RasterSpec("x", 0.5, 0.5, boundary=boundary), scale=scale)
        above = [swept_ball(tp.points_mm, 3.0, a, b) - z for (a, b), z in zip(strips, heights)]
        left = np.concatenate([(d * c).ravel() for d, c in zip(above, cos)])  # normal to the surface
        if boundary == "centre":
            assert max(d.max() for d in above) > 1.0  # the material left at the steep edges (in height)
        else:
            assert min(d.min() for d in above) >= -2e-3  # no gouge (the swept ball's sampling errs by about 1 um)
            # The most left on these strips: 0.37 mm normal to the surface, 0.25 mm inside the edge y = 50 at
            # x = 46.25, in a hollow along x tighter than the ball (radius of curvature 1.6 mm, by second
            # differences of the exact values): no 3 mm ball reaches its bottom.
            assert left.max() <= 0.38
            k = int(np.argmax(above[1] * cos[1]))
            px, py = strips[1][0][k // 2] / scale, strips[1][1][k % 2] / scale
            dx = 1e-3
            f = exact_heights(example4, [px - dx, px, px + dx], [py])[:, 0] * scale
            fxx, fx = (f[0] - 2 * f[1] + f[2]) / (dx * scale) ** 2, (f[2] - f[0]) / (2 * dx * scale)
            assert fxx / (1 + fx**2) ** 1.5 > 1 / 3.0  # curvature along x above the ball's


def _swept_ball_left(points, f, fx, fy, xs, ys, radius, spacing=0.01):
    """Material left above ``f`` at cells ``xs`` x ``ys`` by a ball swept along ``points``, normal to the surface.

    The ball is stamped at most ``spacing`` apart along every move (it lies
    at most ``spacing**2 / 8 R`` below the swept envelope there), and the
    height left is divided by ``sqrt(1 + fx**2 + fy**2)``: the thickness
    along the normal of a thin layer.
    """
    out = [points[:1]]
    for a, b in zip(points[:-1], points[1:]):
        n = max(int(np.ceil(np.hypot(*(b[:2] - a[:2])) / spacing)), 1)
        out.append(a + (b - a) * (np.arange(1, n + 1) / n)[:, None])
    c = np.concatenate(out)
    c[:, 2] += radius
    left = []
    for px in xs:
        near = c[np.abs(c[:, 0] - px) <= radius]
        cut = np.full(ys.shape, np.inf)
        for s in range(0, len(near), 4000):
            q = near[s:s + 4000]
            d2 = (q[:, :1] - px) ** 2 + (q[:, 1:2] - ys[None, :]) ** 2
            z = np.where(d2 <= radius * radius, q[:, 2:] - np.sqrt(np.maximum(radius * radius - d2, 0.0)), np.inf)
            cut = np.minimum(cut, z.min(axis=0))
        left.append((cut - f(px, ys)) / np.sqrt(1 + fx(px, ys) ** 2 + fy(px, ys) ** 2))
    return np.array(left)


@pytest.mark.slow
def test_a_scallop_height_holds_normal_to_the_surface_on_a_steep_flank():
    """Rows from --scallop leave at most that cusp, measured normal to a 67-76 degree flank, and say how much.

    The cusp is measured on a height map of a ball swept along the planned
    points over the polynomial itself.  With the flat-floor side step the same
    request left 0.093 mm, 9.3 times the 0.01 asked.
    """
    from cutters import steep_flank

    surf, f = steep_flank()
    tp = plan(surf, tool=Tool("ball", 2.0), raster=RasterSpec("x", None, 0.25, 0.01, None), scale=1.0)
    xs, ys = np.array([1.5, 3.0, 4.5]), np.arange(1.5, 4.5, 0.002)  # a tool radius and more inside the box
    left = _swept_ball_left(tp.points_mm, f, lambda x, y: -0.06 * (x - 3) + 0.04 * y,
                            lambda x, y: 2.4 + 0.1 * y + 0.04 * x, xs, ys, 1.0)
    assert left.min() >= -1e-6  # no gouge
    assert left.max() <= 0.01 + 1e-6, left.max()
    assert left.max() - 0.0005 <= tp.cusp_mm <= 0.01 + 1e-9, (tp.cusp_mm, left.max())
    assert 0 <= tp.cusp_at_mm[0] <= 6 and 0 <= tp.cusp_at_mm[1] <= 6


@pytest.mark.slow
def test_a_fixed_side_step_states_the_cusp_of_its_rows_on_a_saddle():
    """A ball's fixed side step is given the cusp predicted for its rows, and on a saddle it is what is left.

    Over ``z = 0.3 x y`` (principal curvatures +-0.3 / mm at the middle, a
    hollow along a diagonal that a 3 mm ball barely fits) the cusp between
    rows 0.5 mm apart is the flat floor's, measured on a ball swept along the
    planned points over the polynomial itself: the section across the rows
    is straight.  A prediction from the curvature across the rows of the
    surface the ball centres run on would be 5.4 times too large.
    """
    from lagsym.evaluate import surface_evaluator
    from lagsym.toolpath.scallop import gap_cusps

    xs = [Fraction(-6), Fraction(6)]
    a = Fraction(3, 10)
    surf = lagrange_surface(grid_from_table(xs, xs, [[a * x * y for y in xs] for x in xs]))
    tp = plan(surf, raster=RasterSpec("x", 0.5, 0.25, None, None), scale=1.0)
    assert tp.cusp_mm is not None and tp.hollow_share == 0
    gx, gy = np.array([-0.5, 0.0, 0.5]), np.arange(-1.0, 1.0, 0.002)
    left = _swept_ball_left(tp.points_mm, lambda x, y: 0.3 * x * y, lambda x, y: 0.3 * y, lambda x, y: 0.3 * x,
                            gx, gy, 3.0)
    rows = np.unique(tp.points_mm[np.abs(tp.points_mm[:, 0]) < 6, 1])
    along, cusps = gap_cusps(surface_evaluator(surf), "x", rows, 3.0, 1.0, 0.5)
    near = np.abs(along) <= 1.0
    predicted = np.nanmax(cusps[(rows[:-1] >= -1.5) & (rows[1:] <= 1.5)][:, near])
    assert left.min() >= -1e-6
    assert 0.9 * predicted <= left.max() <= predicted + 1e-4, (left.max(), predicted)
    assert tp.cusp_mm >= predicted


@pytest.mark.slow
def test_the_command_and_the_program_header_state_the_worst_predicted_cusp(run_cli, tmp_path):
    import json

    from cutters import steep_flank

    surf, _ = steep_flank()
    g = surf.grid
    pts = [[float(x), float(y), float(g.z[i][j])] for i, x in enumerate(g.x) for j, y in enumerate(g.y)]
    src = tmp_path / "flank.json"
    src.write_text(json.dumps({"units": "mm", "points": pts}))
    out = tmp_path / "flank.ngc"
    status, _, err = run_cli("toolpath", src, "--tool-diameter", 4, "--scallop", 0.02, "--step", 0.5,
                             "--safe-z", 60, "-o", out)
    assert status == 0, err
    cusp = float(re.search(r"worst predicted cusp ([\d.]+) mm normal to the surface at X[\d.]+ Y[\d.]+", err).group(1))
    assert 0.015 <= cusp <= 0.02
    assert f"(T1 BALL END D4 MM CUSP AT MOST {cusp:.4f} MM NORMAL TO SURFACE)" in out.read_text()
    status, _, err = run_cli("toolpath", src, "--tool-diameter", 4, "--stepover", 1, "--step", 0.5,
                             "--safe-z", 60, "-o", out)
    wider = float(re.search(r"worst predicted cusp ([\d.]+) mm normal to the surface at X[\d.]+ Y[\d.]+", err).group(1))
    assert status == 0 and wider > cusp and f"CUSP AT MOST {wider:.4f} MM NORMAL TO SURFACE" in out.read_text()
    status, _, err = run_cli("toolpath", src, "--tool-shape", "flat", "--tool-diameter", 4, "--stepover", 1,
                             "--step", 0.5, "--safe-z", 60, "-o", out)
    assert status == 0 and "cusp" not in err and "CUSP" not in out.read_text()
