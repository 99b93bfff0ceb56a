"""Large evaluations shared among threads: every value that of one thread, none left running."""

from fractions import Fraction
import threading

import numpy as np
import pytest

from lagsym import lagrange_surface, read_points
from lagsym.evaluate import surface_evaluator, threads
from lagsym.evaluate.surface import grid_product

EXAMPLE = "examples/paper-example-4.json"


@pytest.mark.parametrize("n, per_item, align", [(10**6, 1, 8192), (2000, 2000, 20), (7, 10**6, 3), (0, 1, 1)])
def test_the_parts_cover_the_items_once_in_order_on_block_boundaries(monkeypatch, n, per_item, align):
    monkeypatch.setattr(threads, "available_cores", lambda: 3)
    cuts = threads.parts(n, per_item, align)
    assert cuts[0][0] == 0 and cuts[-1][1] == n
    assert all(a[1] == b[0] for a, b in zip(cuts, cuts[1:]))
    assert all(lo % align == 0 for lo, _ in cuts)
    if n * per_item >= 2 * threads.THREAD_POINTS and n >= 2:
        assert len(cuts) > 1


def test_few_values_take_one_thread(monkeypatch):
    monkeypatch.setattr(threads, "available_cores", lambda: 8)
    assert threads.parts(threads.THREAD_POINTS, 1, 1) == [(0, threads.THREAD_POINTS)]


def test_threaded_points_are_those_of_one_thread_and_within_the_bound(monkeypatch):
    surface = lagrange_surface(read_points(EXAMPLE))
    ev = surface_evaluator(surface)
    rng = np.random.default_rng(7)
    x, y = rng.uniform(1, 5, 3 * threads.THREAD_POINTS), rng.uniform(1, 5, 3 * threads.THREAD_POINTS)
    monkeypatch.setattr(threads, "available_cores", lambda: 3)
    assert len(threads.parts(x.size, 1, 8192)) == 3
    before = threading.active_count()
    shared = ev.points(x, y)
    assert threading.active_count() == before  # the threads end with the call
    monkeypatch.setattr(threads, "available_cores", lambda: 1)
    alone = ev.points(x, y)
    assert np.array_equal(shared, alone)
    bound = ev.error_bound()
    # Independent of both: exact rational evaluation at points of every part.
    for i in np.linspace(0, x.size - 1, 60).astype(int):
        exact = surface.exact_value(Fraction(float(x[i])), Fraction(float(y[i])))
        assert abs(Fraction(float(shared[i])) - exact) <= bound


def test_a_threaded_grid_product_is_that_of_one_thread_and_the_matrix_product(monkeypatch):
    rng = np.random.default_rng(3)
    w, ty = rng.normal(size=(1500, 5)), rng.normal(size=(5, 1300))
    monkeypatch.setattr(threads, "available_cores", lambda: 4)
    assert len(threads.parts(1500, 1300, 30)) == 4
    out = np.full((1500, 1300), np.nan)
    grid_product(w, ty, out)
    monkeypatch.setattr(threads, "available_cores", lambda: 1)
    assert np.array_equal(out, grid_product(w, ty))
    # Every element the dot product of its row and column, to the rounding of a 5-term sum (BLAS may add the
    # terms in another order for a block than for the whole product): against exact rational sums, sampled.
    scale = np.abs(w) @ np.abs(ty)
    gamma = 5 * np.finfo(float).eps / (1 - 5 * np.finfo(float).eps)
    assert np.all(np.abs(out - w @ ty) <= 2 * gamma * scale)
    for i, j in zip(rng.integers(0, 1500, 300), rng.integers(0, 1300, 300)):
        exact = sum(Fraction(float(a)) * Fraction(float(b)) for a, b in zip(w[i], ty[:, j]))
        assert abs(Fraction(float(out[i, j])) - exact) <= Fraction(float(gamma * scale[i, j]))


@pytest.mark.parametrize("failing", [0, 2])
def test_an_error_in_any_part_is_raised_after_every_part_has_ended(failing):
    before = threading.active_count()
    ran = []

    def work(lo, hi):
        if lo == failing:
            raise ValueError(f"part {lo}")
        threading.Event().wait(0.05)  # the other parts still running when the failing one stops
        ran.append(lo)

    with pytest.raises(ValueError, match=f"part {failing}"):
        threads.run_parts(work, [(0, 1), (1, 2), (2, 3)])
    assert sorted(ran) == [p for p in (0, 1, 2) if p != failing]
    assert threading.active_count() == before


def test_blocks_are_each_taken_once_by_the_threads_and_the_calling_thread_takes_its_share(monkeypatch):
    monkeypatch.setattr(threads, "available_cores", lambda: 3)
    taken = []
    callers = set()

    def work(lo, hi):
        taken.append((lo, hi))
        callers.add(threading.get_ident())
        threading.Event().wait(0.002)

    n = 3 * threads.THREAD_POINTS
    threads.run_blocks(work, n, 10_000)
    assert sorted(taken) == [(lo, min(lo + 10_000, n)) for lo in range(0, n, 10_000)]
    assert threading.get_ident() in callers and len(callers) == 3


def test_no_block_is_taken_after_an_error(monkeypatch):
    monkeypatch.setattr(threads, "available_cores", lambda: 2)
    before = threading.active_count()
    taken = []

    def work(lo, hi):
        taken.append(lo)
        if lo == 0:
            raise ValueError("block 0")
        threading.Event().wait(0.01)

    with pytest.raises(ValueError, match="block 0"):
        threads.run_blocks(work, 2 * threads.THREAD_POINTS, 1000)
    assert len(taken) < 10 and threading.active_count() == before


def test_one_thread_runs_the_whole_in_one_call():
    calls = []
    threads.run_blocks(lambda lo, hi: calls.append((lo, hi)), threads.THREAD_POINTS, 1000)
    assert calls == [(0, threads.THREAD_POINTS)]
