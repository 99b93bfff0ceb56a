"""Numbers the documentation states, recomputed: each fails if the page and the computation part."""

from __future__ import annotations

import math
import re
from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy

from lagsym import lagrange_surface, read_points
from lagsym.conditioning import check_surface, lebesgue_constant
from lagsym.equation import rounding_miss
from lagsym.evaluate import evaluate_grid
from lagsym.grid import grid_from_table

from conftest import EXAMPLES, ROOT

DOCS = ROOT / "docs"


def page(name: str) -> str:
    return " ".join((DOCS / name).read_text().split())


def lebesgue_mp(nodes, t) -> mpmath.mpf:
    total = mpmath.mpf(0)
    for j, xj in enumerate(nodes):
        p = mpmath.mpf(1)
        for k, xk in enumerate(nodes):
            if k != j:
                p *= (t - xk) / (xj - xk)
        total += abs(p)
    return total


def first_kind(n):
    return [math.cos(math.pi * (2 * i + 1) / (2 * n)) for i in range(n)]


def extrema(n):
    return [math.cos(math.pi * i / (n - 1)) for i in range(n)]


def test_theory_and_sampling_lebesgue_constants():
    theory, sampling = page("theory.md"), page("sampling.md")
    eq = {n: lebesgue_constant(range(n)) for n in (7, 11, 20)}
    assert f"({eq[7]:.3g} for 7 nodes, {eq[11]:.3g} for 11, {eq[20]:.0f} for 20)" in theory
    assert f"for 20 equally spaced nodes is {eq[20]:.0f} each" in sampling
    assert f"give {lebesgue_constant(first_kind(7)):.3g} for 7 nodes and {lebesgue_constant(first_kind(20)):.3g} for 20" in theory
    assert f"give {lebesgue_constant(extrema(7)):.3g} and {lebesgue_constant(extrema(20)):.3g}" in theory


@pytest.mark.slow
@pytest.mark.parametrize("nodes", [[1.1**k for k in range(40)], [2.0**k for k in range(30)], list(range(20))],
                         ids=["geometric-1.1", "geometric-2", "equispaced-20"])
def test_lebesgue_constant_agrees_with_60_digit_arithmetic(nodes):
    mpmath.mp.dps = 60
    mp_nodes = [mpmath.mpf(v) for v in nodes]
    lam = lebesgue_constant(nodes)
    # A dense 60-digit search of the widest-valued interval and the last one bounds the maximum from below.
    probe = max(lebesgue_mp(mp_nodes, mp_nodes[j] + (mp_nodes[j + 1] - mp_nodes[j]) * mpmath.mpf(k) / 200)
                for j in (0, len(nodes) - 2) for k in range(1, 200))
    assert float(probe) <= lam * (1 + 1e-9)
    assert lam <= float(probe) * (1 + 1e-4)


def test_the_spacing_ratio_changes_no_measure_of_the_surface():
    g = read_points(EXAMPLES / "paper-example-4.json")
    stretched = grid_from_table([v * 40 for v in g.x], g.y, g.z)
    a = {f.name: f for f in check_surface(lagrange_surface(g)).findings}
    b = {f.name: f for f in check_surface(lagrange_surface(stretched)).findings}
    assert b["spacing_ratio"].value == pytest.approx(40 * a["spacing_ratio"].value)
    assert not b["spacing_ratio"].warning
    for name in ("lebesgue_x", "lebesgue_y", "overshoot"):
        assert b[name].value == pytest.approx(a[name].value, rel=1e-9), name


def test_comparison_deviation_percentage_evidence():
    text = page("comparison.md")
    hermite, bezier = 66.2265 / 108.0572, 31.4031 / 51.2383
    assert f"{hermite:.5f}" == f"{bezier:.5f}" == "0.61288"
    assert "66.2265 / 108.0572 = 31.4031 / 51.2383 = 0.61288" in text
    assert f"{100 / hermite:.2f}" == f"{100 / bezier:.2f}" == "163.16" and "/ 163.16" in text


def runge_max_deviation(n: int) -> float:
    nodes = [Fraction(-2) + Fraction(4 * i, n - 1) for i in range(n)]
    z = [[1 / (1 + 4 * (a * a + b * b)) for b in nodes] for a in nodes]
    s = lagrange_surface(grid_from_table(nodes, nodes, z))
    t = np.linspace(-2, 2, 81)
    f = 1 / (1 + 4 * (t[:, None] ** 2 + t[None, :] ** 2))
    return float(np.abs(evaluate_grid(s, t, t) - f).max())


def test_paper_page_degree_6_sentence():
    text = page("paper.md")
    d5, d7 = runge_max_deviation(5), runge_max_deviation(7)
    assert f"| 5x5 | 4 | {d5:.4f} |" in text and f"| 7x7 | 6 | {d7:.4f} |" in text
    assert d7 > d5 > runge_max_deviation(9) / 10
    assert f"the deviation is larger than at 5x5 ({d7:.4f} against {d5:.4f})" in text


def test_equations_page_rounding_numbers():
    from test_symbolic import dome

    text = page("equations.md")
    nodes, z = dome()
    s = lagrange_surface(grid_from_table(nodes, nodes, z))
    m = {d: f"{float(rounding_miss(s, d).largest):.3g}" for d in (4, 5, 6)}
    assert f"misses the control points by up to {m[4]} mm" in text
    assert f"5 digits miss by {m[5]} mm, 6 by {m[6]} mm" in text
    ex4 = rounding_miss(lagrange_surface(read_points(EXAMPLES / "paper-example-4.json")), 4)
    assert f"Example 4 at 4 digits misses by {float(ex4.largest):.3g} mm (at (5, 5))" in text
    assert ex4.at[:2] == (5, 5)


def test_errata_equation_4_as_printed_misses_its_second_point():
    x, x1, x2, y1, y2 = sympy.symbols("x x_1 x_2 y_1 y_2")
    printed = (x - x2) / (x1 - x2) * y1 - (x - x1) / (x2 - x1) * y2
    assert sympy.simplify(printed.subs(x, x1) - y1) == 0
    assert sympy.simplify(printed.subs(x, x2) + y2) == 0  # through (x_2, -y_2)
    second = y1 + (y2 - y1) * (x1 - x) / (x1 - x2)
    assert sympy.simplify(second.subs(x, x2) - y2) == 0
    text = page("paper-errata.md")
    assert "through `(x_2, -y_2)`, not `(x_2, y_2)`" in text and "`j = 0 .. n`" in text


def test_plotting_page_lists_no_view_as_to_come():
    assert "(to come)" not in page("plotting.md")
    assert re.search(r"static\*\* by default", page("plotting.md"))


def test_notebook_1_overshoot_sentence_matches_its_table():
    import json

    from lagsym import curve_from_points, lagrange_curve
    from lagsym.conditioning import check_curve

    def overshoot(n):
        xs = [Fraction(-1) + Fraction(2 * i, n - 1) for i in range(n)]
        c = lagrange_curve(curve_from_points([(v, 1 / (1 + 25 * v * v)) for v in xs]))
        return {f.name: f.value for f in check_curve(c).findings}

    found = {n - 1: overshoot(n) for n in (5, 7, 9, 11)}
    assert found[6]["overshoot"] < found[4]["overshoot"] and found[10]["overshoot"] < found[8]["overshoot"]
    assert found[4]["lebesgue_x"] < found[6]["lebesgue_x"] < found[8]["lebesgue_x"] < found[10]["lebesgue_x"]
    nb = json.loads((ROOT / "notebooks" / "01-lagrange-curves.ipynb").read_text())
    text = " ".join("".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "markdown")
    assert "drops from degree 4 to 6 and from 8 to 10" in text


@pytest.mark.slow
def test_macros_page_quotes_what_macro_stats_prints(tmp_path, monkeypatch, run_cli):
    text = (DOCS / "macros.md").read_text()
    block = text.split("$ lagsym macro examples/paper-example-4.json", 1)[1].split("```", 1)[0]
    argv = ("macro " + block.split("\n", 2)[0] + " " + block.split("\n", 2)[1]).replace("\\", " ").split()
    quoted = block.split("\n", 2)[2].split("\n$ ", 1)[0].strip()
    (tmp_path / "examples").symlink_to(EXAMPLES)
    monkeypatch.chdir(tmp_path)
    status, out, err = run_cli(argv[0], "examples/paper-example-4.json", *argv[1:])
    assert status == 0, err
    assert quoted == (out + err).strip()
    assert f"takes {quoted.split('macro program:')[1].split()[0]} bytes on a Fanuc" in text
    # The paper page's conclusion quotes the same run.
    size, seconds = quoted.split("macro program:")[1].split()[0], quoted.split("bytes, ")[1].split()[0]
    ratio = quoted.split("the point list is ")[1].split()[0]
    paper = " ".join(page("paper.md").split())
    assert f"{int(size):,} bytes ({seconds} s at 9600 baud, 7E2)" in paper and f"{ratio} times larger" in paper
    assert f"of {int(quoted.split('raster points:')[1].split()[0]):,} points" in paper


@pytest.mark.slow
def test_paper_page_quotes_the_point_list_at_a_fine_step(tmp_path, run_cli):
    status, out, err = run_cli("macro", str(EXAMPLES / "paper-example-4.json"), "--scale", "20", "--tool-diameter", "4",
                               "--stepover", "0.5", "--step", "0.01", "--safe-z", "100", "--dialect", "fanuc",
                               "-o", str(tmp_path / "O1000.nc"), "--stats")
    assert status == 0, err
    points = int(out.split("raster points:")[1].split()[0])
    size = int(out.split("point-list program:")[1].split()[0])
    hours = out.split("bytes, ")[2].split()[0]
    macro = int(out.split("macro program:")[1].split()[0])
    paper = " ".join(page("paper.md").split())
    assert f"be {points:,} points, about {size / 1e6:.1f} MB ({hours} h at 9600 baud)" in paper and macro < 3000


def test_dnc_page_line_times_of_the_window():
    from lagsym.dnc import profile

    text = page("dnc.md")
    ms = {baud: 4 / profile("fanuc", baud=baud).chars_per_s * 1000 for baud in (9600, 115200)}
    assert f"4 characters are {ms[9600]:.1f} ms of line at 9600 baud and {ms[115200]:.2f} ms at 115200" in text
    assert f"{profile('fanuc').chars_per_s:.1f} characters/s at 9600 baud" in text


@pytest.mark.slow
def test_the_macros_page_quotes_the_program_sizes():
    from test_macro import rough_grid

    from lagsym.machine import MachineSettings, RasterSpec, Tool
    from lagsym.macro import macro_program

    text = page("macros.md")
    for n in (3, 5, 7, 12):
        sizes = [macro_program(rough_grid(n, seed=n), MachineSettings(dialect=d, safe_z_mm=1e4), RasterSpec("x", 1.0, 1.0),
                               Tool("flat", 0.0), precision=prec, form=form, tolerance_mm=1e9).size
                 for prec, form in ((8, "lagrange"), (15, "horner")) for d in ("fanuc", "linuxcnc", "heidenhain")]
        assert f"| {n}x{n} | " + " | ".join(map(str, sizes)) + " |" in text


def test_sampling_page_float64_basis_bound_ratio(monkeypatch):
    """The bound counted with the basis in float64 units, against the long-double bound, for Example 4."""
    import lagsym.evaluate.bounds as bounds
    from lagsym.evaluate import surface_evaluator

    ev = surface_evaluator(lagrange_surface(read_points(EXAMPLES / "paper-example-4.json")))
    kept = ev.error_bound()
    # The same weights with float64's unit of rounding for the basis values.
    monkeypatch.setattr(bounds, "EPS_BASIS", float(np.finfo(float).eps))
    ratio = ev.error_bound() / kept
    assert ratio > 1
    assert f"the same bound counted in float64 units is {ratio:.1f} times larger" in page("sampling.md")


@pytest.mark.slow
def test_the_roughing_page_quotes_the_roughing_macro(tmp_path, run_cli):
    """Sizes, the clearance tables' range and the extra height over the point-list roughing, recomputed."""
    import re

    from test_rough_macro import BOX, drop, plan

    text = page("roughing.md")
    common = ("rough", EXAMPLES / "paper-example-4.json", "--scale", "20", "--stock-above", "2", "--tool-diameter",
              "10", "--stepdown", "2", "--stepover", "5", "--stock-to-leave", "0.3", "--safe-z", "90")
    sizes = {}
    for name, extra in (("fanuc", ("--macro",)), ("linuxcnc", ("--macro",)), ("points", ())):
        out = tmp_path / f"{name}.nc"
        status, _, err = run_cli(*common, "--dialect", "linuxcnc" if name == "linuxcnc" else "fanuc", *extra,
                                 "-o", out)
        assert status == 0, err
        sizes[name] = len(out.read_bytes())
        if name == "fanuc":
            a = re.search(r"A (\S+) to (\S+) mm \(curvature up to (\S+)/mm\)", err).groups()
    assert (f"the Fanuc program is {sizes['fanuc']} bytes and the LinuxCNC one {sizes['linuxcnc']}, where the "
            f"Fanuc point-list program is {sizes['points']} bytes") in text
    assert f"`A` runs from {a[0]} to {a[1]} mm" in text and f"at most {a[2]} per mm" in text
    surface, settings, tool, spec, stock, rm, _ = plan(stepdown=2.0, step=0.5, ramp_angle_deg=90.0)
    per = len(rm.points_mm) // len(rm.levels_mm)
    last = rm.points_mm[-per:]
    q = last[(last[:, 0] >= BOX[0]) & (last[:, 0] <= BOX[1])]
    cl = drop(q[:, 0], q[:, 1]) + 0.3
    extra = q[:, 2] - np.maximum(cl, rm.levels_mm[-1])
    assert f"on average {extra.mean():.1f} mm and at most {extra.max():.1f} mm above" in page("roughing.md")
    from lagsym.evaluate import surface_evaluator

    ev = surface_evaluator(surface)
    u, v = settings.placement.to_surface(q[:, 0], np.clip(q[:, 1], 20, 100))
    f = settings.placement.height_mm(ev.fast_points(np.clip(u, 1, 5), np.clip(v, 1, 5)))
    c = float((cl - 0.3 - f).max())
    constant = np.maximum(f + c + 0.3, rm.levels_mm[-1]) - np.maximum(cl, rm.levels_mm[-1])
    assert f"above `F` over the box ({c:.1f} mm), would leave {constant.mean():.1f} mm on average" in text
    fanuc = (tmp_path / "fanuc.nc").read_text()
    assert "\n#500=" in fanuc and "\n#627=" in fanuc and "\n#628=" not in fanuc and "\n#499=" not in fanuc
    linuxcnc = (tmp_path / "linuxcnc.nc").read_text()
    assert "\n#1000 = " in linuxcnc and "\n#1127 = " in linuxcnc and "\n#1128 = " not in linuxcnc
    assert "8 x 8 tiling" in text and "(128 numbers, `#500`-`#627` on a Fanuc, `#1000`-`#1127` on LinuxCNC)" in text


def arc_figures(name: str, rs274, tmp_path):
    """The README's finishing settings with --arcs on one example: feed moves before and after, and how far the
    arcs rs274 moves lie above a brute-force ball drop-cutter on the exact polynomial (um, least and most)."""
    from cutters import brute_ball
    from gcheck import arc_feeds, tessellate
    from lagsym.machine import MachineSettings, RasterSpec, Tool
    from lagsym.post.program import point_program, write_program
    from lagsym.toolpath import plan_toolpath
    from test_arcs import example2, example4

    f, box = {"paper-example-2": (example2, (1.0, 4.0, 1.0, 4.0)), "paper-example-4": (example4, (1.0, 5.0, 1.0, 5.0))}[name]
    settings = MachineSettings(mm_per_unit=20.0, dialect="fanuc", safe_z_mm=80.0)
    s = lagrange_surface(read_points(ROOT / "examples" / f"{name}.json"))
    tp = plan_toolpath(s, Tool("ball", 6.0), RasterSpec("x", 0.4, 0.2, arcs=True), settings.placement, settings.program, stock_to_leave_mm=settings.stock_to_leave_mm)
    path = tmp_path / f"{name}.nc"
    path.write_text(write_program(point_program(tp, settings)))
    r = rs274.run(path)
    assert r.returncode == 0, r.stderr[-400:]
    arcs, _ = arc_feeds(r.stdout)
    assert len(arcs) == len(tp.arcs)
    pts = np.concatenate([tessellate(*a, n=50)[1:-1] for a in arcs])
    pick = pts[np.random.default_rng(11).choice(len(pts), 4000, replace=False)]
    dev = pick[:, 2] - brute_ball(f, box, pick[:, 0] / 20.0, pick[:, 1] / 20.0, 3.0 / 20.0) * 20.0
    return len(tp) - 1, len(tp) - 1 - tp.arcs.blocks_saved(), len(tp.arcs), dev.min() * 1000, dev.max() * 1000


@pytest.mark.parametrize("name, label", [("paper-example-2", "Example 2"), ("paper-example-4", "Example 4")])
@pytest.mark.slow
def test_the_toolpaths_page_quotes_the_arc_figures(rs274, tmp_path, name, label):
    before, after, arcs, low, high = arc_figures(name, rs274, tmp_path)
    assert low >= -0.1 and high <= 6.1  # never below; the tolerance and a unit of rounding above
    assert (f"{label}: {before:,} feed moves, {after:,} with {arcs:,} arcs, which lie {low:.1f} to {high:.1f} um "
            f"above the cutter path") in page("toolpaths.md")


def test_the_toolpaths_page_quotes_the_planning_figures():
    from lagsym.toolpath.workers import MAX_PROCESSES, MIN_POINTS

    text = page("toolpaths.md")
    assert f"Plans of {MIN_POINTS:,} fine samples or more share the positions" in text
    assert MAX_PROCESSES == 8 and "one per core up to eight" in text
    assert "STL mesh of 360 cells a side, fine enough to come within about 5 um" in text


@pytest.mark.slow
def test_the_planning_benchmark_mesh_comes_within_5_um():
    """OpenCAMLib on the 360-cell mesh against the exact drop-cutter, at positions over the box."""
    ocl = pytest.importorskip("opencamlib")
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    from bench_dropcutter import ocl_drop, stl_surface

    from lagsym.toolpath import drop_cutter

    surface = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
    rng = np.random.default_rng(2)
    x, y = rng.uniform(1.15, 4.85, 150), rng.uniform(1.15, 4.85, 150)
    exact = drop_cutter(surface, x, y, 0.15, lattice=24, starts=8, margin=False) * 20
    z = ocl_drop(ocl, stl_surface(ocl, surface, 360, 20.0), 6.0, x * 20, y * 20, -100.0)
    err = np.abs(z - exact).max()
    assert 1e-3 < err <= 5e-3  # mm: a mesh of the surface, within 5 um of it


def test_the_sampling_page_quotes_the_threads():
    from lagsym.evaluate.threads import MAX_THREADS, TAKE_VALUES, THREAD_POINTS

    text = page("sampling.md")
    assert MAX_THREADS == 4 and "shared among up to four threads" in text
    assert f"each thread having {THREAD_POINTS:,} values or more" in text
    assert f"blocks of about {TAKE_VALUES:,} values (`TAKE_VALUES`)" in text


def test_the_sampling_page_quotes_when_the_kernels_load():
    from lagsym.evaluate.engine import LOAD_SECONDS

    text = " ".join(page("sampling.md").split())
    assert LOAD_SECONDS == 0.5 and "(`LOAD_SECONDS`, 0.5 s)" in text and "have taken 0.5 s" in text
    assert "once such batches have taken half a second in NumPy" in " ".join(page("architecture.md").split())


def test_the_pages_quote_the_compiled_threshold():
    from lagsym.evaluate import COMPILED_POINTS

    assert f"A batch of {COMPILED_POINTS:,} scattered points or more (`COMPILED_POINTS`)" in page("sampling.md")
    assert f"a batch of {COMPILED_POINTS:,} scattered points or more" in page("architecture.md")
