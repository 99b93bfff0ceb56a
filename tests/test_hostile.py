"""Hostile input, second round: code from names, atomic writes, messages that name the value."""

from __future__ import annotations

import dataclasses
import os

import pytest
import sympy

import lagsym
import lagsym.equation
from lagsym import LagsymError, grid_from_points, lagrange_surface, lagrange_curve, curve_from_points
from lagsym.lagrange import LagrangeSurface, lagrange_basis

GRID = [(0, 0, 1), (0, 1, 2), (1, 0, 3), (1, 1, 5), (2, 0, 1), (2, 1, 7)]

EXPLOITS = [
    "__import__('os').system('touch PWNED')",
    "x+__import__('os').system('touch PWNED')",
    "lambda",
    "x y",
    "x\ny",
    "_x",
    "",
    "1x",
    "é",
    "x" * 65,
]


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    yield tmp_path
    assert not (tmp_path / "PWNED").exists()
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("name", EXPLOITS)
def test_surface_names_are_refused_at_construction(in_tmp, name):
    g = grid_from_points(GRID)
    for kwargs in ({"x": name}, {"y": name}, {"x": sympy.Symbol(name) if name else name}):
        with pytest.raises(LagsymError, match="not a plain identifier") as info:
            s = lagrange_surface(g, **kwargs)
            # Were it accepted, these are the routes by which a name became code.
            lagsym.lambdify_surface(s)(1.0, 2.0)
            lagsym.equation.render(s, "latex", digits=3)
            lagsym.equation.render(s, "python")
        assert repr(name)[:40] in str(info.value)


@pytest.mark.parametrize("name", EXPLOITS[:3])
def test_curve_basis_and_replace_refuse_the_names(in_tmp, name):
    pts = curve_from_points([(1, 1), (2, 3), (3, 1)])
    with pytest.raises(LagsymError, match="not a plain identifier"):
        lagrange_curve(pts, x=name)
    with pytest.raises(LagsymError, match="not a plain identifier"):
        lagrange_basis([1, 2, 3], name)
    s = lagrange_surface(grid_from_points(GRID))
    with pytest.raises(LagsymError, match="not a plain identifier"):
        dataclasses.replace(s, variables=("x", name))
    with pytest.raises(LagsymError, match="not a plain identifier"):
        LagrangeSurface(grid=s.grid, coefficients=s.coefficients, variables=(name, "y"))


def test_good_names_still_evaluate_as_the_exact_polynomial(in_tmp):
    g = grid_from_points(GRID)
    u, t = sympy.Symbol("u"), sympy.Symbol("t", real=True)
    for x, y in (("u", "v"), (u, "w2"), (t, "y")):
        s = lagrange_surface(g, x=x, y=y)
        f = lagsym.lambdify_surface(s)
        for px, py, pz in GRID:
            assert f(float(px), float(py)) == pz
        # The Python text is code: run it in an empty namespace and compare with the points.
        ns: dict = {}
        exec(lagsym.equation.render(s, "python"), ns)  # noqa: S102 - the text under test
        for px, py, pz in GRID:
            assert ns["F"](px, py) == pz
