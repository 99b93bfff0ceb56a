"""The API's contract with a hostile caller: every refusal a LagsymError naming the value, frozen values frozen."""

from __future__ import annotations

import dataclasses
import math
import pickle
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import lagsym
from lagsym import LagsymError

GRID = [(0, 0, 1), (0, 1, 2), (1, 0, 3), (1, 1, 5), (2, 0, 1), (2, 1, 7)]


def surface():
    return lagsym.lagrange_surface(lagsym.grid_from_points(GRID))


def line_settings(**kw):
    from lagsym.dnc.settings import LineSettings

    return LineSettings(**kw)


# (call, text the message must hold: the offending value)
CASES = {
    "lagrange_basis([1, 1])": (lambda: lagsym.lagrange_basis([1, 1]), "both 1"),
    "lagrange_basis([1, nan])": (lambda: lagsym.lagrange_basis([1, math.nan]), "nan"),
    "simulate(precision=nan)": (lambda: lagsym.simulate("G0 X1.\n", "fanuc", precision=math.nan), "nan"),
    "simulate(max_blocks=-1)": (lambda: lagsym.simulate("G0 X1.\n", "fanuc", max_blocks=-1), "-1"),
    "simulate(max_idle_blocks=0)": (lambda: lagsym.simulate("G0 X1.\n", "fanuc", max_idle_blocks=0), "0"),
    "LineSettings(stopbits='abc')": (lambda: line_settings(stopbits="abc"), "'abc'"),
    "LineSettings(leader=5)": (lambda: line_settings(leader=5), "5"),
    "read_points('a\\x00b')": (lambda: lagsym.read_points("a\x00b"), "'a\\x00b'"),
    "evaluate_points(shapes)": (lambda: lagsym.evaluate_points(surface(), np.zeros((2, 3)), np.zeros((3, 2))),
                                "(2, 3)"),
    "evaluate_points(text)": (lambda: lagsym.evaluate_points(surface(), "a", 1.0), "'a'"),
    "evaluate_grid(not a surface)": (lambda: lagsym.evaluate_grid("s", [0.0], [0.0]), "'s'"),
    "raster_pattern(nan)": (lambda: lagsym.raster_pattern((0, math.nan, 0, 1), "x", 0.1, 0.1), "nan"),
    "raster_pattern(7 PiB)": (lambda: lagsym.raster_pattern((0, 1e6, 0, 1e6), "x", 1e-9, 1e-9), "1e+15"),
    "grid_from_table(furlong)": (lambda: lagsym.grid_from_table([0, 1], [0, 1], [[0, 1], [1, 2]], units="furlong"),
                                 "'furlong'"),
    "parse_moves(Arabic-Indic)": (lambda: lagsym.parse_moves("G1 X\u0661\u0662 Y1. F100.\n"), "U+0661"),
    "simulate(Arabic-Indic)": (lambda: lagsym.simulate("#1=\u0663\nG1 X#1 F100.\n", "fanuc"), "U+0663"),
    "simulate(full width)": (lambda: lagsym.simulate("G1 X\uff11. F100.\n", "fanuc"), "U+FF11"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_refusals_are_lagsym_errors_naming_the_value(name):
    call, shown = CASES[name]
    with pytest.raises(LagsymError) as info:
        call()
    assert shown in str(info.value)
    assert "\n" not in str(info.value)


def test_a_plain_program_still_simulates_after_the_checks():
    sim = lagsym.simulate("G0 X1. Y2.\nG1 Z-1. F100.\n", "fanuc", precision=8.0, max_blocks=10)
    assert [(m.x, m.y, m.z) for m in sim.moves] == [(1.0, 2.0, 0.0), (1.0, 2.0, -1.0)]


@pytest.mark.slow
def test_star_import_gives_the_simulate_function():
    # In a fresh interpreter: the order of imports is what made the subpackage shadow the function.
    code = ("from lagsym import *\nimport lagsym.simulate\n"
            "print(callable(simulate), callable(lagsym.simulate), sorted({'sys', 'importlib', 'annotations', "
            "'TYPE_CHECKING'} & set(dir(lagsym))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["True", "True", "[]"]


def test_simulation_moves_are_read_only():
    sim = lagsym.simulate("G1 X1. F100.\n", "fanuc")
    with pytest.raises(dataclasses.FrozenInstanceError):
        sim.moves.append(1, False, 0.0, 0.0, 0.0, 0.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        sim.moves.appenders()
    assert len(sim.moves) == 1


def _job():
    from lagsym.job.spec import parse_job

    data = {"points": "p.csv", "title": "T", "stock": {"block": [0, 10, 0, 10], "top": 5},
            "tools": {"ball6": {"number": 1, "shape": "ball", "diameter": 6}},
            "operations": [{"kind": "finish", "tool": "ball6", "stepover": 1.0, "step": 0.5}]}
    return parse_job(data, "job.toml", __import__("pathlib").Path("."))


def test_job_values_are_read_only_and_still_work():
    spec = _job()
    for table in (spec.stock, spec.tools, spec.operations[0].options):
        with pytest.raises(TypeError):
            table["x"] = 1
        with pytest.raises(AttributeError):
            table.update({})
    assert isinstance(spec.stock["block"], tuple)
    assert spec.stock == {"block": (0, 10, 0, 10), "top": 5}
    other = dataclasses.replace(spec, notes=("ACCEPTED",), variables="full")
    assert other.notes == ("ACCEPTED",) and other.stock == spec.stock and other.tools["ball6"].number == 1
    op = dataclasses.replace(spec.operations[0], options={"stepover": 2.0})
    assert op.options == {"stepover": 2.0}
    with pytest.raises(TypeError):
        op.options["stepover"] = 3.0
    # Worker processes get the spec by pickle.
    assert pickle.loads(pickle.dumps(spec)) == spec


# Hostile values for every argument of the public functions: the answer is a value or a LagsymError.
HOSTILE = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-10**30, max_value=10**30),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=20),
    st.sampled_from(["a\x00b", "1/0", "1e999999999", "\u0661", "__import__('os').system('touch PWNED')", "", "-",
                     "nan", "inf", "x" * 300]),
    st.lists(st.floats(allow_nan=True), max_size=4), st.just(()), st.just({}), st.just(object()),
)


def _calls():
    from lagsym.dnc.settings import LineSettings

    s = surface()
    return [
        lambda a, b: lagsym.lagrange_basis(a),
        lambda a, b: lagsym.lagrange_basis([0, 1, 2], a),
        lambda a, b: lagsym.lagrange_surface(lagsym.grid_from_points(GRID), x=a),
        lambda a, b: lagsym.lagrange_surface(lagsym.grid_from_points(GRID), y=a),
        lambda a, b: lagsym.grid_from_table([0, 1], [0, 1], [[0, 1], [1, 2]], units=a),
        lambda a, b: lagsym.evaluate_points(s, a, b),
        lambda a, b: lagsym.lagrange_surface(a),
        lambda a, b: lagsym.lagrange_curve(a),
        lambda a, b: lagsym.evaluate_grid(s, a, b),
        lambda a, b: lagsym.raster_pattern((0, a, 0, 1), "x", 0.1, 0.1),
        lambda a, b: lagsym.raster_pattern((0, 1, 0, 1), "x", a, 0.1),
        lambda a, b: lagsym.simulate("G1 X1. F100.\n", "fanuc", precision=a),
        lambda a, b: lagsym.simulate("G1 X1. F100.\n", "fanuc", max_blocks=a),
        lambda a, b: lagsym.simulate(a, "fanuc"),
        lambda a, b: lagsym.parse_moves(a),
        lambda a, b: LineSettings(stopbits=a),
        lambda a, b: LineSettings(leader=a),
        lambda a, b: LineSettings(parity=a),
        lambda a, b: lagsym.read_points(a) if isinstance(a, str) and a not in ("-", "") else None,
    ]


CALLS = _calls()


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(min_value=0, max_value=len(CALLS) - 1), HOSTILE, HOSTILE)
def test_public_functions_answer_hostile_values_with_a_lagsym_error(which, a, b):
    try:
        CALLS[which](a, b)
    except LagsymError as e:
        assert "\n" not in str(e)


def test_a_height_beyond_float64_is_refused_naming_the_point_without_a_numpy_warning():
    import warnings

    s = surface()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # NumPy's "overflow encountered" would be an error here
        for call in (lambda: lagsym.evaluate_points(s, [0.5, 1e300], 0.5),
                     lambda: lagsym.evaluate_grid(s, [0.5, -1e300], [0.5])):
            with pytest.raises(lagsym.InputError, match=r"^the height at x = -?1e\+300, y = 0.5 \(1 of 2 points\) "
                                                        r"is beyond float64's range"):
                call()
        z = lagsym.evaluate_points(s, [0.5, float("nan")], 0.5)  # NaN in, NaN out: not an overflow
        assert np.isfinite(z[0]) and np.isnan(z[1])


def test_the_limits_the_docs_quote_are_the_ones_in_force():
    from pathlib import Path

    from lagsym.dnc.config import MAX_CONFIG_BYTES
    from lagsym.lagrange import MAX_NAME
    from lagsym.toolpath.pattern import MAX_LEVELS

    docs = Path(__file__).resolve().parent.parent / "docs"
    assert f"`MAX_LEVELS` ({MAX_LEVELS:,})" in (docs / "api.md").read_text()
    assert f"at most {MAX_CONFIG_BYTES} bytes, UTF-8 TOML" in (docs / "formats.md").read_text()
    assert f"at most {MAX_NAME} characters" in (docs / "equations.md").read_text()
    # And in force: one past each limit is refused.
    with pytest.raises(LagsymError):
        lagsym.raster_pattern((0, MAX_LEVELS, 0, 1), "x", 1.0, 1.0)
    assert len(lagsym.raster_pattern((0, MAX_LEVELS - 2, 0, 1), "x", 1.0, 1.0)[1]) == MAX_LEVELS - 1
    with pytest.raises(LagsymError):
        lagsym.lagrange_surface(lagsym.grid_from_points(GRID), x="a" * (MAX_NAME + 1))
    assert lagsym.lagrange_surface(lagsym.grid_from_points(GRID), x="a" * MAX_NAME).variables[0] == "a" * MAX_NAME


# Generated programs in every dialect and generated job tables: a value or a LagsymError, nothing else.
GCODE = "GXYZIJKFMNOQ#[]=+-*/.0123456789 \nWHILEDOENDIFGOTO<>LBLFN:CALL\u0661"


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(["fanuc", "haas", "linuxcnc", "heidenhain"]), st.text(alphabet=GCODE, max_size=120))
def test_generated_programs_in_every_dialect_answer_with_a_lagsym_error(dialect, text):
    try:
        lagsym.simulate(text, dialect, max_blocks=2000, max_idle_blocks=1000)
    except LagsymError as e:
        assert "\n" not in str(e)


_LEAF = st.one_of(st.none(), st.booleans(), st.integers(-10**20, 10**20), st.floats(), st.text(max_size=8))
_VALUE = st.recursive(_LEAF, lambda c: st.one_of(st.lists(c, max_size=4), st.dictionaries(
    st.sampled_from(["tool", "kind", "number", "shape", "diameter", "top", "block", "margin", "a"]), c, max_size=4)),
    max_leaves=10)
_KEYS = st.sampled_from(["points", "title", "stock", "tools", "operations", "dialect", "units", "scale", "origin",
                         "work_offset", "program_number", "safe_z", "rapid", "variables"])


@pytest.mark.slow
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.dictionaries(_KEYS, _VALUE, max_size=4), st.booleans())
def test_generated_job_tables_answer_with_a_lagsym_error(changes, onto_a_good_job):
    from pathlib import Path

    from lagsym.job.spec import parse_job

    good = {"points": "p.csv", "stock": {"block": [0, 10, 0, 10], "top": 5},
            "tools": {"b": {"number": 1, "shape": "ball", "diameter": 6}},
            "operations": [{"kind": "finish", "tool": "b"}]}
    try:
        parse_job({**good, **changes} if onto_a_good_job else changes, "j.toml", Path("."))
    except LagsymError as e:
        assert "\n" not in str(e)
