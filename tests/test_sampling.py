"""Sample grids: domain, density, whole samples and streamed blocks."""

from __future__ import annotations

import dataclasses
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from conftest import EXAMPLES
from lagsym.errors import InputError
from lagsym.evaluate import evaluate_grid, evaluate_points, surface_evaluator
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.sampling import Box, SampleGrid, iter_blocks, sample, sample_grid


@pytest.fixture(scope="module")
def surface():
    return lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))


def test_default_domain_is_the_control_box(surface):
    g = sample_grid(surface, 5, 9)
    assert g.box == Box(Fraction(1), Fraction(5), Fraction(1), Fraction(5))
    assert (g.nx, g.ny, g.size) == (5, 9, 45)
    assert g.xs.tolist() == [1.0, 2.0, 3.0, 4.0, 5.0]
    assert g.ys[0] == 1.0 and g.ys[-1] == 5.0


def test_step_gives_the_spacing_exactly_when_it_divides_the_box(surface):
    g = sample_grid(surface, step="0.05")
    assert (g.nx, g.ny) == (81, 81)
    assert g.spacing == (Fraction(1, 20), Fraction(1, 20))
    assert g.xs[1] == 1.05 and g.xs[7] == 1.35  # each line is the float nearest its exact value


def test_step_that_does_not_divide_keeps_the_spacing_below_it(surface):
    g = sample_grid(surface, dx="0.3", dy=Fraction(3, 2))
    assert (g.nx, g.ny) == (15, 4)
    assert g.spacing[0] <= Fraction(3, 10) and g.spacing[1] <= Fraction(3, 2)
    assert g.xs[-1] == 5.0 and g.ys[-1] == 5.0


@given(st.integers(-10**6, 10**6), st.integers(1, 10**6), st.integers(1, 10**4), st.integers(2, 300))
def test_grid_lines_are_correctly_rounded(num, width, den, n):
    a, b = Fraction(num, den), Fraction(num + width, den)
    g = SampleGrid(Box(a, b, Fraction(0), Fraction(1)), n, 2)
    want = [float(a + (b - a) * i / (n - 1)) for i in range(n)]
    assert g.xs.tolist() == want


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"nx": 1, "ny": 5}, "nx = 1 is too few"),
        ({}, "give nx \\(and ny, if it differs\\) or a spacing"),
        ({"nx": 5, "ny": 5, "step": "0.1"}, "not both"),
        ({"step": "0.1", "dx": "0.2"}, "not both"),
        ({"dx": "0.1"}, "both dx and dy"),
        ({"step": "0"}, "step = 0 should be positive"),
        ({"step": "-1"}, "should be positive"),
        ({"step": "abc"}, "'abc' is not a number"),
        ({"step": "1e-9"}, "use a larger step"),
        ({"nx": 5, "ny": 5, "box": (3, 2, None, None)}, "x0 = 3 should be less than x1 = 2"),
        ({"nx": 5, "ny": 5, "box": (0, None, None, None)}, "extrapolation"),
        ({"nx": 5, "ny": 5, "box": (None, None, None, 5.5)}, "extrapolation"),
        ({"nx": 5, "ny": 5, "box": (float("nan"), None, None, None)}, "not a finite number"),
        ({"nx": 2.5, "ny": 5}, "not a whole number"),
    ],
)
def test_bad_requests_name_the_value(surface, kwargs, words):
    with pytest.raises(InputError, match=words):
        sample_grid(surface, **kwargs)


def test_extrapolation_only_when_asked(surface):
    g = sample_grid(surface, 7, 7, box=("0", "6", None, None), extrapolate=True)
    assert g.box.x0 == 0 and g.box.x1 == 6 and g.box.y1 == 5
    assert not Box(*surface.grid.bounds).contains(g.box)


def test_sample_returns_read_only_ij_arrays(surface):
    X, Y, Z = sample(surface, 4, 3)
    assert X.shape == Y.shape == Z.shape == (4, 3)
    assert X[:, 0].tolist() == [float(Fraction(1) + Fraction(4, 3) * i) for i in range(4)]
    assert Y[0].tolist() == [1.0, 3.0, 5.0]
    assert np.array_equal(Z, evaluate_points(surface, X, Y))
    for a in (X, Y, Z):
        with pytest.raises(ValueError):
            a[0, 0] = 0.0


def test_sample_grid_is_immutable(surface):
    g = sample_grid(surface, 3, 3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        g.nx = 4
    with pytest.raises(ValueError):
        g.xs[0] = 0.0


def test_sample_of_the_control_grid_is_the_control_heights(surface):
    _, _, Z = sample(surface, 5, 5)
    assert Z.tolist() == [[float(v) for v in row] for row in surface.grid.z]


@pytest.mark.parametrize("block_points", [1, 7, 100, 10**6])
def test_blocks_add_up_to_the_whole_sample(surface, block_points):
    g = sample_grid(surface, 23, 17)
    blocks = list(iter_blocks(surface, g, block_points))
    assert [b.start for b in blocks] == sorted({b.start for b in blocks})
    assert all(b.z.size <= max(block_points, g.ny) for b in blocks)
    z = np.concatenate([b.z for b in blocks])
    assert np.array_equal(np.concatenate([b.xs for b in blocks]), g.xs)
    # BLAS may sum a one-row block in another order: the same to rounding, within the bound
    tol = surface_evaluator(surface).error_bound()
    assert np.abs(z - sample(surface, grid=g).z).max() <= tol
    assert np.abs(z - evaluate_grid(surface, g.xs, g.ys)).max() <= tol


def test_one_count_stands_for_both_as_on_the_command_line(run_cli, tmp_path):
    """``sample(s, 3)`` is the 3 x 3 grid ``lagsym sample --nx 3`` writes."""
    import csv

    s = lagrange_surface(read_points(EXAMPLES / "paper-example-1.json"))
    d = sample(s, 3)
    assert np.asarray(d.z).shape == (3, 3)
    status, _, err = run_cli("sample", EXAMPLES / "paper-example-1.json", "--nx", "3", "-o", tmp_path / "s.csv")
    assert status == 0, err
    rows = list(csv.DictReader((tmp_path / "s.csv").open()))
    assert len(rows) == 9
    # Example 1 is z = x**2 + 3*y, exactly, at the corners and the middle of its box [1, 5] x [2, 4].
    for x, y in ((1, 2), (3, 3), (5, 4)):
        assert any(float(r["x"]) == x and float(r["y"]) == y and float(r["z"]) == x * x + 3 * y for r in rows)
    assert sorted(np.asarray(d.z).ravel().tolist()) == sorted(float(r["z"]) for r in rows)
