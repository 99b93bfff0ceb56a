"""``lagsym curve``: the exact 1-D curve through points."""

from __future__ import annotations

from conftest import EXAMPLES

CURVE3 = EXAMPLES / "paper-curve-3rd.json"


def test_curve_3rd_degree(run_cli):
    assert run_cli("curve", CURVE3) == (0, "y = 5*x**3/6 - 13*x**2/2 + 47*x/3 - 9\n", "")


def test_curve_digits_as_the_paper_prints(run_cli):
    assert run_cli("curve", CURVE3, "--digits", "4")[1] == "y = 0.8333*x**3 - 6.5*x**2 + 15.67*x - 9\n"
