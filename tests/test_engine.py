"""Grids and their engines: a grid's heights are the bits its points give, in NumPy and compiled alike,
a process loads the compiled kernels only once they pay for their loading, and the policy that decides
it is an object a caller may own, turn off or scope to a block of code."""

from __future__ import annotations

import subprocess
import sys
from fractions import Fraction

import numpy as np
import pytest
from conftest import EXAMPLES

from lagsym.errors import InputError
from lagsym.evaluate import COMPILED_POINTS, Engine, current_engine, surface_evaluator, use_engine
from lagsym.evaluate.engine import PROCESS_ENGINE
from lagsym.evaluate.product import grid_product
from lagsym.grid import grid_from_table
from lagsym.lagrange import lagrange_surface


def _left_to_right(w_row, ty_col) -> float:
    """``w[0] t[0] + w[1] t[1] + ...`` in Python floats, each product rounded, added left to right."""
    s = w_row[0] * ty_col[0]
    for a, b in zip(w_row[1:], ty_col[1:]):
        s = s + a * b
    return s


def _surface(n: int, m: int, seed: int):
    rng = np.random.default_rng(seed)
    xs = sorted({Fraction(int(v), 8) for v in rng.choice(np.arange(-400, 400), n, replace=False)})
    ys = sorted({Fraction(int(v), 7) for v in rng.choice(np.arange(-400, 400), m, replace=False)})
    zs = [[Fraction(int(rng.integers(-999, 999)), 100) for _ in ys] for _ in xs]
    return lagrange_surface(grid_from_table(xs, ys, zs))


@pytest.mark.parametrize("k", list(range(1, 14)))
def test_both_engines_add_every_product_left_to_right(k):
    """Any inner size (the compiled kernel takes 1 to 5 terms, then four at a time), any rows and columns."""
    rng = np.random.default_rng(k)
    for rows, cols in ((1, 3), (3, 2049), (130, 700)):
        w = rng.normal(size=(rows, k)) * 10.0 ** rng.integers(-6, 6, (rows, k))
        ty = rng.normal(size=(k, cols))
        numpy_engine = grid_product(w, ty, compiled=False)
        compiled = grid_product(w, ty, np.full((rows, cols), np.nan), compiled=True)
        assert np.array_equal(numpy_engine, compiled)
        for i, j in zip(rng.integers(0, rows, 200), rng.integers(0, cols, 200)):
            assert compiled[i, j] == _left_to_right(w[i].tolist(), ty[:, j].tolist())


@pytest.mark.parametrize("shape", [(2, 2), (5, 5), (3, 9), (14, 11)])
def test_a_grid_is_the_bits_of_its_points_in_either_engine(shape):
    surface = _surface(*shape, seed=shape[0] * 31 + shape[1])
    ev = surface_evaluator(surface)
    rng = np.random.default_rng(shape[1])
    x0, x1, y0, y1 = ev.bounds
    gx = np.sort(np.concatenate([rng.uniform(x0 - 3, x1 + 3, 597), ev.x_nodes[:3]]))  # control lines: snapped
    gy = np.sort(np.concatenate([rng.uniform(y0 - 3, y1 + 3, 697), ev.y_nodes[-3:]]))
    assert gx.size * gy.size >= COMPILED_POINTS  # large enough for either engine
    X, Y = np.meshgrid(gx, gy, indexing="ij")
    points = ev.points(X, Y)
    for compiled in (False, True):
        z = ev.snap_grid(grid_product(ev.x_factor(gx, compiled), ev.y_basis(gy, compiled), compiled=compiled),
                         gx, gy)
        assert np.array_equal(z, points), compiled
    assert np.array_equal(ev.grid(gx, gy), points)
    # Independent of both engines: exact rational values at a sample of the nodes, within the bound.
    box = (min(x0, gx[0]), max(x1, gx[-1]), min(y0, gy[0]), max(y1, gy[-1]))
    bound = ev.error_bound(box)
    for i, j in zip(rng.integers(0, gx.size, 80), rng.integers(0, gy.size, 80)):
        exact = surface.exact_value(Fraction(float(gx[i])), Fraction(float(gy[j])))
        assert abs(Fraction(float(points[i, j])) - exact) <= bound


def _run(code: str) -> list[str]:
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return done.stdout.split()


PRELUDE = ("import sys, numpy as np; from lagsym import lagrange_surface, read_points; "
           "from lagsym.sampling import sample; from lagsym.evaluate import engine; "
           f"s = lagrange_surface(read_points({str(EXAMPLES / 'paper-example-4.json')!r})); "
           "loaded = lambda: 'numba' in sys.modules; ")


@pytest.mark.slow
def test_one_large_grid_runs_in_numpy_and_the_kernels_load_once_they_pay():
    out = _run(PRELUDE + (
        "engine.PROCESS_ENGINE.load_seconds = 0.2; first = sample(s, 600, 600).z; print(loaded()); calls = 1\n"
        "while not loaded() and calls < 5000:\n"
        "    z = sample(s, 600, 600).z; calls += 1; assert np.array_equal(z, first)\n"
        "print(engine.PROCESS_ENGINE.spent >= 0.2, calls > 2)\n"
        "spent = engine.PROCESS_ENGINE.spent; z = sample(s, 600, 600).z\n"
        "print(np.array_equal(z, first), engine.PROCESS_ENGINE.spent == spent)"))
    assert out == ["False", "True", "True", "True", "True"]


@pytest.mark.slow
def test_loading_the_kernels_first_runs_every_large_batch_compiled():
    out = _run(PRELUDE + (
        "from lagsym.evaluate import load_compiled, evaluate_points; load_compiled(); print(loaded())\n"
        "z = sample(s, 600, 600).z; p = evaluate_points(s, np.linspace(1, 5, 300_000), 2.5)\n"
        "print(engine.PROCESS_ENGINE.spent == 0.0, float(z[0, 0]) == 1.0 and float(z[-1, 0]) == 1.0)"))
    assert out == ["True", "True", "True"]


def test_small_batches_never_count_towards_loading():
    out = _run(PRELUDE + (
        "engine.PROCESS_ENGINE.load_seconds = 0.0\n"
        "for _ in range(5): sample(s, 400, 400)\n"
        "print(loaded(), engine.PROCESS_ENGINE.spent == 0.0)"))
    assert out == ["False", "True"]


def test_writing_one_large_sample_does_not_load_the_kernels(tmp_path):
    """A command's one large grid, streamed to a file in blocks, runs in NumPy: loading would cost more than it saves."""
    out = _run(PRELUDE + (
        "from lagsym.export import write_sample; from lagsym.sampling import sample_grid\n"
        f"write_sample({str(tmp_path / 'a.npy')!r}, s, sample_grid(s, 700, 700))\n"
        "print(loaded(), engine.PROCESS_ENGINE.spent > 0)"))
    assert out == ["False", "True"]
    z = np.load(tmp_path / "a.npy")
    assert z.shape == (490_000, 3)


@pytest.mark.slow
def test_an_engine_turned_off_never_loads_the_kernels_and_gives_the_same_bits():
    """``Engine("numpy")``, given or scoped with use_engine: however long large batches take, no kernel loads."""
    out = _run(PRELUDE + (
        "from lagsym.evaluate import Engine, use_engine, evaluate_points\n"
        "off = Engine('numpy', load_seconds=0.0); first = sample(s, 600, 600, engine=off).z\n"
        "with use_engine(off):\n"
        "    for _ in range(3): z = sample(s, 600, 600).z; p = evaluate_points(s, np.linspace(1, 5, 300_000), 2.5)\n"
        "print(loaded(), np.array_equal(z, first), off.spent > 0, engine.PROCESS_ENGINE.spent == 0.0)\n"
        "on = Engine('compiled'); print(np.array_equal(sample(s, 600, 600, engine=on).z, first), loaded(), on.spent)"))
    assert out == ["False", "True", "True", "True", "True", "True", "0.0"]


def test_each_engine_counts_its_own_time_and_the_context_chooses_the_default():
    surface = _surface(5, 5, seed=5)
    ev = surface_evaluator(surface)
    xs = np.linspace(*ev.bounds[:2], 520)
    ys = np.linspace(*ev.bounds[2:], 520)
    mine, other = Engine("numpy"), Engine("numpy")
    assert current_engine() is PROCESS_ENGINE
    with use_engine(mine) as chosen:
        assert chosen is mine and current_engine() is mine
        z = ev.grid(xs, ys)
        with use_engine(other):
            assert current_engine() is other
        assert current_engine() is mine
    assert current_engine() is PROCESS_ENGINE
    assert mine.spent > 0 and other.spent == 0.0
    for policy in ("numpy", "compiled", "auto"):
        assert np.array_equal(ev.grid(xs, ys, engine=Engine(policy)), z), policy
        X, Y = np.meshgrid(xs, ys, indexing="ij")
        assert np.array_equal(ev.points(X, Y, engine=Engine(policy)), z), policy


def test_the_policies_decide_by_size_and_by_what_was_spent():
    assert not Engine("compiled").use_compiled(COMPILED_POINTS - 1)  # small batches stay in NumPy
    assert Engine("compiled").use_compiled(COMPILED_POINTS)
    assert not Engine("numpy", load_seconds=0.0).use_compiled(10**9)
    cheap = Engine("auto", load_seconds=1.0)
    cheap.record(COMPILED_POINTS - 1, 5.0)  # a small batch's time is not counted
    assert cheap.spent == 0.0
    cheap.record(COMPILED_POINTS, 1.0)
    assert cheap.spent == 1.0 and cheap.use_compiled(COMPILED_POINTS)
    with pytest.raises(InputError, match="engine policy 'fast' is not one of auto, numpy, compiled"):
        Engine("fast")
    with pytest.raises(TypeError):
        with use_engine("numpy"):
            pass


def test_the_command_line_names_the_engine_policies():
    from lagsym.cli import ENGINE_POLICIES
    from lagsym.evaluate.engine import POLICIES

    assert ENGINE_POLICIES == POLICIES


def _sample_command(out, chosen) -> str:
    return ("import sys; from lagsym.cli import main; "
            f"status = main({chosen + ['sample', str(EXAMPLES / 'paper-example-4.json')]!r} "
            f"+ ['--nx', '700', '--ny', '700', '-o', {str(out)!r}, '-q']); "
            "print(status, 'numba' in sys.modules)")


@pytest.mark.slow
@pytest.mark.parametrize("policy, loads", [("compiled", True), ("numpy", False), (None, False)])
def test_engine_option_chooses_how_a_command_evaluates(tmp_path, policy, loads):
    """``lagsym --engine compiled sample``: one large grid runs compiled (auto would not load), the same bytes."""
    out, reference = tmp_path / f"{policy}.npy", tmp_path / "reference.npy"
    assert _run(_sample_command(out, [] if policy is None else ["--engine", policy])) == ["0", str(loads)]
    assert _run(_sample_command(reference, [])) == ["0", "False"]
    assert np.array_equal(np.load(out), np.load(reference))
