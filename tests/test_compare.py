"""Deviation measures, the Table 1 setting, the rendered tables and ``lagsym compare``."""

from __future__ import annotations

import csv
import io
import json
import math
from fractions import Fraction

import numpy as np
import pytest
from conftest import EXAMPLES, need_opengl
from hypothesis import given
from hypothesis import strategies as st

from lagsym.compare import (
    MEASURES,
    TABLE_FORMATS,
    compare_surfaces,
    deviation_measures,
    render_table,
    sample_axes,
)
from lagsym.errors import InputError
from lagsym.formula import parse_formula
from lagsym.grid import grid_from_table
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface

PARABOLA = EXAMPLES / "parabola.json"
PARABOLA_F = "50 - ((x-20)**2 + (y-20)**2)/20"


@pytest.fixture(scope="module")
def table1():
    """The Table 1 setting: the paraboloid's 5x5 net against the paraboloid, B-spline of degree n-1."""
    grid = read_points(PARABOLA)
    f = parse_formula(PARABOLA_F)
    return grid, f, compare_surfaces(grid, f, degree=4)


def _column(c, name):
    return next(m for m in c.methods if m.name == name)


# --- measures ---------------------------------------------------------------------------------------------------------


def test_measures_by_hand():
    z_f = np.array([[2.0, 4.0, 4.0], [1.0, 5.0, 0.0]])
    z_a = np.array([[2.0, 1.0, 4.0], [2.0, 5.0, 0.5]])
    m = deviation_measures(z_f, z_a, tolerance=0.0)
    assert m.samples == 6
    assert m.deviation_mean == pytest.approx((0 + 3 + 0 - 1 + 0 - 0.5) / 6)
    assert m.deviation_rate == pytest.approx(14.5 / 16)
    assert (m.max_deviation, m.max_location) == (3.0, (1, 2))
    assert (m.min_deviation, m.min_location) == (-1.0, (2, 1))
    assert m.coincided == 3
    assert m.deviation_percentage == pytest.approx(100 * 4.5 / 6)
    assert m.relative_percentage == pytest.approx(100 * 4.5 / 16)
    assert (m.max_abs_deviation, m.max_abs_location) == (3.0, (1, 2))
    assert m.mean_abs_deviation == pytest.approx(4.5 / 6)
    assert m.rms_deviation == pytest.approx(math.sqrt((9 + 1 + 0.25) / 6))
    assert deviation_measures(z_f, z_a, tolerance=0.5).coincided == 4


def test_rate_is_nan_when_the_reference_sums_to_zero():
    m = deviation_measures([1.0, -1.0], [0.5, 0.5])
    assert math.isnan(m.deviation_rate) and m.relative_percentage == 100.0
    assert math.isnan(deviation_measures([0.0, 0.0], [0.5, 0.5]).relative_percentage)


def test_bad_tolerance_and_shapes():
    with pytest.raises(InputError, match="tolerance"):
        deviation_measures([1.0], [1.0], tolerance=-1)
    with pytest.raises(ValueError, match="should match"):
        deviation_measures([1.0, 2.0], [1.0])


@given(st.lists(st.floats(-1e3, 1e3), min_size=1, max_size=30), st.floats(-10, 10))
def test_measures_of_a_constant_offset(values, offset):
    z_f = np.array(values)
    m = deviation_measures(z_f, z_f - offset, tolerance=0.0)
    assert m.rms_deviation == pytest.approx(abs(offset), abs=1e-9)
    assert m.mean_abs_deviation == pytest.approx(abs(offset), abs=1e-9)
    assert m.max_abs_deviation >= m.mean_abs_deviation - 1e-12
    assert m.min_deviation <= m.deviation_mean + 1e-9 <= m.max_deviation + 2e-9


def test_samples_fall_on_the_nodes_exactly():
    g = read_points(PARABOLA)
    xs, ys = sample_axes(g)
    assert set(g.x_array) <= set(xs) and set(g.y_array) <= set(ys)
    with pytest.raises(InputError, match="1 samples in x"):
        sample_axes(g, (1, 5))
    with pytest.raises(InputError, match="more than the limit"):
        sample_axes(g, (5000, 5000))


# --- Table 1's setting ------------------------------------------------------------------------------------------------


def test_lagrange_reproduces_the_parabola_exactly(table1):
    grid, f, c = table1
    s = lagrange_surface(grid)
    for x, y in [(Fraction(1, 3), Fraction(7, 2)), (Fraction(39, 2), 0), (Fraction(-5), Fraction(41))]:
        assert s.exact_value(x, y) == f.exact_value(x, y)
    lag = _column(c, "Lagrange")
    assert np.abs(lag.deviation).max() < 1e-9
    assert lag.measures.coincided == lag.deviation.size


def test_bezier_and_full_degree_bspline_coincide_and_meet_the_corners(table1):
    _, _, c = table1
    bez, bsp = _column(c, "Bezier"), _column(c, "B-spline")
    np.testing.assert_allclose(bez.deviation, bsp.deviation, rtol=0, atol=1e-12)
    for col in (bez, bsp):
        hits = np.argwhere(np.abs(col.deviation) <= c.tolerance)
        assert sorted(map(tuple, hits)) == [(0, 0), (0, 60), (60, 0), (60, 60)]
        assert col.measures.coincided == 4
        # A concave paraboloid lies above its Bernstein approximation: d >= 0, minimum 0 at a corner.
        assert col.measures.min_deviation == 0.0 and col.measures.min_location == (1, 1)
        assert col.measures.max_location == (31, 31)
        assert col.measures.deviation_rate < 1


def test_default_degree_bspline_differs_from_bezier():
    c = compare_surfaces(read_points(PARABOLA), parse_formula(PARABOLA_F), methods=["bezier", "bspline"])
    assert c.bspline_degree == (3, 3)
    assert np.abs(c.methods[0].deviation - c.methods[1].deviation).max() > 0.1


def test_hermite_differs(table1):
    grid, f, c = table1
    piecewise = compare_surfaces(grid, f, methods=["hermite", "bezier"], hermite="piecewise")
    herm, bez = piecewise.methods
    assert np.abs(herm.deviation - bez.deviation).max() > 1.0
    assert herm.measures.max_abs_deviation > 0.1
    # Through every control point: all 25 nodes are samples.
    assert herm.measures.coincided >= 25
    # The corner patch equals the Bezier surface for any quadratic on an evenly spaced net
    # (same end values and end slopes, and the Bernstein image of a quadratic is a quadratic).
    corner = _column(c, "Hermite")
    np.testing.assert_allclose(corner.deviation, _column(c, "Bezier").deviation, rtol=0, atol=1e-9)
    # On an uneven net the corner patch and the Bezier surface part.
    nodes = [0, 4, 15, 30, 40]
    uneven = grid_from_table(nodes, nodes, [[f.exact_value(x, y) for y in nodes] for x in nodes])
    assert read_points(EXAMPLES / "parabola-uneven.json") == uneven
    u = compare_surfaces(uneven, f, methods=["hermite", "bezier"], samples=(41, 41))
    assert np.abs(u.methods[0].deviation - u.methods[1].deviation).max() > 0.1
    assert [m.measures.coincided for m in u.methods] == [4, 4]


def test_comparison_is_frozen_with_read_only_arrays(table1):
    _, _, c = table1
    with pytest.raises(AttributeError):
        c.reference = "x"  # type: ignore[misc]
    for a in (c.xs, c.z_reference, c.methods[0].z, c.methods[0].deviation):
        with pytest.raises(ValueError):
            a[0] = 1.0
    assert set(c.deviations) == {"Lagrange", "Hermite", "Bezier", "B-spline"}


# --- references -------------------------------------------------------------------------------------------------------


def test_measured_points_are_compared_where_they_were_measured(tmp_path):
    f = parse_formula(PARABOLA_F)
    xs, ys = [0, 5, 12.5, 40], [1, 20, 39]
    pts = [[x, y, str(f.exact_value(Fraction(str(x)), y))] for x in xs for y in ys]
    path = tmp_path / "measured.json"
    path.write_text(json.dumps({"points": pts}))
    measured = read_points(path)
    c = compare_surfaces(read_points(PARABOLA), measured)
    assert c.z_reference.shape == (4, 3)
    assert c.xs.tolist() == [0, 5, 12.5, 40]
    assert np.abs(_column(c, "Lagrange").deviation).max() < 1e-9
    with pytest.raises(InputError, match="measured points fix the samples"):
        compare_surfaces(read_points(PARABOLA), measured, samples=(5, 5))
    outside = grid_from_table([0, 41], [0, 1], [[0, 0], [0, 0]], source="far.json")
    with pytest.raises(InputError, match="far.json: measured x = 41 lies outside"):
        compare_surfaces(read_points(PARABOLA), outside)


def test_reference_that_is_not_finite_is_refused():
    with pytest.raises(InputError, match=r"not finite at \(x, y\) = \(20, 0\)"):
        compare_surfaces(read_points(PARABOLA), parse_formula("1/(x-20)"))


def test_bad_choices_name_the_valid_ones():
    g = read_points(PARABOLA)
    with pytest.raises(InputError, match="lagrange, hermite, bezier, bspline"):
        compare_surfaces(g, methods=["coons"])
    with pytest.raises(InputError, match="corner, piecewise"):
        compare_surfaces(g, hermite="c1")
    with pytest.raises(InputError, match="give 'lagrange'"):
        compare_surfaces(g, "bezier")
    c = compare_surfaces(g, samples=(3, 3), methods=["bezier"])
    with pytest.raises(InputError, match="text, markdown, csv, json"):
        render_table(c, "html")


# --- rendering --------------------------------------------------------------------------------------------------------


def test_text_table_is_shaped_like_table_1(table1):
    text = render_table(table1[2], "text")
    lines = text.splitlines()
    assert lines[0] == f"Comparison with f(x, y) = {PARABOLA_F}"
    assert lines[1].split()[-4:] == ["Lagrange", "Hermite", "Bezier", "B-spline"]
    row = next(line for line in lines if line.startswith("Number of coincided points"))
    assert row.split()[-4:] == ["3721", "4", "4", "4"]
    row = next(line for line in lines if line.startswith("Minimum deviation"))
    assert row.split()[-3:] == ["0.0000"] * 3
    assert "|d| <= 1e-06 mm" in text and "degree 4 x 4" in text and "one corner patch" in text


def test_markdown_csv_and_json(table1):
    c = table1[2]
    md = render_table(c, "markdown").splitlines()
    assert md[0] == "| Parameters | Lagrange | Hermite | Bezier | B-spline |"
    assert md[1] == "|---|---:|---:|---:|---:|"
    assert len([line for line in md if line.startswith("| ")]) == 1 + len(MEASURES)
    # Pipes inside a label are escaped, so every row has exactly the header's cells.
    assert all(line.replace("\\|", "").count("|") == 6 for line in md if line.startswith("| "))
    rows = list(csv.reader(io.StringIO(render_table(c, "csv"))))
    assert rows[0] == ["measure", "Lagrange", "Hermite", "Bezier", "B-spline"]
    assert [r[0] for r in rows[1:]] == [key for key, _ in MEASURES]
    doc = json.loads(render_table(c, "json"))
    assert doc["samples"] == [61, 61] and doc["bspline_degree"] == [4, 4] and doc["hermite"] == "corner"
    assert doc["methods"]["Bezier"]["coincided"] == 4
    assert doc["methods"]["Bezier"]["max_location"] == [31, 31]
    assert set(TABLE_FORMATS) == {"text", "markdown", "csv", "json"}


def test_json_writes_null_for_an_undefined_rate():
    g = grid_from_table([0, 1], [0, 1], [[1, -1], [-1, 1]])
    doc = json.loads(render_table(compare_surfaces(g, parse_formula("0*x"), samples=(3, 3)), "json"))
    assert doc["methods"]["Bezier"]["deviation_rate"] is None


# --- the command ------------------------------------------------------------------------------------------------------


def test_cli_default_compares_with_lagrange(run_cli):
    status, out, err = run_cli("compare", EXAMPLES / "paper-example-4.json")
    assert status == 0, err
    assert out.startswith("Comparison with Lagrange surface\n")
    assert "61 x 61 samples" in out


def test_cli_table_1_setting(run_cli, tmp_path):
    target = tmp_path / "table.json"
    status, out, err = run_cli("compare", PARABOLA, "--reference", PARABOLA_F, "--degree", "4", "--samples", "41x41",
                               "--format", "json", "-o", target)
    assert (status, out, err) == (0, "", "")
    doc = json.loads(target.read_text())
    assert doc["samples"] == [41, 41]
    assert [doc["methods"][m]["coincided"] for m in ("Bezier", "B-spline")] == [4, 4]


def test_cli_measured_points_and_methods(run_cli):
    status, out, err = run_cli("compare", PARABOLA, "--reference", PARABOLA, "--methods", "bezier,hermite",
                               "--hermite", "piecewise", "--format", "csv")
    assert status == 0, err
    rows = list(csv.reader(io.StringIO(out)))
    assert rows[0] == ["measure", "Bezier", "Hermite"]
    assert dict((r[0], r[1:]) for r in rows)["coincided"] == ["4", "25"]


@pytest.mark.parametrize(
    "args, message",
    [
        (["--reference", "__import__('os')"], "lagsym: error: formula"),
        (["--reference", "x ^ 2"], "write powers as **"),
        (["--reference", "missing.csv"], "missing.csv: no such file"),
        (["--reference", "1/(x-20)"], "not finite"),
        (["--methods", "bezier,nurbs"], "'nurbs' is not one of lagrange, hermite, bezier, bspline"),
        (["--hermite", "ferguson"], "choose from 'corner', 'piecewise'"),
        (["--format", "html"], "choose from 'text', 'markdown', 'csv', 'json'"),
        (["--samples", "41by41"], "should be NX or NXxNY"),
        (["--samples", "1x5"], "counts from 2 to 10000"),
        (["--tolerance", "-1"], "is out of range: give a number from 0 to 1000 mm"),
        (["--degree", "0"], "argument --degree: '0' is out of range"),
        (["--reference", PARABOLA, "--samples", "5x5"], "measured points fix the samples"),
    ],
)
def test_cli_errors_exit_2_with_one_line(run_cli, args, message):
    status, out, err = run_cli("compare", PARABOLA, *args)
    assert status == 2
    assert message in err
    assert len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_cli_plot_writes_a_deviation_map(run_cli, tmp_path):
    from PIL import Image

    need_opengl("the deviation map")

    target = tmp_path / "d.png"
    status, out, err = run_cli("compare", PARABOLA, "--samples", "21x21", "--plot", target)
    assert status == 0, err
    assert "Deviation rate" in out
    with Image.open(target) as im:
        assert im.size == (1280, 480)  # plot.DEVIATION_WINDOW_SIZE: one row of maps
        px = np.asarray(im.convert("RGB"), dtype=float)
    assert (np.abs(px - px[0, 0]).sum(axis=2) > 30).mean() > 0.05  # something was drawn


def test_cli_plot_refuses_an_unknown_image_type_before_comparing(run_cli, tmp_path):
    status, _, err = run_cli("compare", PARABOLA, "--plot", tmp_path / "d.xyz")
    assert status == 2 and "d.xyz" in err and not (tmp_path / "d.xyz").exists()
