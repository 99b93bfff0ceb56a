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


def swept_ball(points_mm, radius_mm, xs_mm, ys_mm, spacing_mm=None):
    """Lowest height a ball's lower surface reaches over each cell centre as it follows the polyline ``points_mm``.

    Written for the tests, apart from lagsym's own simulation: the polyline
    is sampled at ``spacing_mm`` (by default a quarter of the cell) and every
    sample scattered onto the cells of its square footprint with
    ``np.minimum.at``.  Between samples a ball sweeps lower than they show by
    at most ``R - sqrt(R**2 - (spacing / 2)**2)`` plus half the height step.
    """
    p = np.asarray(points_mm, dtype=float)
    hx, hy = xs_mm[1] - xs_mm[0], ys_mm[1] - ys_mm[0]
    spacing = spacing_mm or 0.25 * min(hx, hy)
    seg = np.diff(p, axis=0)
    n = np.maximum(np.ceil(np.hypot(seg[:, 0], seg[:, 1]) / spacing), 1).astype(int)
    k = np.repeat(np.arange(len(seg)), n)
    t = (np.arange(k.size) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    q = np.vstack([p[k] + t[:, None] * seg[k], p[-1:]])
    out = np.full((len(xs_mm), len(ys_mm)), np.inf)
    kx, ky = int(np.ceil(radius_mm / hx)) + 1, int(np.ceil(radius_mm / hy)) + 1
    ox, oy = np.meshgrid(np.arange(-kx, kx + 1), np.arange(-ky, ky + 1), indexing="ij")
    ox, oy = ox.ravel(), oy.ravel()
    for s in range(0, len(q), 4000):
        c = q[s:s + 4000]
        ix = np.rint((c[:, 0] - xs_mm[0]) / hx).astype(int)[:, None] + ox
        iy = np.rint((c[:, 1] - ys_mm[0]) / hy).astype(int)[:, None] + oy
        ok = (ix >= 0) & (ix < len(xs_mm)) & (iy >= 0) & (iy < len(ys_mm))
        ix, iy = np.clip(ix, 0, len(xs_mm) - 1), np.clip(iy, 0, len(ys_mm) - 1)
        d2 = (xs_mm[ix] - c[:, 0:1]) ** 2 + (ys_mm[iy] - c[:, 1:2]) ** 2
        ok &= d2 <= radius_mm**2
        z = c[:, 2:3] + radius_mm - np.sqrt(np.maximum(radius_mm**2 - d2, 0.0))
        np.minimum.at(out, (ix[ok], iy[ok]), z[ok])
    return out


def exact_heights(surface, xs, ys):
    """The surface at every ``(xs[i], ys[j])`` (surface units), from its exact rational values, as floats."""
    from fractions import Fraction

    fx = [Fraction(float(v)) for v in xs]
    fy = [Fraction(float(v)) for v in ys]
    return np.array([[float(surface.exact_value(a, b)) for b in fy] for a in fx])
