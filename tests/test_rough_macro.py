"""The parametric roughing macro, run by lagsym's simulator at the control's precision and by LinuxCNC's rs274.

Every move is checked against a drop-cutter written here (a lattice over
the disc, refined around its best points, on the Lagrange basis products of
test_rough, not lagsym's evaluator or drop_cutter): a lower bound of the
exact height, so a tip found below it plus the stock is a real gouge.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from test_rough import EX4, exact_heights, moves, sweep_flat

from lagsym.errors import ToolpathError
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import MachineSettings, Tool
from lagsym.macro.program import RENDERERS
from lagsym.macro.roughing import rough_macro, rough_macro_program
from lagsym.simulate import simulate
from lagsym.toolpath.rough import RoughSpec, rough_toolpath, stock_around

BOX = (20.0, 100.0, 20.0, 100.0)
TOP = 73.6  # 2 mm above the highest point, 71.6 mm
TOL = 0.002  # the 2 um


def profile(shape, radius, corner, d):
    """How far the cutter's edge stands above its tip at distance d from its axis."""
    if shape == "flat":
        return np.zeros_like(d)
    r = radius if shape == "ball" else corner
    e = np.clip(d - (radius - r), 0.0, r)
    return r - np.sqrt(r * r - e * e)


def drop(x, y, shape="flat", radius=5.0, corner=None, n=41):
    """A lower bound of the drop-cutter height at each (x, y): the best of a lattice, refined around it."""
    a = np.linspace(-radius, radius, n)
    ox, oy = np.meshgrid(a, a)
    keep = ox ** 2 + oy ** 2 <= radius ** 2
    ox, oy = ox[keep], oy[keep]

    def best(cx, cy, dx, dy):
        px, py = cx[:, None] + dx, cy[:, None] + dy
        d = np.hypot(px - cx[:, None], py - cy[:, None])
        inside = (d <= radius) & (px >= BOX[0]) & (px <= BOX[1]) & (py >= BOX[2]) & (py <= BOX[3])
        z = np.where(inside, exact_heights(EX4, np.clip(px, 20, 100), np.clip(py, 20, 100))
                     - profile(shape, radius, corner, d), -np.inf)
        k = z.argmax(axis=1)
        rows = np.arange(len(cx))
        return z[rows, k], px[rows, k], py[rows, k]

    x, y = np.asarray(x, float), np.asarray(y, float)
    z, bx, by = best(x, y, ox[None, :], oy[None, :])
    step = 2 * radius / (n - 1)
    for _ in range(3):  # a 9 x 9 lattice around the best point, finer each time
        g = np.linspace(-step, step, 9)
        gx, gy = np.meshgrid(g, g)
        z2, bx2, by2 = best(x, y, (bx - x)[:, None] + gx.ravel(), (by - y)[:, None] + gy.ravel())
        better = z2 > z
        z, bx, by = np.where(better, z2, z), np.where(better, bx2, bx), np.where(better, by2, by)
        step /= 4
    return z


def plan(shape="flat", diameter=10.0, corner=None, dialect="fanuc", precision=8, stepdown=10.0, step=1.0,
         stepover=5.0, margin=0.0, direction="x", ramp_angle_deg=None):
    surface = lagrange_surface(read_points(EX4))
    settings = MachineSettings(dialect=dialect, mm_per_unit=20.0, safe_z_mm=120.0)
    tool = Tool(shape, diameter, corner, ramp_angle_deg=ramp_angle_deg)
    spec = RoughSpec(stepdown, stepover, step, 0.3, direction)
    stock = stock_around(BOX, TOP, margin)
    rm = rough_macro(surface, tool, stock, spec, settings, precision=precision)
    return surface, settings, tool, spec, stock, rm, RENDERERS[dialect](rm.loops, settings, precision=precision)


def feed_points_between(pts):
    """Each feed end point and the midpoint of each move into it."""
    mid = (pts[1:] + pts[:-1]) / 2
    return np.vstack([pts, mid])


def check_gouge_free(pts, shape, radius, corner, stock=0.3):
    """No point (ends and midpoints of the moves) below the lattice drop-cutter height plus the stock."""
    near = ((pts[:, 0] >= BOX[0] - radius) & (pts[:, 0] <= BOX[1] + radius)
            & (pts[:, 1] >= BOX[2] - radius) & (pts[:, 1] <= BOX[3] + radius))
    p = pts[near]
    cl = drop(p[:, 0], p[:, 1], shape, radius, corner)
    gap = p[:, 2] - (cl + stock)
    assert gap.min() >= -TOL, f"{gap.min():.4f} mm below the drop-cutter height plus stock at {p[gap.argmin()]}"
    return gap


@pytest.mark.parametrize("dialect, precision", [("fanuc", 8), ("linuxcnc", 15), ("heidenhain", 8)])
@pytest.mark.slow
def test_simulated_macro_never_goes_below_the_drop_cutter_height(dialect, precision):
    _, _, tool, _, _, rm, text = plan(dialect=dialect, precision=precision)
    sim = simulate(text, dialect, precision)
    pts = sim.feed_points()
    assert len(pts) == len(rm.points_mm) + 1  # the plunge, then every position the loops visit
    # the PC's model of the path is what the control computes (to its arithmetic and resolution)
    assert np.abs(pts[1:] - rm.points_mm).max() <= 2e-3
    check_gouge_free(feed_points_between(pts), "flat", 5.0, None)


@pytest.mark.slow
@pytest.mark.parametrize("shape, diameter, corner", [("ball", 6.0, None), ("bull", 8.0, 1.0)])
def test_ball_and_bull_macros_are_gouge_free(shape, diameter, corner):
    _, _, tool, _, _, rm, text = plan(shape, diameter, corner, dialect="linuxcnc", precision=15, step=1.5,
                                      stepover=diameter / 2, stepdown=20.0)
    pts = simulate(text, "linuxcnc", 15).feed_points()
    check_gouge_free(feed_points_between(pts)[::3], shape, diameter / 2, corner)


@pytest.mark.slow
def test_macro_is_at_or_above_the_point_list_roughing(rs274):
    """Through rs274: at every level the tip is no lower than the point-list roughing's there, to 2 um."""
    surface, settings, tool, spec, stock, rm, text = plan(dialect="linuxcnc", precision=15)
    feeds = np.array([m[1:] for m in moves(rs274, text) if m[0] == "F"])
    assert np.abs(feeds[1:] - rm.points_mm).max() <= 1e-3  # rs274 runs the loops as the model says
    pl = rough_toolpath(surface, tool, stock, spec, settings)
    assert len(rm.levels_mm) <= len(pl.levels_mm)
    assert (rm.levels_mm >= pl.levels_mm[:len(rm.levels_mm)] - TOL).all()
    per_level = len(rm.points_mm) // len(rm.levels_mm)
    p = feeds[1:]
    level = np.repeat(pl.levels_mm[:len(rm.levels_mm)], per_level)
    floor = np.maximum(level, drop(p[:, 0], p[:, 1]) + 0.3)
    near = (p[:, 0] >= 15) & (p[:, 0] <= 105)
    assert (p[near, 2] - floor[near]).min() >= -TOL


@pytest.mark.slow
def test_macro_clears_the_block(rs274):
    """A swept flat end over a height map: no cut into the stock, no rapid or plunge through material, and the
    block is down to the last level's tips everywhere (each at most ``K`` plus ``R |grad F|`` above ``F``)."""
    _, _, _, _, _, rm, text = plan(dialect="linuxcnc", precision=15, stepdown=4.0, step=1.0)
    mv = moves(rs274, text)
    cell = 0.5
    gx = gy = np.arange(10.0, 110.0 + cell / 2, cell)
    fx, fy = np.meshgrid(gx, gy, indexing="ij")
    inbox = (fx >= 20) & (fx <= 100) & (fy >= 20) & (fy <= 100)
    f = np.where(inbox, exact_heights(EX4, np.clip(fx, 20, 100), np.clip(fy, 20, 100)), -np.inf)
    h = np.where(inbox, TOP, -np.inf)
    pos = None
    for kind, x, y, z in mv:
        if pos is not None:
            removed = sweep_flat(h, gx, gy, pos, (x, y, z), 5.0)
            if kind == "T" or (x, y) == pos[:2]:
                assert removed <= 1e-6, f"a rapid or a plunge at {pos} cut {removed} mm"
        pos = (x, y, z)
    assert (h[inbox] - f[inbox]).min() >= 0.3 - TOL
    # the last level's tips over each cell: the block is down to them (and to no less than the stock)
    feeds = np.array([m[1:] for m in mv if m[0] == "F"])
    last = feeds[-len(rm.points_mm) // len(rm.levels_mm):]
    reach = np.full(h.shape, np.inf)
    for x, y, z in last:
        d = (fx - x) ** 2 + (fy - y) ** 2 <= 25.0
        reach[d] = np.minimum(reach[d], z)
    ok = inbox & np.isfinite(reach)
    assert ok[inbox].all()
    assert (h[ok] - np.maximum(reach[ok], f[ok] + 0.3)).max() <= 0.2  # the grid's own error, as in test_rough


@pytest.mark.parametrize("dialect, precision", [("fanuc", 8), ("linuxcnc", 15), ("heidenhain", 8)])
def test_program_size_does_not_grow_with_the_block(dialect, precision):
    """A block 800 mm wider on every side, at a finer step and step-down: 100 times the moves, the same program."""
    small = plan(dialect=dialect, precision=precision)
    big = plan(dialect=dialect, precision=precision, margin=400.0, step=0.5, stepdown=2.0)
    assert len(big[5].points_mm) > 100 * len(small[5].points_mm)
    assert abs(len(big[-1]) - len(small[-1])) <= 20 and len(big[-1].encode()) < 9 * 1024


@pytest.mark.parametrize("milling", ["climb", "conventional"])
def test_one_way_milling_is_refused_for_the_macro(milling):
    surface = lagrange_surface(read_points(EX4))
    with pytest.raises(Exception, match="zig-zag only"):
        rough_macro(surface, Tool("flat", 10.0), stock_around(BOX, TOP), RoughSpec(milling=milling),
                    MachineSettings(dialect="fanuc", mm_per_unit=20.0), precision=8)


@pytest.mark.slow
def test_a_job_with_a_roughing_macro_runs_in_rs274(rs274, tmp_path, run_cli):
    """The example job with its roughing as a macro: rs274 runs the loops, then the finish, as planned."""
    from test_job import job_text

    job = tmp_path / "macro.toml"
    job.write_text(job_text(**{"stepover = 5": "stepover = 5\nstep = 2\nmacro = true", "stepdown = 2": "stepdown = 20",
                               "stepover = 0.5": "stepover = 4", "step = 0.2": "step = 2"}))
    out = tmp_path / "job.ngc"
    status, _, err = run_cli("job", job, "-o", out)
    assert status == 0, err
    text = out.read_text()
    assert "o100 while" in text and "(1 ROUGH MACRO T1" in text and "T2 M06" in text
    feeds = np.array([m[1:] for m in moves(rs274, text, "T1 P1 Z0 D10 ;r\nT2 P2 Z0 D6 ;b\n") if m[0] == "F"])
    from lagsym.job import plan_job, read_job

    rough = plan_job(read_job(job)).operations[0]
    assert np.abs(feeds[1:len(rough.points_mm) + 1] - rough.points_mm).max() <= 1e-3  # after the plunge
    # verify --job runs the macro through the simulator: every move of both tools, no gouge, no crash
    status, report, err = run_cli("verify", "--job", job, out, "--cell", "2")
    assert status == 0, report + err
    # the climb to the safe Z right after the tool change is a move of its own, before X and Y
    line = 1 + [t.split()[:2] for t in text.splitlines()].index(["T1", "M06"])
    assert f"T1 FLAT END D10 MM from line {line}: {len(rough.points_mm) + 4} moves" in report


@pytest.mark.parametrize("args, words", [
    (("--dialect", "grbl", "--macro"), "a roughing macro is written for fanuc or haas or linuxcnc, not grbl"),
    (("--precision", "8",), "--precision 8 applies to a macro only"),
    (("--macro", "--max-samples", "1000"), "--max-samples 1000: a roughing macro makes no drop-cutter samples"),
    (("--macro", "--milling", "conventional"), "a roughing macro cuts zig-zag only"),
    (("--macro", "--max-points", "1000"), "more than the limit of 1e+03"),
])
def test_options_that_do_not_apply_to_the_macro_are_refused(run_cli, args, words):
    status, out, err = run_cli("rough", EX4, "--scale", "20", "--stock-above", "2", "--safe-z", "90", *args)
    assert status == 2 and words in err and err.count("\n") == 1 and not out, err


def test_rough_macro_from_the_command_line_reports_its_size_and_clearance(run_cli, tmp_path):
    out = tmp_path / "O1000.nc"
    status, _, err = run_cli("rough", EX4, "--scale", "20", "--stock-above", "2", "--tool-diameter", "10",
                             "--stepdown", "2", "--safe-z", "90", "--dialect", "fanuc", "--macro", "-o", out)
    assert status == 0, err
    size = len(out.read_bytes())
    assert f"macro: {size} bytes" in err and size < 6 * 1024 and "WHILE [" in out.read_text()


@pytest.mark.parametrize("dialect, precision", [("fanuc", 8), ("linuxcnc", 15)])
def test_inch_rows_along_y_with_an_origin_run_as_planned(dialect, precision):
    """Program units, row direction and work offset change the loops' constants, not where the tool goes."""
    from lagsym.macro.roughing import rough_macro_program

    surface = lagrange_surface(read_points(EX4))
    settings = MachineSettings(dialect=dialect, mm_per_unit=20.0, safe_z_mm=120.0, units="inch",
                               origin_mm=(5.0, -3.0, 1.0))
    rm = rough_macro(surface, Tool("ball", 6.0), stock_around((25.0, 105.0, 17.0, 97.0), 74.6, 3.0),
                     RoughSpec(12.0, 3.0, 1.5, 0.3, "y"), settings, precision=precision)
    text = rough_macro_program(rm, settings)
    assert "G20" in text
    pts = simulate(text, dialect, precision).feed_points() * 25.4
    assert np.abs(pts[1:] - rm.points_mm).max() <= 1e-4
    rows = rm.points_mm[:, 0]
    assert len(np.unique(rows)) < len(np.unique(rm.points_mm[:, 1]))  # rows along y: few X, many Y


def test_a_safe_z_below_the_highest_tip_the_control_moves_to_is_refused():
    # The clearance lifts the tip above the block on steep flanks; the highest feed move the simulated
    # control makes, plus the feed height, is the lowest safe Z the macro may retract to and approach from.
    surface, settings, tool, spec, stock, rm, text = plan(stepdown=30.0, step=2.0, stepover=10.0)
    highest = float(simulate(text, "fanuc", 8).feed_points()[:, 2].max())
    assert highest > stock.top_mm  # above the block, as docs/roughing.md says
    doc = " ".join((EX4.parent.parent / "docs" / "roughing.md").read_text().split())
    assert f"(to {highest:.2f} mm over a {stock.top_mm:.1f} mm block top at a 30 mm step-down" in doc
    need = highest + settings.feed_height_mm
    for safe, ok in ((need - 0.01, False), (need + 0.01, True)):
        low = dataclasses.replace(settings, safe_z_mm=safe)
        if ok:
            rough_macro(surface, tool, stock, spec, low, precision=8)
            continue
        with pytest.raises(ToolpathError, match=r"safe Z .* less than the feed height 2 mm above the highest tip "
                                                r"of the roughing macro .*: raise --safe-z to at least"):
            rough_macro(surface, tool, stock, spec, low, precision=8)


def test_rough_macro_is_refused_where_the_control_cannot_hold_its_variables(run_cli, tmp_path):
    """The variables are counted in the program text itself; a small Fanuc (#100-#149, #500-#531) cannot hold
    them, which the simulator confirms with alarm 115, so --variables small is refused naming them."""
    import re

    from lagsym.simulate import ControlAlarm

    args = ("rough", EX4, "--scale", "20", "--stock-above", "2", "--safe-z", "90", "--dialect", "fanuc", "--macro",
            "--stepdown", "20", "--stepover", "8", "--step", "2", "-o")
    full = tmp_path / "full.nc"
    status, _, err = run_cli(*args, full)
    assert status == 0, err
    text = full.read_text()
    used = sorted({int(n) for n in re.findall(r"#(\d+)", text)})
    small = ((100, 149), (500, 531))
    outside = [n for n in used if not any(lo <= n <= hi for lo, hi in small)]
    assert outside and used[0] == 100 and used[-1] == 627 and len(used) == 178, (used[:3], used[-3:], len(used))
    with pytest.raises(ControlAlarm, match="alarm 115"):
        simulate(text, "fanuc", 8, variable_ranges=small)
    status, out, err = run_cli(*args, tmp_path / "small.nc", "--variables", "small")
    assert status == 2 and not out and err.count("\n") == 1, err
    loops = sorted(n for n in used if n < 500)
    assert f"needs #{loops[0]}-#{loops[-1]} and #500-#{used[-1]} ({len(used)} variables)" in err, err
    assert "#100-#149, #500-#531" in err and not (tmp_path / "small.nc").exists()
    # the same check for --variables full passes, and without --macro the option is refused rather than ignored
    status, _, err = run_cli(*args, tmp_path / "again.nc", "--variables", "full")
    assert status == 0 and (tmp_path / "again.nc").read_text() == text, err
    status, _, err = run_cli(*args[:10], "--variables", "small")
    assert status == 2 and "--variables small applies to a macro only" in err


@pytest.mark.slow
def test_a_job_file_variables_profile_is_checked_for_its_roughing_macro(run_cli, tmp_path):
    from test_job import job_text

    job = tmp_path / "small.toml"
    job.write_text(job_text(**{"stepover = 5": "stepover = 8\nstep = 2\nmacro = true", "stepdown = 2": "stepdown = 20",
                               'dialect = "linuxcnc"': 'dialect = "fanuc"\nvariables = "small"'}))
    status, _, err = run_cli("job", job, "-o", tmp_path / "job.nc")
    assert status == 2 and "#500-#627 is outside the small variable profile of a fanuc control" in err, err
    job.write_text(job_text(**{'dialect = "linuxcnc"': 'dialect = "fanuc"\nvariables = "small"'}))
    status, _, err = run_cli("job", job, "-o", tmp_path / "job.nc")
    assert status == 2 and "variables = 'small' applies to a roughing macro only" in err, err


BUMP = [(x, y, 3 if (x, y) == (2, 2) else 0) for x in (0, 2, 4) for y in (0, 2, 4)]  # flanks up to 71 degrees
PIT = [(x, y, 0 if (x, y) == (2, 2) else 3 if 2 in (x, y) else 4) for x in (0, 2, 4) for y in (0, 2, 4)]  # a pocket


@pytest.mark.parametrize("dialect, precision, points, scale, box, top", [
    ("fanuc", 8, EX4, 20.0, BOX, TOP), ("linuxcnc", 15, EX4, 20.0, BOX, TOP), ("heidenhain", 8, EX4, 20.0, BOX, TOP),
    ("fanuc", 8, BUMP, 10.0, (0.0, 40.0, 0.0, 40.0), 32.0), ("linuxcnc", 15, PIT, 10.0, (0.0, 40.0, 0.0, 40.0), 42.0)])
def test_a_tool_that_may_not_plunge_gets_a_ramping_macro_in_every_dialect(dialect, precision, points, scale, box,
                                                                          top):
    """From Python: a non-centre-cutting mill (3 degrees) is planned, not refused; the header states the
    angle, and the simulated control never descends over the block steeper than it (one 0.001 mm unit of
    rounding allowed per move), where the same macro planned to plunge does: on Example 4, a bump and a pit."""
    from lagsym.grid import grid_from_points

    surface = lagrange_surface(read_points(points) if points is EX4 else grid_from_points(points))
    settings = MachineSettings(dialect=dialect, mm_per_unit=scale, safe_z_mm=120.0)
    steepest = {}
    for angle in (None, 90.0):
        tool = Tool("flat", 10.0, centre_cutting=angle is not None, ramp_angle_deg=angle)
        rm = rough_macro(surface, tool, stock_around(box, top), RoughSpec(10.0, 5.0, 1.0, 0.3), settings,
                         precision=precision)
        text = rough_macro_program(rm, settings)
        assert f"RAMP INTO MATERIAL AT MOST {tool.max_ramp_deg:g} DEG" in text
        pts = simulate(text, dialect, precision).feed_points()
        a, b = pts[:-1], pts[1:]
        run = np.hypot(*(b[:, :2] - a[:, :2]).T)
        over = (b[:, 0] >= box[0]) & (b[:, 0] <= box[1]) & (run > 0)
        fall = (a[:, 2] - b[:, 2])[over] - 1e-3
        steepest[angle] = float(np.degrees(np.arctan2(fall, run[over])).max())
    assert 2.0 < steepest[None] <= 3.0 and steepest[90.0] > 60.0, steepest
