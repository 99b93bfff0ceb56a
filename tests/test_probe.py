"""Measure on the machine, fit, machine: probing programs, the simulated probe, the results read back, the loop.

Every check is against an independent computation: the nodes against NumPy's
Chebyshev points, the LinuxCNC programs against LinuxCNC's own ``rs274``, and
the whole loop against the true surface's formula by brute force.
"""

from __future__ import annotations

import io
import re
import shlex
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from lagsym.cli import main
from lagsym.controls import CONTROLS
from lagsym.errors import InputError
from lagsym.formula import parse_formula
from lagsym.gcode.limits import check_blocks
from lagsym.probe import ProbeSettings, node_plan, probe_program, read_results, surface_points
from lagsym.simulate import ControlAlarm, simulate
from lagsym.simulate.probing import probe_target

from conftest import EXAMPLES

# The true surface of the loop: a quadric the fit of degree 2 can reproduce, over a 40 x 30 mm box.
TRUE = "3 + 0.02*x + 0.0006*y**2 - 0.00003*x**2 + 0.00001*x*y"
BOX = (0, 40, 0, 30)
TOLERANCE = 0.005  # the finishing program's chordal tolerance, mm


def run(argv):
    out, err = io.StringIO(), io.StringIO()
    return main([str(a) for a in argv], out, err), out.getvalue(), err.getvalue()


def one_line_error(status, err, code=2):
    assert status == code, err
    assert err.count("\n") == 1 and err.startswith("lagsym: error:"), err


# --------------------------------------------------------------------------- the node plan


@pytest.mark.parametrize("n", [2, 3, 5, 7, 10])
def test_chebyshev_nodes_are_numpys_chebyshev_extrema(n):
    plan = node_plan((-20, 80, 0, 50), nodes=(n, n))
    for (lo, hi), got in (((-20, 80), plan.xs), ((0, 50), plan.ys)):
        ref = lo + (hi - lo) * (np.polynomial.chebyshev.chebpts2(n) + 1) / 2  # -1..1 ascending
        assert got == tuple(Fraction(round(Fraction(v) * 1000), 1000) for v in ref)
        assert got[0] == lo and got[-1] == hi


def test_node_count_is_degree_plus_one_plus_margin():
    for degree, margin in [((4, 4), 2), ((3, 5), 0), ((6, 2), 3)]:
        plan = node_plan(BOX, degree, margin=margin)
        assert (len(plan.xs), len(plan.ys)) == (degree[0] + 1 + margin, degree[1] + 1 + margin)


def test_nodes_are_numbered_in_probing_order_and_cover_the_grid():
    plan = node_plan(BOX, (2, 1), spacing="even", margin=1)
    nodes = plan.nodes()
    assert [n for n, _, _ in nodes] == list(range(1, len(plan) + 1))
    assert sorted((x, y) for _, x, y in nodes) == sorted((x, y) for x in plan.xs for y in plan.ys)
    # no long move back: consecutive nodes are neighbours
    steps = [abs(a[1] - b[1]) + abs(a[2] - b[2]) for a, b in zip(nodes, nodes[1:])]
    assert max(steps) == max(max(np.diff([float(v) for v in plan.xs])), max(np.diff([float(v) for v in plan.ys])))


def test_bad_plans_and_settings_are_refused():
    with pytest.raises(InputError, match="node spacing 'odd'"):
        node_plan(BOX, 2, spacing="odd")
    with pytest.raises(InputError, match="more than the limit"):
        node_plan(BOX, nodes=(60, 60))
    with pytest.raises(InputError, match="top 1 mm must be above bottom 2 mm"):
        ProbeSettings(1, 1, 2)
    with pytest.raises(InputError, match="retract height 3 mm"):
        ProbeSettings(1, 5, 0, retract_mm=3)


# --------------------------------------------------------------------------- the programs


def test_linuxcnc_probing_programs_pass_rs274(tmp_path):
    """rs274 reads the program, reports each G38.2 as STRAIGHT_PROBE to the planned node, and its LOG lines
    (the probe, never tripping in rs274, reports the end point) read back as results."""
    from debtools import rs274

    plan = node_plan(BOX, (1, 2), margin=1)
    s = ProbeSettings(Fraction(3, 2), 6, 2)
    path = tmp_path / "probe.ngc"
    path.write_text(probe_program(plan, s, "linuxcnc"))
    r = rs274().run(path)
    assert r.returncode == 0, r.stderr
    probes = re.findall(r"STRAIGHT_PROBE\(([-\d.]+), ([-\d.]+), ([-\d.]+)", r.stdout)
    assert [(Fraction(x), Fraction(y), Fraction(z)) for x, y, z in probes] == \
        [(x, y, s.end_mm) for _, x, y in plan.nodes()]
    # every probe move starts at the approach height, above the part's top plus the tip and clearance
    before = re.findall(r"STRAIGHT_TRAVERSE\(([-\d.]+), ([-\d.]+), ([-\d.]+).*\n.*\n.*TURN_PROBE_ON", r.stdout)
    assert {Fraction(z) for _, _, z in before} == {s.top_mm + s.tip_radius_mm + s.clearance_mm}
    logged = "\n".join(re.findall(r'LOG\("([^"]*)"\)', r.stdout)) + "\n"
    res = read_results(logged, "rs274")
    assert res.points == tuple((x, y, s.end_mm) for _, x, y in plan.nodes())
    assert res.tip_radius == s.tip_radius_mm


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_fanuc_and_haas_probing_programs_pass_the_simulator_and_the_controls_limits(dialect):
    plan = node_plan(BOX, 2, margin=2)
    text = probe_program(plan, ProbeSettings(1, 6, 2), dialect, program_number=1234)
    c = CONTROLS[dialect]
    check_blocks(text.splitlines(), c)
    for word in re.findall(r"\b[XYZ](-?\d+\.\d*)", text):
        assert len(word.replace("-", "").replace(".", "")) <= c.axis_digits
    assert c.framing.program_word.format(1234) in text
    sim = simulate(text, dialect, 8, target=probe_target(parse_formula(TRUE), 1))
    assert sim.probes == len(plan) and len(sim.output) == len(plan) + 2


def test_simulator_refuses_a_probing_move_without_a_surface_and_the_other_controls_code(tmp_path):
    fanuc = probe_program(node_plan(BOX, 0, margin=1), ProbeSettings(1, 6, 2), "fanuc")
    with pytest.raises(ControlAlarm, match="G31 probes"):
        simulate(fanuc, "fanuc", 8)
    with pytest.raises(ControlAlarm, match="G38.2"):
        simulate("G0 X0. Y0. Z5.\nG38.2 Z-1. F100.\n", "fanuc", 8, target=probe_target(parse_formula("0"), 0))
    with pytest.raises(ControlAlarm, match="G31"):
        simulate("G0 X0 Y0 Z5\nG31 Z-1 F100\nM2\n", "linuxcnc", 15, target=probe_target(parse_formula("0"), 0))


def test_a_probing_mode_carried_on_without_its_word_is_refused():
    """G38.2 is a motion mode on LinuxCNC: a later block of axis words alone would probe again, which the
    simulator does not run; a Fanuc's G31 is one-shot, and the next block moves in the mode before it."""
    t = probe_target(parse_formula("1"), 0)
    for block in ("Z5", "#1=5\nZ#1"):
        with pytest.raises(ControlAlarm, match="G38.2 mode without its G38.2 word"):
            simulate(f"G0 X0 Y0 Z5\nG38.2 Z-1 F100\n{block}\nM2\n", "linuxcnc", 15, target=t)
    sim = simulate("G0 X0. Y0. Z5.\nG31 Z-1. F100.\nZ5.\nM30\n", "fanuc", 8, target=t)
    assert [(m.motion, m.z) for m in sim.moves] == [("G0", 5.0), ("G1", 1.0), ("G0", 5.0)]


def test_simulated_probe_stops_where_the_ball_rests_on_the_surface():
    """Against a plane the tip centre rests r * sqrt(1 + a^2 + b^2) above it (exactly)."""
    a, b, r = 0.3, -0.2, 2.0
    t = probe_target(parse_formula(f"1 + {a}*x + {b}*y"), r)
    x, y = 4.0, 7.0
    _, _, z = t.touch((x, y, 40.0), (x, y, -40.0))
    assert abs(z - (1 + a * x + b * y + r * np.sqrt(1 + a * a + b * b))) < 1e-7


# --------------------------------------------------------------------------- the whole loop


def _moves(text: str) -> np.ndarray:
    """Feed moves' end points of a point-list program, read here with a few lines of its own."""
    pos, mode, out = [0.0, 0.0, 0.0], None, []
    for line in text.splitlines():
        line = re.sub(r"\(.*?\)", "", line).upper()
        for g in re.findall(r"G(\d+)", line):
            if g in ("0", "00", "1", "01"):
                mode = int(g)
        words = dict(re.findall(r"([XYZ])(-?\d*\.?\d*)", line))
        if not words:
            continue
        for k, axis in enumerate("XYZ"):
            if axis in words:
                pos[k] = float(words[axis])
        if mode == 1:
            out.append(list(pos))
    return np.array(out)


def _centre_heights(f, x, y, radius, n=61):
    """Brute force: the lowest a ball of ``radius`` can sit above (x, y) without entering z = f."""
    u = np.linspace(-radius, radius, n)
    dx, dy = np.meshgrid(u, u, indexing="ij")
    keep = dx ** 2 + dy ** 2 <= radius ** 2
    dx, dy = dx[keep], dy[keep]
    lift = np.sqrt(np.maximum(radius ** 2 - dx ** 2 - dy ** 2, 0))
    out = []
    for px, py in zip(x, y):
        z = f(px + dx, py + dy) + lift
        k = int(np.argmax(z))
        # refine around the best offset on a grid 20 times finer
        v = np.linspace(-1, 1, 21) * (u[1] - u[0])
        gx, gy = np.meshgrid(dx[k] + v, dy[k] + v, indexing="ij")
        inside = gx ** 2 + gy ** 2 <= radius ** 2
        gx, gy = gx[inside], gy[inside]
        out.append(float(np.max(f(px + gx, py + gy) + np.sqrt(np.maximum(radius ** 2 - gx ** 2 - gy ** 2, 0)))))
    return np.array(out)


@pytest.mark.parametrize("dialect", ["fanuc", "linuxcnc"])
def test_probe_fit_machine_loop(tmp_path, dialect):
    """True surface -> probing program -> simulated control -> printed results -> read-probe -> fit ->
    toolpath -> brute-force gouge and material check against the formula."""
    f = parse_formula(TRUE)
    tip, tool_r = 1.0, 3.0
    prog = tmp_path / "probe.nc"
    status, _, err = run(["probe", "--dialect", dialect, "--box", ",".join(map(str, BOX)), "--top", 6,
                          "--bottom", 2, "--tip-radius", tip, "--degree", 2, "-o", prog])
    assert status == 0, err
    results = tmp_path / "results.txt"
    status, _, err = run(["simulate", prog, "--surface", TRUE, "--tip-radius", tip, "--print-output", results,
                          "-o", tmp_path / "moves.csv"])
    assert status == 0, err
    points = tmp_path / "points.json"
    assert run(["read-probe", results, "-o", points])[0] == 0
    surface = tmp_path / "surface.json"
    status, report, err = run(["fit", points, "--degree", 2, "-o", surface])
    assert status == 0, err
    largest = float(re.search(r"residuals: max ([\d.e+-]+)", report).group(1))
    nc = tmp_path / "part.nc"
    status, _, err = run(["toolpath", surface, "--tool-diameter", 2 * tool_r, "--stepover", 2, "--step", 1,
                          "--tolerance", TOLERANCE, "--safe-z", 20, "--dialect", "fanuc", "-o", nc])
    assert status == 0, err
    pts = _moves(nc.read_text())
    assert len(pts) > 100
    # the cutter locations over the box, and the middle of every straight move between them
    mids = (pts[1:] + pts[:-1]) / 2

    def over_box(p):
        return p[(p[:, 0] >= BOX[0]) & (p[:, 0] <= BOX[1]) & (p[:, 1] >= BOX[2]) & (p[:, 1] <= BOX[3])]

    locations, mids = over_box(pts), over_box(mids)
    # the program gives the ball's lowest point: its centre is one radius up
    at = locations[:, 2] + tool_r - _centre_heights(f, locations[:, 0], locations[:, 1], tool_r)
    between = mids[:, 2] + tool_r - _centre_heights(f, mids[:, 0], mids[:, 1], tool_r)
    # stated error: the fit's largest residual, the printed results' last digit (4 decimals on a Fanuc), the
    # vertical tip compensation's bound (read-probe reports it), the brute force's grid
    report = points.read_text()
    bound = float(re.search(r'"approximation_bound": ([\d.e+-]+)', report).group(1))
    stated = largest + 5e-5 + bound + 2e-5
    gouge = float(max(-at.min(), -between.min()))
    assert gouge <= stated, (gouge, stated)
    # material left at a cutter location: the finishing guarantee lifts a location by at most the chordal
    # tolerance (so the straight moves stay above the surface), and the program's last digit rounds it
    left = float(at.max())
    assert left <= stated + TOLERANCE + 5e-4, (left, stated)


# --------------------------------------------------------------------------- failures: one line, exit 2


def _results(tmp_path, dialect="fanuc") -> Path:
    prog = tmp_path / "probe.nc"
    run(["probe", "--dialect", dialect, "--box", ",".join(map(str, BOX)), "--top", 6, "--bottom", 2,
         "--tip-radius", 1, "--degree", 1, "--margin", 1, "-o", prog])
    results = tmp_path / "results.txt"
    status, _, err = run(["simulate", prog, "--surface", TRUE, "--tip-radius", 1, "--print-output", results,
                          "-o", tmp_path / "moves.csv"])
    assert status == 0, err
    return results


@pytest.mark.parametrize("dialect, message", [("fanuc", "alarm 3000"), ("linuxcnc", "without making contact")])
def test_a_probe_that_never_trips(tmp_path, dialect, message):
    prog = tmp_path / "probe.nc"
    run(["probe", "--dialect", dialect, "--box", ",".join(map(str, BOX)), "--top", 6, "--bottom", 2,
         "--tip-radius", 1, "--degree", 1, "--margin", 1, "-o", prog])
    out = tmp_path / "results.txt"
    status, _, err = run(["simulate", prog, "--surface=-5 + 0*x", "--tip-radius", 1, "--print-output", out])
    one_line_error(status, err)
    assert message in err and not out.exists()


def test_a_results_file_with_a_missing_node(tmp_path):
    results = _results(tmp_path)
    lines = results.read_text().splitlines()
    assert lines[3].startswith("P 3 ")
    results.write_text("\n".join(lines[:3] + lines[4:]) + "\n")
    points = tmp_path / "points.json"
    status, _, err = run(["read-probe", results, "-o", points])
    one_line_error(status, err)
    assert "node 3 of 9 missing" in err and not points.exists()
    status, _, err = run(["fit", results, "-o", tmp_path / "s.json"])
    one_line_error(status, err)


@pytest.mark.parametrize("dialect", ["fanuc", "linuxcnc"])
def test_a_stream_cut_mid_line(tmp_path, dialect):
    results = _results(tmp_path, dialect)
    text = results.read_text()
    cut = text.index("P5") if dialect == "linuxcnc" else text.index("P 5")
    results.write_text(text[: cut + 12])
    points = tmp_path / "points.json"
    status, _, err = run(["read-probe", results, "-o", points])
    one_line_error(status, err)
    assert "node 5: the line is cut mid-way" in err and not points.exists()
    results.write_text(text[: text.index("\n", cut) + 1])  # cut after a whole line: no END
    status, _, err = run(["read-probe", results, "-o", points])
    one_line_error(status, err)
    assert "stop after node 5 without END" in err and "node 6 and after never came" in err


def test_an_alarm_line_in_the_results(tmp_path):
    results = _results(tmp_path)
    lines = results.read_text().splitlines()
    results.write_text("\n".join(lines[:4] + ["ALARM 3001 PROBE NOT TRIPPED"] + lines[4:]) + "\n")
    status, _, err = run(["read-probe", results])
    one_line_error(status, err)
    assert "not a probe result (after node 3)" in err


# --------------------------------------------------------------------------- the documented example

PAGE = Path(__file__).resolve().parent.parent / "docs" / "probing.md"


def _page_commands():
    doc = PAGE.read_text()
    return [line.strip() for line in doc.splitlines()
            if line.strip().startswith(("lagsym probe --box", 'lagsym simulate probe.nc --surface "'))]


def _run_page_commands(tmp_path):
    reports = []
    for line in _page_commands():
        argv = [a.replace("examples/probe-results.txt", str(tmp_path / "r.txt")) for a in shlex.split(line)[1:]]
        argv = [str(tmp_path / a) if a == "probe.nc" else a for a in argv]
        status, out, err = run(argv)
        assert status == 0, err
        reports.append(out + err)
    return reports


def test_example_results_are_what_the_documented_commands_print(tmp_path):
    """examples/probe-results.txt, quoted in docs/probing.md, comes from the page's two commands, and the
    page quotes what they print."""
    assert len(_page_commands()) == 2
    reports = _run_page_commands(tmp_path)
    text = (tmp_path / "r.txt").read_text()
    assert text == (EXAMPLES / "probe-results.txt").read_text()
    doc = PAGE.read_text()
    assert reports[0].splitlines()[0] in doc
    assert "\n".join(text.splitlines()[:3]) in doc


def _lebesgue(nodes) -> float:
    """The largest of sum_j |l_j(t)| over a fine grid of the nodes' interval, in plain NumPy."""
    nodes = np.asarray(nodes, dtype=float)
    t = np.linspace(nodes.min(), nodes.max(), 20001)
    total = np.zeros_like(t)
    for j, xj in enumerate(nodes):
        others = np.delete(nodes, j)
        total += np.abs(np.prod((t[:, None] - others) / (xj - others), axis=1))
    return float(total.max())


def test_the_probing_page_quotes_the_lebesgue_constants():
    doc = " ".join(PAGE.read_text().split())
    for n in (7, 11):
        cheb = _lebesgue(np.polynomial.chebyshev.chebpts2(n))
        even = _lebesgue(np.linspace(-1, 1, n))
        assert f"| {n} | {cheb:.3g} | {even:.3g} |" in doc


@pytest.mark.slow
def test_the_probing_page_quotes_the_fits_amplification(tmp_path):
    """The page's example probed at 9 x 9 Chebyshev and even nodes and fitted with degree 6."""
    line = _page_commands()[1]
    formula = shlex.split(line)[4]
    figures = {}
    for spacing in ("chebyshev", "even"):
        prog, res = tmp_path / f"{spacing}.nc", tmp_path / f"{spacing}.txt"
        assert run(["probe", "--box", "0,100,0,60", "--top", 10, "--bottom", 2, "--tip-radius", 1, "--degree", 6,
                    "--spacing", spacing, "-o", prog])[0] == 0
        assert run(["simulate", prog, "--surface", formula, "--tip-radius", 1, "--print-output", res,
                    "-o", tmp_path / "m.csv"])[0] == 0
        status, _, err = run(["fit", res, "--degree", 6])
        assert status == 0
        figures[spacing] = re.search(r"amplification of errors in the points: ([\d.]+)", err).group(1)
    doc = " ".join(PAGE.read_text().split())
    assert (f"amplifies errors in the points up to {figures['chebyshev']} times with Chebyshev nodes and "
            f"{figures['even']} times with even ones") in doc


# --------------------------------------------------------------------------- the loop in one job file

JOB = """dialect = "{dialect}"
safe_z = 20
[probe]
box = [0, 40, 0, 30]
top = 6
bottom = 2
tip_radius = 1
degree = 2
fit_degree = 2
[stock]
top_above = 1
[tools.ball]
number = 2
shape = "ball"
diameter = 6
[[operations]]
kind = "finish"
tool = "ball"
stepover = 2
step = 1
tolerance = {tolerance}
"""


def test_the_loop_in_one_job_file(tmp_path):
    """lagsym job writes the probing program; after the simulated measurement, --measured fits it and writes the
    finishing program, whose header names the results and the fit's residuals (as 'lagsym fit' reports them),
    checked by brute force against the formula."""
    job = tmp_path / "job.toml"
    job.write_text(JOB.format(dialect="fanuc", tolerance=TOLERANCE))
    prog, results, part = tmp_path / "probe.nc", tmp_path / "results.txt", tmp_path / "part.nc"
    status, _, err = run(["job", job, "-o", prog])
    assert status == 0, err
    assert prog.read_text().count("G31 ") == 25
    assert run(["simulate", prog, "--surface", TRUE, "--tip-radius", 1, "--print-output", results,
                "-o", tmp_path / "m.csv"])[0] == 0
    status, _, err = run(["job", job, "--measured", results, "-o", part])
    assert status == 0, err
    # the residuals as 'lagsym fit' reports them for the same results, read on their own path
    status, fit_report, _ = run(["fit", results, "--degree", 2, "-o", tmp_path / "s.json"])
    largest = float(re.search(r"residuals: max ([\d.e+-]+)", fit_report).group(1))
    head = part.read_text().split("G21", 1)[0]
    import hashlib

    assert f"(MEASURED RESULTS.TXT SHA256 {hashlib.sha256(results.read_bytes()).hexdigest()[:16].upper()})" in head
    assert f"RESIDUALS MAX {largest:.4g}".upper() in head
    pts = _moves(part.read_text())
    over = pts[(pts[:, 0] >= BOX[0]) & (pts[:, 0] <= BOX[1]) & (pts[:, 1] >= BOX[2]) & (pts[:, 1] <= BOX[3])]
    at = over[:, 2] + 3.0 - _centre_heights(parse_formula(TRUE), over[:, 0], over[:, 1], 3.0)
    stated = largest + 5e-5 + 1e-4 + 2e-5  # the fit, the printed digit, the tip compensation, the brute force
    assert -at.min() <= stated
    assert at.max() <= stated + TOLERANCE + 5e-4


def test_job_probe_stage_errors_are_one_line(tmp_path):
    job = tmp_path / "job.toml"
    job.write_text(JOB.format(dialect="grbl", tolerance=TOLERANCE))
    status, _, err = run(["job", job])
    one_line_error(status, err)
    assert "a probe stage is written for fanuc, haas, linuxcnc, not 'grbl'" in err
    job.write_text('points = "p.json"\n' + JOB.format(dialect="fanuc", tolerance=TOLERANCE))
    one_line_error(*run(["job", job])[::2])
    job.write_text(JOB.format(dialect="fanuc", tolerance=TOLERANCE).replace("degree = 2\n", "degree = 1\n", 1))
    status, _, err = run(["job", job, "--measured", EXAMPLES / "probe-results.txt", "-o", tmp_path / "x.nc"])
    one_line_error(status, err)
    assert "49 nodes, but the job's probe stage has 16" in err and not (tmp_path / "x.nc").exists()
    status, _, err = run(["job", EXAMPLES / "example-4-job.toml", "--measured", EXAMPLES / "probe-results.txt"])
    one_line_error(status, err)
    assert "has no [probe] table" in err


def test_the_probing_page_quotes_the_job_header(tmp_path):
    """docs/probing.md's job commands run, and the header lines it quotes are those the program has."""
    doc = PAGE.read_text()
    commands = [line.strip() for line in doc.splitlines() if line.strip().startswith("lagsym job examples/probe-job")]
    assert len(commands) == 2
    for line in commands:
        argv = [str(tmp_path / a) if a.endswith(".nc") else str(EXAMPLES.parent / a) if a.startswith("examples/")
                else a for a in shlex.split(line)[1:]]
        status, _, err = run(argv)
        assert status == 0, err
    program = (tmp_path / "probed-job.nc").read_text()
    quoted = re.search(r"```\n(\(MEASURED .*?)```", doc, re.DOTALL).group(1).splitlines()
    assert len(quoted) == 3 and all(line in program.splitlines() for line in quoted)


def test_tip_compensation_on_a_bowl_against_the_formula():
    """docs/probing.md: a bowl probed with a 3 mm tip; the points within 0.000002 mm of the formula, where the
    heights straight below the centres would be off by 0.08 mm (both computed here in NumPy)."""
    f = parse_formula("3 + 0.02*(x-20)**2 + 0.01*y**2")
    r = 3.0
    plan = node_plan(BOX, 4, margin=2)
    text = probe_program(plan, ProbeSettings(r, 40, 0), "linuxcnc")
    res = read_results("\n".join(simulate(text, "linuxcnc", 15, target=probe_target(f, r)).output) + "\n")
    sp = surface_points(res)
    pts = np.array([[float(v) for v in p] for p in sp.points])
    assert [p[:2] for p in sp.points] == [p[:2] for p in res.points]
    err = float(np.max(np.abs(pts[:, 2] - f(pts[:, 0], pts[:, 1]))))
    doc = " ".join(PAGE.read_text().split())
    assert err <= 2e-6 and "come within 0.000002 mm of the surface" in doc
    assert err <= sp.bound
    # straight below: a least-squares 4x4 polynomial through the centres, its slope at each node
    c = np.array([[float(v) for v in p] for p in res.points])
    basis = lambda x, y: np.stack([x ** a * y ** b for a in range(5) for b in range(5)], axis=-1)  # noqa: E731
    coef = np.linalg.lstsq(basis(c[:, 0], c[:, 1]), c[:, 2], rcond=None)[0]
    h = 1e-5
    gx = (basis(c[:, 0] + h, c[:, 1]) @ coef - basis(c[:, 0] - h, c[:, 1]) @ coef) / (2 * h)
    gy = (basis(c[:, 0], c[:, 1] + h) @ coef - basis(c[:, 0], c[:, 1] - h) @ coef) / (2 * h)
    below = c[:, 2] - r * np.sqrt(1 + gx ** 2 + gy ** 2)
    assert f"would be off by {np.max(np.abs(below - f(c[:, 0], c[:, 1]))):.2f} mm" in doc


def test_simulate_probes_a_surface_file(tmp_path):
    """--surface may be a fitted surface file: a dry run against the surface fitted from a first run prints the
    heights of the first run within the fit's residuals and the printed last digit."""
    prog, first, second = tmp_path / "p.nc", tmp_path / "r1.txt", tmp_path / "r2.txt"
    assert run(["probe", "--box", ",".join(map(str, BOX)), "--top", 6, "--bottom", 2, "--tip-radius", 0,
                "--degree", 2, "--margin", 1, "-o", prog])[0] == 0
    assert run(["simulate", prog, "--surface", TRUE, "--print-output", first, "-o", tmp_path / "m.csv"])[0] == 0
    status, report, err = run(["fit", first, "--degree", 2, "-o", tmp_path / "s.json"])
    assert status == 0, err
    largest = float(re.search(r"residuals: max ([\d.e+-]+)", report).group(1))
    status, _, err = run(["simulate", prog, "--surface", tmp_path / "s.json", "--print-output", second,
                          "-o", tmp_path / "m2.csv"])
    assert status == 0, err
    a, b = read_results(first.read_text()), read_results(second.read_text())
    assert [p[:2] for p in a.points] == [p[:2] for p in b.points]
    assert max(abs(float(p[2] - q[2])) for p, q in zip(a.points, b.points)) <= largest + 1e-4
