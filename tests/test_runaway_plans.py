"""Finishing plans whose size follows from a scallop height are refused before the work, with the figure.

A job's ``scallop = 0.000001`` walked 29,999 rows for 40 s before the point
limit refused it; waterline and steep-and-shallow at a scallop of 1.1e-6 mm ran
past two minutes and 2.7 GB.  Each now counts, before it plans, at least how
many drop-cutter points the plan takes; the counts are checked here against
the rows a real walk makes and the drop-cutter points a real plan asks for.
"""

from __future__ import annotations

import re
import time

import numpy as np
import pytest

from lagsym import LagsymError
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import Placement, RasterSpec, Tool
from lagsym.toolpath import plan_strategy
from lagsym.toolpath import waterline
from lagsym.toolpath.dropcutter import evaluator_of
from lagsym.toolpath.scallop import TooManyRows, scallop_levels

from conftest import EXAMPLES, ROOT

CASES = [("paper-example-4", "x", 3.0, 0.01, 20.0), ("paper-example-4", "y", 1.0, 0.003, 5.0),
         ("paper-example-3", "x", 6.0, 0.05, 50.0), ("parabola-uneven", "y", 3.0, 0.001, 1.0)]


@pytest.mark.parametrize("name, direction, radius, scallop, mpu", CASES)
def test_the_rows_foreseen_never_exceed_the_rows_walked(name, direction, radius, scallop, mpu):
    ev = evaluator_of(lagrange_surface(read_points(EXAMPLES / f"{name}.json")))
    walked = len(scallop_levels(ev, direction, radius, scallop, mpu).levels)
    with pytest.raises(TooManyRows) as refused:
        scallop_levels(ev, direction, radius, scallop, mpu, max_rows=1)
    assert 0.9 * walked <= refused.value.at_least <= walked  # a lower bound, and a close one
    assert len(scallop_levels(ev, direction, radius, scallop, mpu, max_rows=walked).levels) == walked
    with pytest.raises(TooManyRows):  # past the bound but short of the walk: the walk itself stops at the limit
        scallop_levels(ev, direction, radius, scallop, mpu, max_rows=walked - 1)


@pytest.mark.slow
def test_a_job_with_a_scallop_too_small_for_the_point_limit_is_refused_in_seconds(tmp_path, run_cli):
    job = (EXAMPLES / "example-4-job.toml").read_text()
    job = job[:job.rindex("stepover = 0.5")] + "scallop = 0.000002\nstep = 0.2\n"
    (tmp_path / "paper-example-4.json").write_text((EXAMPLES / "paper-example-4.json").read_text())
    (tmp_path / "job.toml").write_text(job)
    started = time.monotonic()
    status, _, err = run_cli("job", tmp_path / "job.toml", "-o", tmp_path / "job.ngc")
    assert time.monotonic() - started < 30 and not (tmp_path / "job.ngc").exists()
    assert status == 2 and err.count("\n") == 1, err
    found = re.search(r"operations\[1\] \(finish\): at least (\d+) rows of \d+ fine samples is at least (\S+) "
                      r"drop-cutter points, more than the limit of 5e\+06", err)
    assert found and "(--max-points)" in err, err
    doc = " ".join((ROOT / "docs" / "toolpaths.md").read_text().split())
    assert f"at least {found.group(1)} rows, {found.group(2)} points" in doc  # the figures the docs quote


@pytest.mark.slow
@pytest.mark.parametrize("strategy", ["waterline", "steep-shallow"])
def test_waterline_at_a_tiny_scallop_is_refused_before_it_plans(tmp_path, run_cli, strategy):
    started = time.monotonic()
    status, _, err = run_cli("toolpath", EXAMPLES / "paper-example-4.json", "--scale", "20", "--tool-diameter", "6",
                             "--strategy", strategy, "--scallop", "0.0000011", "--safe-z", "80", "--feed", "600",
                             "-o", tmp_path / "o.nc")
    assert time.monotonic() - started < 30 and not (tmp_path / "o.nc").exists()
    assert status == 2 and err.count("\n") == 1, err
    assert f"the {strategy} strategy at a scallop height of 1.1e-06 mm takes at least" in err
    assert "more than the limit of 5e+06" in err and "(--max-points)" in err, err


@pytest.mark.slow
@pytest.mark.parametrize("strategy", ["waterline", "steep-shallow"])
def test_the_points_foreseen_never_exceed_the_points_a_plan_drops(monkeypatch, strategy):
    """The figure refused with is at most what the plan really asks of drop-cutter (counted at its one door)."""
    surface = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
    asked = []
    real_call = waterline._Drop.__call__
    monkeypatch.setattr(waterline._Drop, "__call__", lambda self, x, y, snap=False: (
        asked.append(np.size(x)), real_call(self, x, y, snap))[1])
    foreseen = []
    real_check = waterline.check_strategy_work

    def check_with_no_room(*args, **kwargs):  # the figure the check would refuse with, and the plan goes on
        try:
            real_check(*args, **{**kwargs, "max_points": 1})
        except LagsymError as e:
            foreseen.append(float(re.search(r"takes at least (\S+) drop-cutter points", str(e)).group(1)))
        return real_check(*args, **kwargs)

    monkeypatch.setattr(waterline, "check_strategy_work", check_with_no_room)
    plan_strategy(surface, Tool("ball", 6.0), RasterSpec("y", None, None, 0.02, 0.01), Placement(5.0),
                  strategy=strategy, max_points=None)
    assert len(foreseen) == 1
    foreseen = foreseen[0]
    assert 0 < foreseen <= sum(asked)


def _decimal_rows(n: int) -> str:
    rng = np.random.default_rng(7)
    xs = sorted({round(float(v), 3) for v in np.linspace(0, 50, n) + rng.uniform(0, 0.2, n)})
    return "x,y,z\n" + "".join(f"{a},{b},{(i * j) % 7 / 10}\n" for i, a in enumerate(xs) for j, b in enumerate(xs))


@pytest.mark.parametrize("command", ["compare", "simulate"])
def test_compare_and_simulate_take_the_size_limit_they_name(tmp_path, run_cli, command):
    """Their refusal of a large exact surface named ``--max-exact-mb``, which neither took."""
    path = tmp_path / "g.csv"
    path.write_text(_decimal_rows(20))
    program = tmp_path / "p.nc"
    program.write_text("%\nO1000\nG21 G90\nG01 X1. Y1. Z1. F100.\nM30\n%\n")
    args = [path] if command == "compare" else [program, "--surface", path]
    status, _, err = run_cli(command, *args, "--max-exact-mb", "0.001")
    assert status == 2 and "20 x 20 nodes" in err and "limit of 0.001 MB" in err and "--max-exact-mb" in err, err
    status, _, err = run_cli(command, *args, "--max-exact-mb", "1000")
    assert status == 0, err
