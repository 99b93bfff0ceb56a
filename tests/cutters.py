"""Surfaces and reference values shared by the drop-cutter, chordal and toolpath tests."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from hypothesis import strategies as st

from lagsym.evaluate import evaluate_points
from lagsym.grid import grid_from_table
from lagsym.lagrange import lagrange_surface
from lagsym.toolpath import drop_cutter


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
    z = evaluate_points(surface, px, py)
    if shape == "ball":
        z = z + np.sqrt(np.maximum(radius**2 - (px - cx) ** 2 - (py - cy) ** 2, 0)) - radius
    return float(z.max())


def valley():
    """z = 2 (x - 2)**2 over [0, 4] x [0, 4]: curvature radius 1/4 at the bottom, smaller than the tools used."""
    xs = [Fraction(i) for i in range(5)]
    ys = [Fraction(0), Fraction(4)]
    return lagrange_surface(grid_from_table(xs, ys, [[2 * (x - 2) ** 2] * 2 for x in xs]))


@st.composite
def surfaces(draw):
    n = draw(st.integers(2, 4))
    m = draw(st.integers(2, 4))
    zs = draw(st.lists(st.lists(st.integers(-6, 6), min_size=m, max_size=m), min_size=n, max_size=n))
    xs = [Fraction(2 * i) for i in range(n)]
    ys = [Fraction(3 * k, 2) for k in range(m)]
    return lagrange_surface(grid_from_table(xs, ys, [[Fraction(v, 2) for v in row] for row in zs]))


def big_ball_surface():
    """Strongly curved for its size: under a big ball the highest contact sits on a narrow peak near the rim."""
    zs = [[0, 0, 0, 2], [0, 0, 6, 0], [0, 0, -1, 5], [0, 0, 0, 0]]
    xs = [Fraction(2 * i) for i in range(4)]
    ys = [Fraction(3 * k, 2) for k in range(4)]
    return lagrange_surface(grid_from_table(xs, ys, [[Fraction(v, 2) for v in row] for row in zs]))
