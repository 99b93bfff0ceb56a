"""Newton starts for a ball's drop-cutter search, checked against sympy's derivatives and a brute-force search."""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from lagsym.evaluate import surface_evaluator
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.toolpath import CL_MARGIN, drop_cutter
from lagsym.toolpath.newton import newton_ball, surface_jet

from conftest import EXAMPLES
from cutters import brute_ball, steep_flank


@pytest.fixture(scope="module")
def example4():
    return lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))


def test_the_jet_is_the_surface_and_its_derivatives(example4):
    x, y = sympy.symbols("x y")
    f = example4.expr
    parts = [f, f.diff(x), f.diff(y), f.diff(x, 2), f.diff(x, y), f.diff(y, 2)]
    rng = np.random.default_rng(3)
    px, py = rng.uniform(1, 5, 200), rng.uniform(1, 5, 200)
    want = np.array([sympy.lambdify((x, y), p, "numpy")(px, py) * np.ones_like(px) for p in parts])
    got = surface_jet(surface_evaluator(example4), px, py)
    assert np.abs(got - want).max() <= 1e-10 * np.abs(want).max()


def test_newton_only_climbs_and_every_height_is_a_real_contact(example4):
    ev = surface_evaluator(example4)
    box, r = ev.bounds, 0.15
    rng = np.random.default_rng(5)
    cx, cy = rng.uniform(1 - r, 5 + r, 3000), rng.uniform(1 - r, 5 + r, 3000)
    cx, cy = np.clip(cx, 1 - 0.7 * r, 5 + 0.7 * r), np.clip(cy, 1 - 0.7 * r, 5 + 0.7 * r)
    a = rng.uniform(0, 2 * np.pi, cx.size)
    d = r * np.sqrt(rng.uniform(0, 1, cx.size))
    px, py = np.clip(cx + d * np.cos(a), 1, 5), np.clip(cy + d * np.sin(a), 1, 5)
    keep = (px - cx) ** 2 + (py - cy) ** 2 <= r * r
    px, py, cx, cy = px[keep], py[keep], cx[keep], cy[keep]
    height = lambda qx, qy: (example4_values(example4, qx, qy)
                             + np.sqrt(np.maximum(r * r - (qx - cx) ** 2 - (qy - cy) ** 2, 0)) - r)
    v0 = height(px, py)
    qx, qy, val = px.copy(), py.copy(), v0.copy()
    h, done = newton_ball(ev, qx, qy, val, cx, cy, radius=r, box=box, spacing=r / 8, settle=1e-9)
    assert np.all(val >= v0)
    assert np.all((qx >= 1) & (qx <= 5) & (qy >= 1) & (qy <= 5))
    assert np.all((qx - cx) ** 2 + (qy - cy) ** 2 <= r * r)
    assert np.abs(height(qx, qy) - val).max() < 1e-12
    assert done.mean() > 0.5 and np.all(h[done] < r / 8) and np.all(h[~done] == r / 8)


def example4_values(surface, x, y):
    """Heights by the barycentric evaluator, not the Chebyshev one the search uses."""
    from lagsym.evaluate import evaluate_points

    return evaluate_points(surface, x, y)


@pytest.mark.parametrize("row", [0.0, 0.02, 1.5, 3.0, 5.97, 6.0])
def test_a_ball_along_a_row_comes_closer_to_the_brute_force_maximum_than_the_margin_needs(row):
    # Rows past the box, on its edge, near it and inside: contacts inside, on an edge and at a corner.
    surface, f = steep_flank()
    r = 0.3
    cx = np.linspace(-r * 0.9, 6 + r * 0.9, 161)
    cy = np.full(cx.size, row)
    z = drop_cutter(surface, cx, cy, r, margin=False)
    best = brute_ball(f, (0.0, 6.0, 0.0, 6.0), cx, cy, r, n=41, rounds=10)
    span = 1.0 + r + 15.0
    # Within a ten-thousandth of the margin (the pattern search alone stopped up to 6e-4 of it short).
    assert np.all(z >= best - 1e-4 * CL_MARGIN * span)
    assert np.all(z + CL_MARGIN * span >= best)
