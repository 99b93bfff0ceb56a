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


def tool_height(d2, radius, corner):
    """Height of a cutter's lower surface above its tip at squared distance ``d2`` from its axis (``inf`` beyond).

    Written here apart from ``lagsym.machine.cutter_profile``: a flat end of
    radius ``radius - corner`` rounded by a quarter circle of ``corner``.
    """
    d = np.sqrt(d2)
    out = np.full(np.shape(d2), np.inf)
    flat = radius - corner
    inside = d <= radius
    out[inside & (d <= flat)] = 0.0
    ring = inside & (d > flat)
    out[ring] = corner - np.sqrt(np.maximum(corner**2 - (d[ring] - flat) ** 2, 0.0))
    return out


def swept_tool(moves, radius, corner, xs, ys, n=201, rounds=7):
    """Lowest point a cutter reaches over each cell centre along the straight moves ``(a, b)`` (tip positions).

    For each move and cell, the tip's position along the move is searched on
    ``n`` points, then ``rounds`` times again on ``n`` points around the best
    found, each time ``n / 4`` times closer.  Every value is the tool's
    height at a real position, so never below the true lowest point; the
    height along a move is convex, so the zooms close in on it.
    """
    gx, gy = (v.ravel() for v in np.meshgrid(xs, ys, indexing="ij"))
    out = np.full(gx.shape, np.inf)
    for a, b in moves:
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        centre, half = np.full(gx.shape, 0.5), np.full(gx.shape, 0.5)
        best = np.full(gx.shape, np.inf)
        for _ in range(rounds + 1):
            t = np.clip(centre[:, None] + half[:, None] * np.linspace(-1.0, 1.0, n)[None, :], 0.0, 1.0)
            p = a[None, None, :] + t[..., None] * (b - a)[None, None, :]
            z = p[..., 2] + tool_height((gx[:, None] - p[..., 0]) ** 2 + (gy[:, None] - p[..., 1]) ** 2, radius, corner)
            k = np.argmin(z, axis=1)
            rows = np.arange(len(k))
            best = np.minimum(best, z[rows, k])
            centre, half = t[rows, k], half * 4.0 / (n - 1)
        out = np.minimum(out, best)
    return out.reshape(len(xs), len(ys))
