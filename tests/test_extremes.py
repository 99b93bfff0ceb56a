"""The certified heights check states: never inside the surface's true range, and close to it."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from lagsym.cad.extremes import height_bounds
from lagsym.evaluate import evaluate_grid
from lagsym.io import read_points
from lagsym.lagrange import horner2, lagrange_surface


@pytest.mark.parametrize("name", ["paper-example-2.json", "paper-example-4.json", "probe-12x12.csv"])
def test_the_bounds_hold_every_exact_value_and_close_on_the_samples(name):
    from conftest import EXAMPLES

    s = lagrange_surface(read_points(EXAMPLES / name))
    x0, x1, y0, y1 = s.grid.bounds
    xs, ys = np.linspace(float(x0), float(x1), 301), np.linspace(float(y0), float(y1), 301)
    z = evaluate_grid(s, xs, ys)
    span = float(z.max() - z.min())
    lo, hi = height_bounds(s, reached=(float(z.min()), float(z.max())), tolerance=1e-3 * span)
    # exact values (rational arithmetic, not lagsym's evaluator) at a grid of rational points and around the samples'
    # extremes: none outside the bounds
    f = [Fraction(k, 40) for k in range(41)]
    pts = [(x0 + (x1 - x0) * a, y0 + (y1 - y0) * b) for a in f for b in f]
    for flat in (int(np.argmax(z)), int(np.argmin(z))):
        i, j = divmod(flat, len(ys))
        pts += [(Fraction(xs[i]) + dx, Fraction(ys[j]) + dy) for dx in (Fraction(-1, 1000), 0, Fraction(1, 1000))
                for dy in (Fraction(-1, 1000), 0, Fraction(1, 1000))
                if x0 <= Fraction(xs[i]) + dx <= x1 and y0 <= Fraction(ys[j]) + dy <= y1]
    exact = [horner2(s.coefficients, x, y) for x, y in pts]
    assert Fraction(lo) <= min(exact) and max(exact) <= Fraction(hi)
    # and close: within the tolerance asked (and the pad for rounding) of what the samples reached
    assert hi - z.max() <= 1.001e-3 * span + 1e-9 * np.abs(z).max() + 1e-12
    assert z.min() - lo <= 1.001e-3 * span + 1e-9 * np.abs(z).max() + 1e-12


def test_a_bound_is_kept_when_the_budget_of_patches_is_spent(monkeypatch):
    """Stopped early the bound is looser, never lower than the surface."""
    import lagsym.cad.extremes as ex
    from conftest import EXAMPLES

    s = lagrange_surface(read_points(EXAMPLES / "probe-12x12.csv"))
    x0, x1, y0, y1 = (float(v) for v in s.grid.bounds)
    z = evaluate_grid(s, np.linspace(x0, x1, 301), np.linspace(y0, y1, 301))
    monkeypatch.setattr(ex, "MAX_PATCHES", 3)
    lo, hi = height_bounds(s, reached=(float(z.min()), float(z.max())), tolerance=1e-9)
    assert hi >= z.max() and lo <= z.min()
