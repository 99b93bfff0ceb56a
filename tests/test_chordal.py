"""Chordal checks: no move of a planned toolpath passes below the true cutter path."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lagsym.grid import grid_from_table
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import MachineSettings, Placement, RasterSpec, Tool
from lagsym.toolpath import drop_cutter, plan_toolpath

from conftest import EXAMPLES
from cutters import surfaces


def plan(surf, tool=Tool("ball", 6.0), raster=RasterSpec("x", 2.0, 1.0), **kw):
    settings = MachineSettings(mm_per_unit=kw.pop("scale", 20.0), **kw)
    return plan_toolpath(surf, tool, raster, settings.placement, settings.program, stock_to_leave_mm=settings.stock_to_leave_mm)


def cl_above_moves(surf, tp, scale, per_move=50, moves=None):
    """How far the true cutter path rises above each straight move, sampled at ``per_move`` points along it."""
    p = tp.points_mm
    m = np.arange(len(p) - 1) if moves is None else moves
    a, b = p[m], p[m + 1]
    u = np.linspace(0.0, 1.0, per_move)
    q = a[:, None, :] + u[None, :, None] * (b - a)[:, None, :]
    r = tp.tool.radius_mm / scale
    cl = drop_cutter(surf, q[..., 0] / scale, q[..., 1] / scale, r, tp.tool.shape) * scale
    return (cl - q[..., 2]).max(axis=1)


def moves_near_edges(tp, within_mm):
    """Moves with an end within ``within_mm`` of the box edge across the move: where the tool meets that edge."""
    p = tp.points_mm
    x0, x1, y0, y1 = tp.bounds_mm
    near_x = np.minimum(p[:, 0] - x0, x1 - p[:, 0]) < within_mm
    near_y = np.minimum(p[:, 1] - y0, y1 - p[:, 1]) < within_mm
    across = (((near_x[:-1] | near_x[1:]) & (p[:-1, 0] != p[1:, 0]))
              | ((near_y[:-1] | near_y[1:]) & (p[:-1, 1] != p[1:, 1])))
    return np.flatnonzero(across)


@pytest.fixture(scope="module")
def example1_corner():
    """Example 1 at scale 10 with a 6 mm ball: the tool rolls onto the steep box edge x = 50 and the corner."""
    surf = lagrange_surface(read_points(EXAMPLES / "paper-example-1.json"))
    tp = plan(surf, raster=RasterSpec("x", None, None, 0.01, 0.005, boundary="centre"), scale=10.0)
    return surf, tp


@pytest.mark.slow
def test_moves_stay_above_the_cutter_path_where_the_tool_meets_an_edge(example1_corner):
    # Regression: on the row y = 39.024 the ball starts to rest on the corner region between two
    # cutter locations 0.22 mm apart, and the move between them cut 0.29 mm below the true path.
    surf, tp = example1_corner
    m = moves_near_edges(tp, 3.0)
    assert len(m) > 1000
    above = cl_above_moves(surf, tp, 10.0, moves=m)
    assert above.max() <= 0.005
    assert above.max() <= 1e-4  # the moves are lifted by the dip found, not merely kept within the tolerance
    assert np.all(tp.lift_mm <= 0.005 + 1e-12)
    # The row nearest y = 39.024 (rows from a scallop height follow the slopes, so not exactly there).
    level = {r: np.median(tp.points_mm[tp.rows == r, 1]) for r in np.unique(tp.rows)}
    nearest = min(level, key=lambda r: abs(level[r] - 39.0244))
    row = (tp.rows == nearest) & (tp.points_mm[:, 0] > 47.0) & (tp.points_mm[:, 0] < 47.4)
    assert abs(level[nearest] - 39.0244) < 0.2 and row.sum() > 2  # cutter locations were added where the path bends


@pytest.mark.slow
def test_moves_along_the_rows_in_the_middle_stay_above_the_cutter_path(example1_corner):
    surf, tp = example1_corner
    rng = np.random.default_rng(7)
    m = np.setdiff1d(np.arange(len(tp) - 1), moves_near_edges(tp, 3.0))
    above = cl_above_moves(surf, tp, 10.0, per_move=20, moves=rng.choice(m, 300, replace=False))
    assert above.max() <= 1e-6


@pytest.mark.slow
def test_example1_program_does_not_gouge_at_the_corner(example1_corner):
    from lagsym.gcode import parse_moves
    from lagsym.post.program import point_program, write_program
    from lagsym.verify import simulate_cut

    surf, tp = example1_corner
    s = MachineSettings(dialect="linuxcnc", mm_per_unit=10.0, safe_z_mm=400.0)
    report = simulate_cut(surf, parse_moves(write_program(point_program(tp, s))), tp.tool, Placement(10.0), cell_mm=0.25)
    assert not report.gouges, report.summary()
    assert report.gouge_mm <= report.gouge_limit_mm


# Derandomized: a random search found the dip in test_known_dip_in_tolerance_mode below (now fixed);
# this property runs the same ten examples every time.
@settings(max_examples=10, derandomize=True)
@given(surfaces(), st.floats(0.5, 3.0), st.sampled_from(["ball", "flat"]), st.sampled_from(["x", "y"]),
       st.sampled_from([None, 0.02]), st.integers(0, 2**31))
@pytest.mark.slow
def test_no_move_dips_below_the_cutter_path(surf, radius, shape, direction, tol, seed):
    _no_move_dips(surf, radius, shape, direction, tol, seed)


def test_known_dip_in_tolerance_mode():
    # Regression: in tolerance mode a move dipped 0.71 um below the cutter path (limit 0.1 um) where the
    # ball meets a box edge; the checks now take the bend between their samples into account.
    surf = lagrange_surface(grid_from_table([0, 2], [0, Fraction(3, 2), 3],
                                            [[Fraction(-5, 2), -1, 1], [Fraction(5, 2), Fraction(5, 2), 3]]))
    _no_move_dips(surf, 1.375, "ball", "y", 0.02, 2)


def _no_move_dips(surf, radius, shape, direction, tol, seed):
    scale = 5.0
    raster = RasterSpec(direction, 3.0, 1.0 if tol is None else None, None, tol)
    tp = plan(surf, tool=Tool(shape, 2 * radius * scale), raster=raster, scale=scale)
    rng = np.random.default_rng(seed)
    rows = rng.choice(np.unique(tp.rows), 2)
    m = np.flatnonzero(np.isin(tp.rows[:-1], rows))
    above = cl_above_moves(surf, tp, scale, per_move=25, moves=m)
    # The moves are lifted by the dip found (with a tolerance, by at most the tolerance): what the
    # planner's own samples miss is far below the program's resolution of 0.001 mm.
    assert above.max() <= 1e-4
    if tol is not None:
        # A move a few units of the program's last decimal long cannot be split; where it still bends more
        # than the tolerance (a flat end's rim leaving a box corner beyond the box: its height falls 0.1 mm
        # within one unit) it is lifted by its dip, as Toolpath.lift_mm and the command's output say.
        p = tp.points_mm
        short = np.hypot(*np.diff(p[:, :2], axis=0).T) < 0.003
        at_short = np.zeros(len(p), dtype=bool)
        at_short[:-1] |= short
        at_short[1:] |= short
        assert tp.lift_mm[~at_short].max() <= tol + 1e-12
