"""docs/paper-errata.md states numbers about the paper's printed equations: recompute each one."""

from __future__ import annotations

import json

import sympy

from lagsym import lagrange_surface, read_points
from lagsym.lagrange import X, Y

from conftest import EXAMPLES, ROOT

PRINTED = json.loads((EXAMPLES / "paper-printed-equations.json").read_text())
DOC = (ROOT / "docs" / "paper-errata.md").read_text()


def _printed(key: str, fixes: dict[str, str] | None = None) -> sympy.Expr:
    text = PRINTED[key]
    for old, new in (fixes or {}).items():
        assert old in text
        text = text.replace(old, new)
    return sympy.sympify(text, locals={"x": X, "y": Y}, rational=True)


def _misses(key: str, expr: sympy.Expr):
    g = read_points(EXAMPLES / f"paper-{key}.json")
    devs = [(abs(expr.subs({X: a, Y: b}) - z), a, b) for a, b, z in g.points()]
    worst = max(devs)
    return float(worst[0]), (worst[1], worst[2]), float(sum(d[0] for d in devs) / len(devs))


def _surface(key: str):
    return lagrange_surface(read_points(EXAMPLES / f"paper-{key}.json"))


def test_examples_1_and_2_agree_with_the_print():
    for key in ("example-1", "example-2"):
        assert sympy.expand(_surface(key).expr - _printed(key)) == 0


def test_example_3_errata():
    s = _surface("example-3")
    assert s.coefficients[1][2] == sympy.Rational(-139, 6)
    assert s.coefficients[1][1] == sympy.Rational(161, 3)
    worst, where, _ = _misses("example-3", _printed("example-3"))
    assert f"**{worst:.4f}**" in DOC and where == (4, 4)
    worst, where, _ = _misses("example-3", _printed("example-3", {"23.1667*x*y ": "23.1667*x*y**2 "}))
    assert f"**{worst:.4f}**" in DOC and where == (4, 4)


def test_example_4_errata():
    s = _surface("example-4")
    terms = s.poly.as_dict()
    assert len(terms) == 25 and "**25**" in DOC
    printed = _printed("example-4")
    assert sympy.Poly(printed, X, Y).degree(X) == 2 and sympy.Poly(printed, X, Y).degree(Y) == 3
    worst, where, _ = _misses("example-4", printed)
    assert f"**{worst:.2f}**" in DOC and where == (5, 5)
    worst, where, mean = _misses("example-4", _printed("example-4", {"1255*x*y": "12.55*x*y", "105*y": "10.5*y"}))
    assert f"**{worst:.4f}**" in DOC and f"**{mean:.4f}**" in DOC and where == (4, 2)
