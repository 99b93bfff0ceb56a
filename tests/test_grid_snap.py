"""Grid lines that fall on control nodes exactly: found alike on sorted and unsorted axes, long or short."""

import numpy as np

from lagsym import lagrange_surface, read_points
from lagsym.evaluate import surface_evaluator
from lagsym.evaluate.surface import SurfaceEvaluator


def _naive(nodes, exact, v):
    """Every value against every node, in Python."""
    pairs = [(i, k) for i, value in enumerate(v.tolist()) for k, node in enumerate(nodes.tolist())
             if value == node and exact[k]]
    return [i for i, _ in pairs], [k for _, k in pairs]


def _random_axes(seed: int, count: int = 2000):
    """``count`` random ``(nodes, exact, axis)``: a few quarter-step nodes, most exact, and an axis of nodes, other
    quarter steps, NaN, infinities and -0.0, sorted seven times in ten."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        m = int(rng.integers(1, 8))
        nodes = np.sort(rng.choice(np.arange(-5, 20) / 4, m, replace=False))
        exact = rng.random(m) < 0.8
        v = rng.choice(np.concatenate([nodes, np.arange(-6, 22) / 4, [np.nan, np.inf, -np.inf, -0.0]]),
                       int(rng.integers(0, 200)))
        if rng.random() < 0.7:
            v = np.sort(v)
        yield nodes, exact, v


def test_the_lines_on_nodes_are_those_a_comparison_of_every_pair_finds():
    for nodes, exact, v in _random_axes(1):
        i, k = SurfaceEvaluator._hits(nodes, exact, v)
        assert (i.tolist(), k.tolist()) == _naive(nodes, exact, v)


def test_a_long_sorted_axis_snaps_its_nodes_to_the_control_heights():
    surface = lagrange_surface(read_points("examples/paper-example-4.json"))
    ev = surface_evaluator(surface)
    xs = np.linspace(1, 5, 4001)  # every node of Example 4 (1 to 5 in steps of 1) on a line
    ys = np.concatenate([np.linspace(1, 5, 401), [3.0, 3.0]])
    z = ev.grid(xs, ys)
    heights = surface.grid.z_array
    for a in range(5):
        for b in range(5):
            rows, cols = np.flatnonzero(xs == a + 1), np.flatnonzero(ys == b + 1)
            assert rows.size == 1 and cols.size >= 1
            assert (z[np.ix_(rows, cols)] == heights[a, b]).all()


def test_the_compiled_lookup_finds_the_same_lines_as_a_comparison_of_every_pair():
    for nodes, exact, v in _random_axes(3):
        i, k = SurfaceEvaluator._hits(nodes, exact, v, compiled=True)
        assert (i.tolist(), k.tolist()) == _naive(nodes, exact, v)
