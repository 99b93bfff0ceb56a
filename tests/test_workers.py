"""Drop-cutter in worker processes gives the values one process gives."""

from __future__ import annotations

import numpy as np

from lagsym.evaluate import surface_evaluator
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.toolpath import drop_cutter
from lagsym.toolpath.workers import Workers

from conftest import EXAMPLES
from cutters import brute


def test_worker_processes_give_the_same_values_as_one_process():
    surface = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
    ev = surface_evaluator(surface)
    rng = np.random.default_rng(11)
    x, y = rng.uniform(1, 5, 3000), rng.uniform(1, 5, 3000)
    alone = drop_cutter(surface, x, y, 0.15, evaluator=ev)
    with Workers(ev, 2) as workers:
        assert workers.parallel
        shared = drop_cutter(surface, x, y, 0.15, evaluator=ev, workers=workers)
    assert np.array_equal(shared, alone)
    for k in range(3):  # and the values are drop-cutter's: never below a brute-force search
        assert shared[k] >= brute(surface, x[k], y[k], 0.15)


def test_one_process_runs_the_chunks_here():
    ev = surface_evaluator(lagrange_surface(read_points(EXAMPLES / "paper-example-4.json")))
    with Workers(ev, 1) as workers:
        assert not workers.parallel
        assert workers.map(lambda e, a: (e is ev, a), [(1,), (2,)]) == [(True, 1), (True, 2)]
