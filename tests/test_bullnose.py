"""Bull-nose (corner-radius) end mills in drop-cutter, toolpath, verify, rough and jobs.

Checked against a brute-force cutter written here: the exact polynomial from
its rational power-basis coefficients (numpy's ``polyval2d``, not lagsym's
evaluator) and the torus profile from its definition, searched on a dense
lattice over the disc.
"""

from __future__ import annotations


import re

import numpy as np
import pytest

from lagsym.errors import InputError, ToolpathError
from lagsym.gcode import parse_moves
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import Tool
from lagsym.toolpath import drop_cutter

from conftest import EXAMPLES

EX2 = EXAMPLES / "paper-example-2.json"
EX4 = EXAMPLES / "paper-example-4.json"


def _power(surface):
    return np.array([[float(c) for c in row] for row in surface.coefficients])


def _profile(d, radius, corner):
    """Height of a bull nose's lower surface above its tip at distance ``d`` from the axis, by its definition."""
    flat = radius - corner
    e = np.clip(d - flat, 0.0, corner)
    return np.where(d <= flat, 0.0, corner - np.sqrt(np.maximum(corner**2 - e**2, 0.0)))


def brute_bull(surface, cx, cy, radius, corner, n=301):
    """Tip height of the bull nose dropped at each ``(cx, cy)``: a lower bound from a dense lattice over the disc."""
    c = _power(surface)
    x0, x1, y0, y1 = (float(v) for v in surface.grid.bounds)
    t = np.linspace(-radius, radius, n)
    gx, gy = np.meshgrid(t, t)
    inside = gx**2 + gy**2 <= radius**2
    ox, oy = gx[inside], gy[inside]
    out = np.empty(len(cx))
    for i, (a, b) in enumerate(zip(cx, cy)):
        # Points beyond the box edge are moved onto it (closer to the axis, so still under the tool):
        # the contact on a steep edge is then sampled on the edge itself.
        px, py = np.clip(a + ox, x0, x1), np.clip(b + oy, y0, y1)
        prof = _profile(np.hypot(px - a, py - b), radius, corner)
        out[i] = np.max(np.polynomial.polynomial.polyval2d(px, py, c) - prof)
    return out


@pytest.fixture(scope="module")
def ex4():
    return lagrange_surface(read_points(EX4))


def _positions(surface, k, seed=7):
    rng = np.random.default_rng(seed)
    x0, x1, y0, y1 = (float(v) for v in surface.grid.bounds)
    return rng.uniform(x0, x1, k), rng.uniform(y0, y1, k)


def test_drop_cutter_matches_a_brute_force_bull_nose(ex4):
    cx, cy = _positions(ex4, 40)
    got = drop_cutter(ex4, cx, cy, 0.3, "bull", corner=0.1)
    ref = brute_bull(ex4, cx, cy, 0.3, 0.1, n=401)
    assert np.all(got >= ref - 1e-12)  # never below a real contact
    assert np.max(got - ref) < 2e-4  # and as close as the lattice resolves (0.0015 units apart)


def test_bull_nose_lies_between_the_ball_and_the_flat_end(ex4):
    cx, cy = _positions(ex4, 200, seed=3)
    ball = drop_cutter(ex4, cx, cy, 0.3, "ball")
    bull = drop_cutter(ex4, cx, cy, 0.3, "bull", corner=0.12)
    flat = drop_cutter(ex4, cx, cy, 0.3, "flat")
    assert np.all(ball <= bull + 1e-9) and np.all(bull <= flat + 1e-9)
    assert np.mean(bull < flat - 1e-3) > 0.3 and np.mean(bull > ball + 1e-3) > 0.3  # and differs from both


def test_corner_limits_are_the_ball_and_the_flat_end(ex4):
    cx, cy = _positions(ex4, 50, seed=5)
    near_ball = drop_cutter(ex4, cx, cy, 0.3, "bull", corner=0.3 * (1 - 1e-9))
    near_flat = drop_cutter(ex4, cx, cy, 0.3, "bull", corner=1e-9)
    assert np.max(np.abs(near_ball - drop_cutter(ex4, cx, cy, 0.3, "ball"))) < 1e-6
    assert np.max(np.abs(near_flat - drop_cutter(ex4, cx, cy, 0.3, "flat"))) < 1e-6


@pytest.mark.parametrize("kwargs, message", [
    ({"shape": "bull"}, "needs a corner radius (--corner-radius)"),
    ({"shape": "bull", "corner_radius_mm": 5.0}, "less than half the tool diameter (5 mm)"),
    ({"shape": "bull", "corner_radius_mm": 0.0}, "more than 0"),
    ({"shape": "bull", "corner_radius_mm": float("nan")}, "corner radius"),
    ({"shape": "ball", "corner_radius_mm": 1.0}, "not a ball end"),
])
def test_a_bull_nose_needs_a_corner_radius_within_its_radius(kwargs, message):
    with pytest.raises(InputError, match=None) as e:
        Tool(diameter_mm=10.0, **kwargs)
    assert message in str(e.value)


def test_drop_cutter_refuses_a_corner_for_other_shapes(ex4):
    with pytest.raises(ToolpathError, match="corner radius"):
        drop_cutter(ex4, 2.0, 2.0, 0.3, "flat", corner=0.1)
    with pytest.raises(ToolpathError, match="corner radius"):
        drop_cutter(ex4, 2.0, 2.0, 0.3, "bull", corner=0.3)


def _feed_samples(moves, per_move=4):
    """Points along every feed move whose ends have a known Z: the start of each and ``per_move - 1`` between."""
    p, rapid, zk = moves.points_mm, np.asarray(moves.rapid, bool), np.asarray(moves.z_known, bool)
    use = ~rapid[1:] & zk[:-1] & zk[1:]
    a, b = p[:-1][use], p[1:][use]
    s = np.linspace(0.0, 1.0, per_move + 1)[:-1]
    return (a[:, None, :] + s[None, :, None] * (b - a)[:, None, :]).reshape(-1, 3)


@pytest.fixture(scope="module")
def bull_program(tmp_path_factory):
    from lagsym.cli import main
    import io

    path = tmp_path_factory.mktemp("bull") / "bull.nc"
    out, err = io.StringIO(), io.StringIO()
    status = main(["toolpath", str(EX2), "--scale", "10", "--tool-shape", "bull", "--tool-diameter", "10",
                   "--corner-radius", "2", "--stepover", "2", "--step", "1", "--safe-z", "40", "-o", str(path)],
                  out, err)
    assert status == 0, err.getvalue()
    lift = float(re.search(r"largest lift for chordal error ([0-9.]+) mm", out.getvalue() + err.getvalue()).group(1))
    return path, lift


@pytest.mark.slow
def test_the_bull_nose_toolpath_never_cuts_into_the_part(bull_program):
    """At every point of every feed move the tool lies on or above the surface (brute force, 0.1 mm lattice)."""
    bull_program, lift = bull_program
    surface = lagrange_surface(read_points(EX2))
    moves = parse_moves(bull_program.read_text())
    samples = _feed_samples(moves)
    x0, x1, y0, y1 = (10.0 * float(v) for v in surface.grid.bounds)
    near = (samples[:, 0] > x0 - 5) & (samples[:, 0] < x1 + 5) & (samples[:, 1] > y0 - 5) & (samples[:, 1] < y1 + 5)
    samples = samples[near]
    assert len(samples) > 1500
    px, py = np.clip(samples[:, 0], x0, x1) / 10.0, np.clip(samples[:, 1], y0, y1) / 10.0
    touch = np.hypot(samples[:, 0] - 10 * px, samples[:, 1] - 10 * py) <= 5.0
    need = 10.0 * brute_bull(surface, samples[touch, 0] / 10.0, samples[touch, 1] / 10.0, 0.5, 0.2, n=101)
    dip = need - samples[touch, 2]
    assert dip.max() <= 10.0 ** -3 + 1e-9, f"{dip.max():.4f} mm into the part"  # the program's Z resolution
    # and it finishes: at the cutter locations the tool is no higher than the lift the command reports
    cl = moves.points_mm[~np.asarray(moves.rapid, bool) & np.asarray(moves.z_known, bool)]
    cl = cl[(cl[:, 0] > x0) & (cl[:, 0] < x1) & (cl[:, 1] > y0) & (cl[:, 1] < y1)][::37]
    fine = 10.0 * brute_bull(surface, cl[:, 0] / 10.0, cl[:, 1] / 10.0, 0.5, 0.2, n=401)
    assert 0.0 < lift < 0.1 and np.max(cl[:, 2] - fine) <= lift + 2e-3


@pytest.mark.slow
def test_the_bull_nose_program_reads_in_the_interpreter_and_verifies(run_cli, bull_program, rs274):
    from gcheck import interpret

    bull_program, _ = bull_program
    text = bull_program.read_text()
    assert "(T1 BULL NOSE D10 R2 MM)" in text
    feeds, _ = interpret(rs274, text)
    assert len(feeds) > 400
    status, out, err = run_cli("verify", EX2, bull_program, "--scale", "10", "--tool-shape", "bull",
                               "--tool-diameter", "10", "--corner-radius", "2")
    # A 2 mm side step with a 2 mm corner leaves cusps of over a millimetre on the 74 degree flanks: beyond the
    # default --max-left of 0.1 mm, and the only finding.
    assert status == 1 and "worst gouge" in out and ": none" in out.split("worst gouge")[1].splitlines()[0], out
    assert "TOO MUCH" in out.split("material left")[1].splitlines()[0] and "rapid into part" in out, out
    status, out, err = run_cli("verify", EX2, bull_program, "--scale", "10", "--tool-shape", "bull",
                               "--tool-diameter", "10", "--corner-radius", "2", "--max-left", "2")
    assert status == 0, out + err
    # verify draws the tool it is told: a flat end of the same diameter on this path cuts into the part
    status, out, _ = run_cli("verify", EX2, bull_program, "--scale", "10", "--tool-shape", "flat",
                             "--tool-diameter", "10")
    assert status == 1 and "GOUGE" in out


@pytest.mark.parametrize("args, message", [
    (["--tool-shape", "bull", "--tool-diameter", "10"], "--corner-radius"),
    (["--tool-shape", "bull", "--tool-diameter", "10", "--corner-radius", "5"], "less than half"),
    (["--tool-shape", "ball", "--corner-radius", "1"], "bull-nose"),
    (["--tool-shape", "bull", "--tool-diameter", "10", "--corner-radius", "0"], "--corner-radius"),
    (["--tool-shape", "bull", "--tool-diameter", "10", "--corner-radius", "nan"], "--corner-radius"),
])
def test_toolpath_refuses_a_bad_corner_radius(run_cli, args, message):
    status, out, err = run_cli("toolpath", EX2, "--scale", "10", *args)
    assert status == 2 and message in err and len(err.strip().splitlines()) == 1, err


def test_macros_refuse_a_bull_nose(run_cli):
    status, _, err = run_cli("macro", EX2, "--tool-shape", "bull")
    assert status == 2 and "'ball', 'flat'" in err


def test_roughing_with_a_bull_nose_stays_above_the_stock_to_leave(run_cli, tmp_path):
    target = tmp_path / "rough.nc"
    status, out, err = run_cli("rough", EX2, "--scale", "10", "--tool-shape", "bull", "--tool-diameter", "8",
                               "--corner-radius", "1", "--stepdown", "5", "--stepover", "4", "--step", "1",
                               "--stock-to-leave", "0.5", "--stock-above", "2", "--safe-z", "60", "-o", target)
    assert status == 0, err
    text = target.read_text()
    assert "BULL NOSE D8 R1 MM" in text
    pts = _feed_samples(parse_moves(text), per_move=2)
    surface = lagrange_surface(read_points(EX2))
    x0, x1, y0, y1 = (10.0 * float(v) for v in surface.grid.bounds)
    px, py = np.clip(pts[:, 0], x0, x1), np.clip(pts[:, 1], y0, y1)
    touch = np.hypot(pts[:, 0] - px, pts[:, 1] - py) <= 4.0
    pts, px, py = pts[touch], px[touch], py[touch]
    inside = (pts[:, 0] >= x0) & (pts[:, 0] <= x1) & (pts[:, 1] >= y0) & (pts[:, 1] <= y1)
    pts = pts[inside][::7]
    floor = 10.0 * brute_bull(surface, pts[:, 0] / 10.0, pts[:, 1] / 10.0, 0.4, 0.1, n=121) + 0.5
    assert len(pts) > 100 and np.min(pts[:, 2] - floor) >= -2e-3


def test_a_job_takes_a_bull_nose_tool(tmp_path, run_cli):
    job = tmp_path / "job.toml"
    job.write_text(f'''points = "{EX2}"
scale = 10
safe_z = 60
[stock]
top_above = 2
[tools.bull]
number = 2
shape = "bull"
diameter = 8
corner_radius = 1
[[operations]]
kind = "rough"
tool = "bull"
stepdown = 5
stepover = 4
feed = 800
spindle = 4000
''')
    status, out, err = run_cli("job", job, "-o", tmp_path / "job.nc")
    assert status == 0, err
    assert "BULL NOSE D8 R1 MM" in (tmp_path / "job.nc").read_text()
    job.write_text(job.read_text().replace("corner_radius = 1", "corner_radius = 4"))
    status, out, err = run_cli("job", job, "-o", tmp_path / "job2.nc")
    assert status == 2 and "tools.bull." in err and "corner radius" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "job2.nc").exists()
