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


def steep_flank(size=6):
    """A flank rising 67 to 76 degrees across x-rows, hollow across them and tilted along them.

    Returns the surface and the polynomial itself, ``f(x, y)`` in NumPy, for
    checks that must not go through lagsym's evaluators.
    """
    def f(x, y):
        return 2.4 * y + 0.05 * y * y - 0.03 * (x - size / 2) ** 2 + 0.04 * x * y

    def exact(x, y):
        return Fraction(12, 5) * y + Fraction(1, 20) * y * y - Fraction(3, 100) * (x - Fraction(size, 2)) ** 2 \
            + Fraction(1, 25) * x * y

    nodes = [Fraction(0), Fraction(size, 2), Fraction(size)]
    grid = grid_from_table(nodes, nodes, [[exact(x, y) for y in nodes] for x in nodes])
    return lagrange_surface(grid), f


def brute_ball(f, box, cx, cy, radius, n=41, rounds=8):
    """Tip heights of a ball over ``(cx, cy)`` on ``f`` inside ``box``: a lattice over the disc, then zooms on the best.

    Every value is the height of a real contact, so it is never above the
    true drop-cutter value; the zooms bring it to within about ``1e-9`` of it
    where the highest contact is one peak.
    """
    x0, x1, y0, y1 = box
    cx, cy = np.asarray(cx, dtype=float)[:, None], np.asarray(cy, dtype=float)[:, None]
    t = np.linspace(-1.0, 1.0, n)
    gx, gy = (v.ravel()[None, :] for v in np.meshgrid(t, t))
    mx, my, half = cx.copy(), cy.copy(), np.full(cx.shape, float(radius))
    best = np.full(cx.shape[0], -np.inf)
    for _ in range(rounds):
        px, py = np.clip(mx + half * gx, x0, x1), np.clip(my + half * gy, y0, y1)
        dx, dy = px - cx, py - cy
        d = np.hypot(dx, dy)
        out = d > radius
        px = np.where(out, cx + dx * radius / np.where(out, d, 1.0), px)
        py = np.where(out, cy + dy * radius / np.where(out, d, 1.0), py)
        px, py = np.clip(px, x0, x1), np.clip(py, y0, y1)  # the box holds the centre, so the disc stays inside
        d2 = (px - cx) ** 2 + (py - cy) ** 2
        z = f(px, py) + np.sqrt(np.maximum(radius * radius - d2, 0.0)) - radius
        z = np.where(d2 <= radius * radius * (1 + 1e-12), z, -np.inf)
        k = np.argmax(z, axis=1)
        rows = np.arange(len(k))
        best = np.maximum(best, z[rows, k])
        mx, my = px[rows, k][:, None], py[rows, k][:, None]
        half = half * 4.0 / (n - 1)
    return best
