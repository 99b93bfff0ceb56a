"""The guard rail: commands that make something physical refuse a surface that amplifies its points' errors.

The amplification is checked against a brute-force maximum of the tensor
Lebesgue function, evaluated from the Lagrange basis directly in NumPy.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from conftest import EXAMPLES
from lagsym.conditioning import AMPLIFICATION_LIMIT, amplification, check_surface, require_conditioning
from lagsym.errors import ConditioningError
from lagsym.grid import grid_from_table
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface

from test_fit import noisy_grid, _dec


def brute_lebesgue(nodes, t):
    """sum_i |L_i(t)| at every t, the basis evaluated as the plain product formula."""
    nodes = np.asarray(nodes, dtype=float)
    total = np.zeros_like(t)
    for i, xi in enumerate(nodes):
        li = np.ones_like(t)
        for j, xj in enumerate(nodes):
            if j != i:
                li *= (t - xj) / (xi - xj)
        total += np.abs(li)
    return total


@pytest.mark.parametrize("nx, ny", [(3, 3), (5, 5), (8, 8), (9, 9), (12, 7)])
def test_the_amplification_is_the_maximum_of_the_tensor_lebesgue_function(nx, ny):
    xs, ys = list(range(nx)), [2 * k for k in range(ny)]
    a = amplification(grid_from_table(xs, ys, [[0] * ny] * nx))
    tx, ty = np.linspace(0, nx - 1, 20001), np.linspace(0, 2 * (ny - 1), 20001)
    lx, ly = brute_lebesgue(xs, tx), brute_lebesgue(ys, ty)
    brute = lx.max() * ly.max()  # the tensor function is the product, so its maximum is too
    assert brute <= a.value * (1 + 1e-9) and a.value <= brute * (1 + 1e-6)
    assert math.isclose(float(brute_lebesgue(xs, np.array([a.at[0]]))[0]), a.lebesgue_x, rel_tol=1e-9)


def test_the_paper_examples_pass_and_12x12_even_nodes_do_not():
    for name in ("paper-example-1.json", "paper-example-2.json", "paper-example-3.json", "paper-example-4.json",
                 "parabola.json", "parabola-uneven.json"):
        assert require_conditioning(read_points(EXAMPLES / name)).value < 6
    grid = grid_from_table(range(12), range(12), [[0] * 12] * 12, source="g.json")
    with pytest.raises(ConditioningError, match=r"g.json: errors in the points can be amplified up to 2623 times"):
        require_conditioning(grid)
    assert require_conditioning(grid, accept=True).exceeds


def test_check_judges_degree_by_conditioning():
    n = 12
    cheb = [round(50 - 50 * math.cos(math.pi * i / (n - 1)), 4) for i in range(n)]
    from fractions import Fraction

    nodes = [Fraction(str(v)) for v in cheb]
    well = check_surface(lagrange_surface(grid_from_table(nodes, nodes, [[(i * k) % 3 for k in range(n)]
                                                                          for i in range(n)])))
    found = {f.name: f for f in well.findings}
    assert not found["degree_x"].warning and "well-spaced nodes" in found["degree_x"].message
    assert found["amplification"].value < 7 and not found["amplification"].warning
    even = check_surface(lagrange_surface(grid_from_table(range(n), range(n), [[(i * k) % 3 for k in range(n)]
                                                                                for i in range(n)])))
    found = {f.name: f for f in even.findings}
    assert found["degree_x"].warning and found["amplification"].warning
    assert round(found["amplification"].value) == 2623


@pytest.fixture
def noisy(tmp_path):
    src = tmp_path / "probe.csv"
    src.write_text("x,y,z\n" + "".join(f"{_dec(x)},{_dec(y)},{_dec(z)}\n" for x, y, z in noisy_grid()))
    return src


@pytest.mark.parametrize("command, extra", [
    ("toolpath", ()), ("macro", ()), ("sample", ("--nx", "5")), ("export", ()),
    ("rough", ("--stock-above", "2")),
])
def test_commands_refuse_the_noisy_12x12_interpolant_in_one_line(run_cli, tmp_path, noisy, command, extra):
    out_file = tmp_path / ("o.step" if command == "export" else "o.csv" if command == "sample" else "o.nc")
    status, out, err = run_cli(command, noisy, "-o", out_file, *extra)
    assert status == 2 and err.count("\n") == 1 and err.startswith("lagsym: error:"), err
    assert "amplified up to 2623 times" in err and "lagsym fit" in err and "--accept-conditioning" in err
    assert not out_file.exists()


@pytest.mark.slow
def test_job_refuses_and_accepts_with_the_header_note(run_cli, tmp_path, noisy):
    job = tmp_path / "job.toml"
    job.write_text(f'points = "{noisy.name}"\nscale = 1\n[stock]\ntop_above = 2\n'
                   '[tools.ball]\nnumber = 1\nshape = "ball"\ndiameter = 6\n'
                   '[[operations]]\nkind = "finish"\ntool = "ball"\nstepover = 10\nstep = 5\n')
    status, _, err = run_cli("job", job, "-o", tmp_path / "j.nc")
    assert status == 2 and "amplified up to 2623 times" in err
    status, _, err = run_cli("job", job, "-o", tmp_path / "j.nc", "--accept-conditioning")
    assert status == 0, err
    assert "(CONDITIONING 2623X ABOVE 100 ACCEPTED --ACCEPT-CONDITIONING)" in (tmp_path / "j.nc").read_text()


@pytest.mark.slow
def test_the_override_is_recorded_in_the_program_header(run_cli, tmp_path, noisy):
    prog = tmp_path / "p.nc"
    status, _, err = run_cli("toolpath", noisy, "-o", prog, "--accept-conditioning", "--stepover", "10", "--step", "5")
    assert status == 0 and "accepted with --accept-conditioning" in err
    head = prog.read_text().splitlines()[:6]
    assert "(CONDITIONING 2623X ABOVE 100 ACCEPTED --ACCEPT-CONDITIONING)" in head


def test_the_fit_of_the_same_points_passes_the_guard_and_machines(run_cli, tmp_path, noisy):
    surf = tmp_path / "surface.json"
    assert run_cli("fit", noisy, "-o", surf)[0] == 0
    assert require_conditioning(read_points(surf)).value < AMPLIFICATION_LIMIT / 10
    status, _, err = run_cli("toolpath", surf, "-o", tmp_path / "p.nc", "--stepover", "10", "--step", "5")
    assert status == 0 and "CONDITIONING" not in (tmp_path / "p.nc").read_text()
    assert json.loads(surf.read_text())["degree"][0] < 11


def test_a_fit_that_interpolates_is_refused_as_the_interpolant_is(run_cli, tmp_path, noisy):
    surf = tmp_path / "full.json"
    status, out, err = run_cli("fit", noisy, "--degree", "11", "-o", surf)
    assert status == 0 and "this fit amplifies errors in the points up to" in err
    amp = json.loads(surf.read_text())["amplification"]
    assert 0.9 * 2623 < amp <= 2623 * (1 + 1e-9)  # sampled, so at most the exact interpolant's figure
    status, _, err = run_cli("toolpath", surf, "-o", tmp_path / "p.nc")
    assert status == 2 and "by this least-squares fit" in err and "--degree auto" in err
    status, out, _ = run_cli("check", surf)
    assert "WARNING surface amplification of errors in the measured points it was fitted to" in out


def test_the_override_is_recorded_in_the_macro_header(run_cli, tmp_path, noisy):
    prog = tmp_path / "m.ngc"
    status, _, err = run_cli("macro", noisy, "--dialect", "linuxcnc", "--tool-diameter", "0", "--safe-z", "100",
                             "--stepover", "10", "--step", "10", "-o", prog, "--accept-conditioning")
    assert status == 0, err
    assert "(CONDITIONING 2623X ABOVE 100 ACCEPTED --ACCEPT-CONDITIONING)" in prog.read_text().splitlines()[:8]


def checkerboard(tmp_path):
    """7 x 7 nodes of 0 and 1 alternating: well-spaced enough (amplification 20.7), but the interpolant swings
    between them far beyond its points' heights."""
    src = tmp_path / "checker.json"
    n = 7
    src.write_text(json.dumps({"x": [2 * i for i in range(n)], "y": [2 * k for k in range(n)],
                               "z": [[(i + k) % 2 for k in range(n)] for i in range(n)]}))
    return src


def brute_interpolant(nodes, z, t):
    """The interpolant on the grid ``t x t``, from the Lagrange basis as the plain product formula."""
    nodes = np.asarray(nodes, dtype=float)
    basis = np.array([np.prod([(t - xj) / (xi - xj) for j, xj in enumerate(nodes) if j != i], axis=0)
                      for i, xi in enumerate(nodes)])
    return basis.T @ np.asarray(z, dtype=float) @ basis


def test_the_checkerboard_really_leaves_its_heights_by_more_than_their_range():
    n = 7
    swing = brute_interpolant([2 * i for i in range(n)], [[(i + k) % 2 for k in range(n)] for i in range(n)],
                              np.linspace(0, 12, 1201))
    assert swing.max() - 1 > 1.0 or 0 - swing.min() > 1.0  # more than the whole range of 1 beyond it


@pytest.mark.parametrize("command, extra", [
    ("toolpath", ("--tool-diameter", "2")), ("macro", ("--tool-diameter", "2")), ("sample", ("--nx", "5")),
    ("export", ()), ("rough", ("--stock-above", "2", "--tool-diameter", "4")),
])
def test_commands_refuse_a_surface_that_overshoots_its_points_by_more_than_their_range(run_cli, tmp_path, command,
                                                                                         extra):
    src = checkerboard(tmp_path)
    assert amplification(read_points(src)).value < AMPLIFICATION_LIMIT
    out_file = tmp_path / ("o.step" if command == "export" else "o.csv" if command == "sample" else "o.nc")
    status, out, err = run_cli(command, src, "-o", out_file, *extra)
    assert status == 2 and err.count("\n") == 1 and err.startswith("lagsym: error:"), err
    assert "leaves its points' heights by up to 7.099 between them (710% of their range 1, certified" in err
    assert "lagsym fit" in err and "--accept-conditioning" in err and not out_file.exists()


def test_an_overshoot_accepted_is_said_and_recorded_in_the_program_header(run_cli, tmp_path):
    src = checkerboard(tmp_path)
    status, out, err = run_cli("toolpath", src, "--tool-diameter", "2", "--stepover", "2", "-o", tmp_path / "o.nc",
                               "--accept-conditioning")
    assert status == 0 and "above the limit of 100%: accepted with --accept-conditioning" in err
    head = (tmp_path / "o.nc").read_text()[:3000].upper()
    assert "(OVERSHOOT 710 PERCENT OF THE DATA RANGE ABOVE 100 PERCENT ACCEPTED --ACCEPT-CONDITIONING)" in head


def test_the_measured_data_page_quotes_the_overshoot_figures(run_cli, tmp_path, monkeypatch):
    from conftest import ROOT

    from lagsym.cad.extremes import overshoot

    text = (ROOT / "docs" / "measured-data.md").read_text()
    page = " ".join(text.split())
    src = checkerboard(tmp_path)
    monkeypatch.chdir(tmp_path)
    status, _, err = run_cli("toolpath", "checker.json", "-o", "part.nc")
    assert status == 2 and err.strip() in text.splitlines()
    amp, o = amplification(read_points(src)), overshoot(lagrange_surface(read_points(src)))
    assert f"amplify {amp.value:.3g} times, yet the interpolant reaches {o.most:.2g} beyond them" in page
    papers = max(overshoot(lagrange_surface(read_points(EXAMPLES / f"paper-example-{k}.json"))).share
                 for k in (1, 2, 3, 4))
    assert f"(the paper's examples reach {100 * papers:.0f} %)" in page and papers < 1.0
