"""lagsym.grid: every check on control points, once, in exact numbers."""

from __future__ import annotations

import dataclasses
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from lagsym.errors import GridError, InputError
from lagsym.grid import ControlGrid, CurvePoints, curve_from_points, grid_from_points, grid_from_table

F = Fraction


def test_points_in_any_order_form_the_papers_matrix():
    g = grid_from_points([(3, 2, 15), (1, 3, 10), (1, 2, 7), (3, 3, 18)], source="p.json")
    assert g.x == (1, 3) and g.y == (2, 3)
    assert g.z == ((7, 10), (15, 18))
    assert g.shape == (2, 2) and g.degree == (1, 1)
    assert g.bounds == (1, 3, 2, 3)
    assert g.z_range() == (7, 18)
    assert g.source == "p.json"
    assert all(isinstance(v, Fraction) for v in (*g.x, *g.y, *g.z[0]))


def test_table_with_decreasing_uneven_nodes_is_stored_increasing():
    g = grid_from_table([F(5, 2), 0, 1], [1, F(-1, 3)], [[25, 26], [0, 1], [10, 11]])
    assert g.x == (0, 1, F(5, 2)) and g.y == (F(-1, 3), 1)
    assert g.z == ((1, 0), (11, 10), (26, 25))


def test_points_list_matches_the_table():
    g = grid_from_table([0, 1], [0, 2], [[1, 2], [3, 4]])
    assert g.points() == [(0, 0, 1), (0, 2, 2), (1, 0, 3), (1, 2, 4)]


@pytest.mark.parametrize(
    "points, message",
    [
        ([], "no control points"),
        ([(0, 0, 1), (0, 1, 1), (1, 0, 1), (0, 0, 2)], r"duplicated grid point \(0, 0\) at points 1 and 4"),
        ([(0, 0, 1), (1, 0, 1)], "all 2 points have y = 0"),
        ([(0, 0, 1), (0, 1, 1), (1, 0, 1)], r"no point at \(x, y\) = \(1, 1\)"),
        ([(0, 0, 1), (0, 1)], r"point 2 \[0, 1\] should be \[x, y, z\]"),
        ([(0, 0, 1.5), (0, 1, 1), (1, 0, 1), (1, 1, 1)], "point 1: 1.5 is not an exact number"),
    ],
)
def test_bad_points_name_the_source_and_the_value(points, message):
    with pytest.raises(InputError, match=message) as e:
        grid_from_points(points, source="pts.csv")
    assert str(e.value).startswith("pts.csv: ")


@pytest.mark.parametrize(
    "x, y, z, error, message",
    [
        ([0], [0, 1], [[1, 2]], GridError, "at least 2 nodes in each direction, got 1 in x and 2 in y"),
        ([0, 1, 0], [0, 1], [[1, 2], [3, 4], [5, 6]], GridError, r"repeated node x = 0 \(entries 0 and 2\)"),
        ([0, 1], [0, 1], [[1, 2]], GridError, "z has 1 rows but x has 2 nodes"),
        ([0, 1], [0, 1], [[1, 2], [3]], GridError, r"z\[1\] has 1 heights but y has 2 nodes"),
        ([0, 1], [0, 1], [[1, 2], "34"], GridError, r"z\[1\] = '34' is not a row of heights"),
        ([0, 1], [0, 0.5], [[1, 2], [3, 4]], InputError, r"y\[1\]: 0.5 is not an exact number"),
        ([0, 1], [0, 1], [[1, 2], [3, True]], InputError, r"z\[1\]\[1\]: True is not an exact number"),
    ],
)
def test_bad_tables_name_the_value(x, y, z, error, message):
    with pytest.raises(error, match=message):
        grid_from_table(x, y, z, source="t.json")


def test_grid_is_frozen_and_its_arrays_read_only():
    g = grid_from_table([0, 1], [0, 1], [[1, 2], [3, 4]])
    with pytest.raises(dataclasses.FrozenInstanceError):
        g.x = (5, 6)
    for a in (g.x_array, g.y_array, g.z_array):
        assert not a.flags.writeable
    assert g.z_array.tolist() == [[1.0, 2.0], [3.0, 4.0]]


def test_with_z_keeps_the_nodes_and_checks_the_heights():
    g = grid_from_table([0, 1], [0, 1], [[1, 2], [3, 4]], source="a.json")
    h = g.with_z([[F(1, 3), 0], [0, 0]])
    assert h.x == g.x and h.y == g.y and h.z[0][0] == F(1, 3)
    assert g.z[0][0] == 1  # a new value, the old one untouched


def test_curve_points_sorted_and_checked():
    c = curve_from_points([(3, 1), (1, 1), (2, 3)], source="c.json")
    assert isinstance(c, CurvePoints)
    assert c.x == (1, 2, 3) and c.y == (1, 3, 1) and c.degree == 2
    with pytest.raises(GridError, match=r"c.json: x = 1 repeats \(points 1 and 3\).*limitation 1"):
        curve_from_points([(1, 0), (2, 0), (1, 5)], source="c.json")
    with pytest.raises(GridError, match="a curve needs at least 2 points, got 1"):
        curve_from_points([(1, 0)], source="c.json")


def test_equal_grids_compare_equal_whatever_their_source():
    a = grid_from_table([0, 1], [0, 1], [[1, 2], [3, 4]], source="a")
    b = grid_from_points([(1, 1, 4), (0, 0, 1), (1, 0, 3), (0, 1, 2)], source="b")
    assert a == b and isinstance(a, ControlGrid)


_rational = st.fractions(min_value=-1000, max_value=1000, max_denominator=1000)


@pytest.mark.slow
@given(st.lists(_rational, min_size=2, max_size=6, unique=True),
       st.lists(_rational, min_size=2, max_size=6, unique=True), st.data())
def test_any_order_of_a_full_grid_gives_the_same_grid(xs, ys, data):
    z = {(x, y): data.draw(_rational) for x in xs for y in ys}
    points = [(x, y, h) for (x, y), h in z.items()]
    shuffled = data.draw(st.permutations(points))
    g = grid_from_points(shuffled)
    assert g.x == tuple(sorted(xs)) and g.y == tuple(sorted(ys))
    for i, x in enumerate(g.x):
        for k, y in enumerate(g.y):
            assert g.z[i][k] == z[(x, y)]
    assert np.array_equal(g.z_array, np.array([[float(v) for v in row] for row in g.z]))
