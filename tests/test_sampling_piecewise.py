"""Sampling a piecewise surface: the API and `lagsym sample`, against pieces built apart from lagsym."""

from __future__ import annotations

import csv
import io
import math
from fractions import Fraction

import numpy as np
import pytest

from lagsym.io import read_points
from lagsym.sampling import iter_blocks, sample, sample_grid
from lagsym.surfaces.piecewise import piecewise_surface

from conftest import EXAMPLES
from piecewise_check import Reference

PART = EXAMPLES / "part-20x20.csv"


@pytest.fixture(scope="module")
def ref():
    return Reference(PART)


@pytest.fixture(scope="module")
def surface():
    return piecewise_surface(read_points(PART))


def span(ref):
    return float(ref.tables[0].max() - ref.tables[0].min())


def test_sample_is_the_pieces(ref, surface):
    X, Y, Z = sample(surface, 77, 53)  # lines on and between the borders
    assert Z.shape == (77, 53) and not Z.flags.writeable
    assert np.abs(Z - ref(X, Y)).max() <= 1e-12 * span(ref)
    # every node inside the box is hit exactly by a 39 x 39 grid (1 mm over 38 mm): its height, rounded once
    X, Y, Z = sample(surface, 39, 39)
    assert np.array_equal(Z[::2, ::2][:-1, :-1], ref.tables[0][:-1, :-1])


def test_blocks_are_the_sample(surface):
    g = sample_grid(surface, 61, 45)
    whole = sample(surface, grid=g).z
    blocks = list(iter_blocks(surface, g, block_points=100))
    assert len(blocks) > 1
    assert np.array_equal(np.concatenate([b.z for b in blocks]), whole)


def test_a_sub_box_and_a_spacing(ref, surface):
    g = sample_grid(surface, step="0.3", box=(5, "17.5", 2, 11))
    X, Y, Z = sample(surface, grid=g)
    assert (g.nx, g.ny) == (math.ceil(Fraction(25, 2) / Fraction(3, 10)) + 1, 9 * 10 // 3 + 1)
    assert np.abs(Z - ref(X, Y)).max() <= 1e-12 * span(ref)


def test_command_line(tmp_path, ref):
    from lagsym.cli import main

    pieces = tmp_path / "pieces.json"
    assert main(["piecewise", str(PART), "-o", str(pieces)], io.StringIO(), io.StringIO()) == 0
    out, err = io.StringIO(), io.StringIO()
    assert main(["sample", str(pieces), "--nx", "31", "--ny", "23"], out, err) == 0, err.getvalue()
    rows = list(csv.reader(out.getvalue().splitlines()))
    data = np.array([[float(v) for v in r] for r in rows[1:]])
    assert data.shape == (31 * 23, 3)
    assert np.abs(data[:, 2] - ref(data[:, 0], data[:, 1])).max() <= 1e-9 * span(ref)  # CSV keeps 12+ digits
    npy = tmp_path / "s.npy"
    assert main(["sample", str(pieces), "--step", "0.5", "-o", str(npy)], io.StringIO(), io.StringIO()) == 0
    a = np.load(npy)
    assert a.shape == (77 * 77, 3) and np.abs(a[:, 2] - ref(a[:, 0], a[:, 1])).max() <= 1e-12 * span(ref)
    stl = tmp_path / "s.stl"
    assert main(["sample", str(pieces), "--nx", "20", "-o", str(stl)], io.StringIO(), io.StringIO()) == 0
    assert stl.stat().st_size == 84 + 50 * 2 * 19 * 19
    # outside the box: refused in one line without --extrapolate, a warning with it
    out, err = io.StringIO(), io.StringIO()
    assert main(["sample", str(pieces), "--x1", "40"], out, err) == 2
    assert len(err.getvalue().strip().splitlines()) == 1 and "--extrapolate" in err.getvalue()
    out, err = io.StringIO(), io.StringIO()
    assert main(["sample", str(pieces), "--x1", "40", "--nx", "5", "--extrapolate"], out, err) == 0
    assert "extrapolated" in err.getvalue()
