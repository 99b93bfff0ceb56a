"""Raster pattern, drop-cutter cutter locations, step control and the Toolpath value."""

from __future__ import annotations

import dataclasses
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lagsym.errors import ToolpathError
from lagsym.grid import grid_from_table
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import MachineSettings, RasterSpec, Tool
from lagsym.toolpath import (
    CL_MARGIN,
    SurfaceEvaluator,
    Toolpath,
    drop_cutter,
    filter_rows,
    plan_toolpath,
    raster_pattern,
    scallop_stepover,
)

from conftest import EXAMPLES


def reference(surface, x, y, radius, shape="ball"):
    """The exact drop-cutter value as the tests define it: a much finer search from many more starts."""
    return drop_cutter(surface, x, y, radius, shape, lattice=24, starts=8, margin=False)


def brute(surface, cx, cy, radius, shape="ball", n=401):
    """A dense lattice over the disc with the barycentric evaluator: a lower bound of the true maximum."""
    x0, x1, y0, y1 = (float(v) for v in surface.grid.bounds)
    t = np.linspace(-radius, radius, n)
    gx, gy = np.meshgrid(t, t)
    inside = gx**2 + gy**2 <= radius**2
    px, py = cx + gx[inside], cy + gy[inside]
    ok = (px >= x0) & (px <= x1) & (py >= y0) & (py <= y1)
    px, py = px[ok], py[ok]
    z = surface.evaluate(px, py)
    if shape == "ball":
        z = z + np.sqrt(np.maximum(radius**2 - (px - cx) ** 2 - (py - cy) ** 2, 0)) - radius
    return float(z.max())


def valley():
    """z = 2 (x - 2)**2 over [0, 4] x [0, 4]: curvature radius 1/4 at the bottom, smaller than the tools used."""
    xs = [Fraction(i) for i in range(5)]
    ys = [Fraction(0), Fraction(4)]
    return lagrange_surface(grid_from_table(xs, ys, [[2 * (x - 2) ** 2] * 2 for x in xs]))


@pytest.fixture(scope="module")
def example4():
    return lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))


def test_evaluator_agrees_with_exact_values(example4):
    ev = SurfaceEvaluator(example4)
    for x, y in [(1, 1), (Fraction(5, 2), Fraction(7, 3)), (5, 5), (Fraction(13, 10), 4)]:
        assert ev(float(x), float(y)) == pytest.approx(float(example4.exact_value(x, y)), abs=1e-12)


def test_point_tool_is_the_surface(example4):
    x, y = np.array([1.0, 2.25, 5.0]), np.array([1.0, 3.5, 5.0])
    z = drop_cutter(example4, x, y, 0.0)
    exact = [float(example4.exact_value(Fraction(a), Fraction(b))) for a, b in zip(x, y)]
    np.testing.assert_allclose(z, exact, atol=1e-12)


def test_ball_on_a_plane_matches_the_closed_form():
    # z = x/2 + y/4: a ball of radius R touches at the foot of the normal, tip at plane + R (sqrt(1 + a^2 + b^2) - 1).
    xs = [Fraction(0), Fraction(10)]
    surf = lagrange_surface(grid_from_table(xs, xs, [[x / 2 + y / 4 for y in xs] for x in xs]))
    r = 1.5
    z = drop_cutter(surf, 5.0, 5.0, r)
    truth = 3.75 + r * (np.sqrt(1 + 0.25 + 0.0625) - 1)
    assert truth <= float(z) <= truth + 1e-5


def test_concave_region_tighter_than_the_tool():
    """A normal offset would put the tip on the valley floor and cut both walls; drop-cutter rests on the walls."""
    surf = valley()
    r = 1.0
    z = float(drop_cutter(surf, 2.0, 2.0, r))
    u = np.linspace(-r, r, 2_000_001)
    truth = float(np.max(2 * u**2 + np.sqrt(r * r - u * u) - r))
    assert truth > 0.3  # the ball stays well above the floor ...
    assert truth <= z <= truth + 1e-5
    normal_offset_tip = 0.0  # ... where the normal offset of the floor point would put it: a gouge of 0.37
    assert z - normal_offset_tip > 0.3


def test_flat_end_takes_the_highest_point_under_it():
    surf = valley()
    z = float(drop_cutter(surf, 2.0, 2.0, 1.0, "flat"))
    assert 2.0 <= z <= 2.0 + 1e-5  # the rim at x = 1 and x = 3


def test_near_the_edge_only_the_surface_inside_the_box_counts():
    # On the valley wall at the box edge x = 4 the ball rests on the surface inside; no extrapolated wall beyond.
    surf = valley()
    z = float(drop_cutter(surf, 4.0, 2.0, 1.0))
    assert z == pytest.approx(brute(surf, 4.0, 2.0, 1.0, n=801), abs=1e-4)
    assert z >= brute(surf, 4.0, 2.0, 1.0, n=801) - 1e-12


def test_positions_outside_the_box_are_refused(example4):
    with pytest.raises(ToolpathError, match="outside"):
        drop_cutter(example4, 5.5, 3.0, 0.1)


heights = st.lists(st.integers(-8, 8), min_size=9, max_size=16)


@st.composite
def surfaces(draw):
    n = draw(st.integers(2, 4))
    m = draw(st.integers(2, 4))
    zs = draw(st.lists(st.lists(st.integers(-6, 6), min_size=m, max_size=m), min_size=n, max_size=n))
    xs = [Fraction(2 * i) for i in range(n)]
    ys = [Fraction(3 * k, 2) for k in range(m)]
    return lagrange_surface(grid_from_table(xs, ys, [[Fraction(v, 2) for v in row] for row in zs]))


@given(surfaces(), st.floats(0.05, 2.5), st.sampled_from(["ball", "flat"]), st.integers(0, 2**31))
def test_cutter_location_never_below_the_exact_value(surf, radius, shape, seed):
    x0, x1, y0, y1 = (float(v) for v in surf.grid.bounds)
    rng = np.random.default_rng(seed)
    x = rng.uniform(x0, x1, 6)
    y = rng.uniform(y0, y1, 6)
    x[0], y[0] = x0, y1  # a corner
    z = drop_cutter(surf, x, y, radius, shape)
    ref = reference(surf, x, y, radius, shape)
    span = 1.0 + radius + max(abs(float(v)) for row in surf.grid.z for v in row)
    assert np.all(z >= ref)
    assert np.all(z <= ref + 100 * CL_MARGIN * span)
    for k in range(2):
        assert z[k] >= brute(surf, x[k], y[k], radius, shape, n=161) - 1e-12 * span


def test_raster_pattern_covers_the_box_with_steps_no_wider_than_asked():
    levels, along = raster_pattern((0, 10, 0, 4), "x", 0.3, 0.7)
    assert levels[0] == 0 and levels[-1] == 4 and np.diff(levels).max() <= 0.3 + 1e-12
    assert along[0] == 0 and along[-1] == 10 and np.diff(along).max() <= 0.7 + 1e-12


def test_filter_keeps_moves_within_the_tolerance():
    t = np.linspace(0, 10, 201)
    z = np.sin(t)
    keep = filter_rows(t, z, 0.01)
    assert keep[0] == 0 and keep[-1] == 200 and len(keep) < 60
    for i, j in zip(keep[:-1], keep[1:]):
        chord = np.interp(t[i:j + 1], [t[i], t[j]], [z[i], z[j]])
        assert np.abs(chord - z[i:j + 1]).max() <= 0.01


def test_scallop_gives_the_side_step():
    assert scallop_stepover(3.0, 0.01) == pytest.approx(2 * np.sqrt(0.06 - 0.0001))
    with pytest.raises(ToolpathError, match="radius"):
        scallop_stepover(1.0, 2.0)


def plan(surf, tool=Tool("ball", 6.0), raster=RasterSpec("x", 2.0, 1.0), **kw):
    settings = MachineSettings(scale=kw.pop("scale", 20.0), **kw)
    return plan_toolpath(surf, tool, raster, settings)


def test_toolpath_is_a_frozen_value_with_read_only_arrays(example4):
    tp = plan(example4)
    assert isinstance(tp, Toolpath)
    with pytest.raises(dataclasses.FrozenInstanceError):
        tp.tool = Tool()
    for a in (tp.points_mm, tp.rows, tp.exact_mm):
        with pytest.raises(ValueError):
            a[0] = 0


def test_zig_zag_rows_alternate_and_stay_in_the_box(example4):
    tp = plan(example4, raster=RasterSpec("y", 2.0, 1.0), origin_mm=(5.0, -3.0, 1.0))
    p = tp.points_mm
    assert p[:, 0].min() == pytest.approx(25.0) and p[:, 0].max() == pytest.approx(105.0)
    assert p[:, 1].min() == pytest.approx(17.0) and p[:, 1].max() == pytest.approx(97.0)
    row0 = p[tp.rows == 0]
    row1 = p[tp.rows == 1]
    assert np.all(np.diff(row0[:, 1]) > 0) and np.all(np.diff(row1[:, 1]) < 0)
    assert np.all(row0[:, 0] == row0[0, 0]) and row1[0, 0] - row0[0, 0] <= 2.0 + 1e-9


def test_point_tool_path_lies_on_the_surface(example4):
    tp = plan(example4, tool=Tool("ball", 0.0), raster=RasterSpec("x", 10.0, 5.0))
    for x, y, z in tp.points_mm[::7]:
        assert tp.exact_mm is not None
        assert z >= float(example4.exact_value(Fraction(x / 20), Fraction(y / 20))) * 20 - 1e-9


@settings(max_examples=12)
@given(surfaces(), st.floats(0.5, 8.0), st.sampled_from(["ball", "flat"]), st.floats(0.005, 0.2),
       st.sampled_from(["x", "y"]))
def test_planned_points_between_exact_value_and_tolerance_above(surf, diameter, shape, tol, direction):
    tp = plan(surf, tool=Tool(shape, diameter), raster=RasterSpec(direction, 3.0, None, None, tol), scale=5.0)
    p = tp.points_mm
    exact = reference(surf, p[:, 0] / 5.0, p[:, 1] / 5.0, diameter / 2 / 5.0, shape) * 5.0
    assert np.all(p[:, 2] >= exact)
    assert np.all(p[:, 2] <= exact + tol + 1e-5)
    x0, x1, y0, y1 = (float(v) * 5.0 for v in surf.grid.bounds)
    assert np.all((p[:, 0] >= x0 - 1e-9) & (p[:, 0] <= x1 + 1e-9) & (p[:, 1] >= y0 - 1e-9) & (p[:, 1] <= y1 + 1e-9))


def test_scallop_and_tolerance_choose_the_steps(example4):
    tp = plan(example4, raster=RasterSpec("x", None, None, 0.02, 0.01), scale=4.0)
    assert tp.stepover_mm <= scallop_stepover(3.0, 0.02) + 1e-12
    assert tp.lift_mm.max() <= 0.01
    with pytest.raises(ToolpathError, match="ball"):
        plan(example4, tool=Tool("flat", 6.0), raster=RasterSpec("x", None, 1.0, 0.02, None))


def test_stock_to_leave_raises_the_ball_by_the_stock_on_a_plane():
    xs = [Fraction(0), Fraction(10)]
    surf = lagrange_surface(grid_from_table(xs, xs, [[Fraction(1)] * 2] * 2))
    a = plan(surf, raster=RasterSpec("x", 5.0, 5.0), scale=1.0)
    b = plan(surf, raster=RasterSpec("x", 5.0, 5.0), scale=1.0, stock_to_leave_mm=0.25)
    np.testing.assert_allclose(b.points_mm[:, 2] - a.points_mm[:, 2], 0.25, atol=1e-9)
