"""Rest roughing: a job's rough operation with ``rest = true`` cuts only what the operations before it left.

The example job with a rest stage (examples/example-4-rest-job.toml) is run
through LinuxCNC's rs274 and its moves pressed, tool by tool, into a NumPy
height map of the block written in the tests (the flat end swept exactly
along each move, a ball stamped at most 0.1 mm apart along it), compared
with the interpolating polynomial evaluated from the control points.  The
rough and the finish are planned the same with the rest stage or without
it, so leaving the rest tool's moves out of the same program gives the job
without it: what the finishing ball takes in one go is measured both ways.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from conftest import made_once
from test_job import EX4, _densified, finish_excess, run_job, stamp_ball
from test_rough import exact_heights, sweep_flat

ROOT = Path(__file__).resolve().parent.parent
REST_JOB = ROOT / "examples" / "example-4-rest-job.toml"
TOOLS = "T1 P1 Z0 D10 ;rougher\nT2 P2 Z0 D6 ;ball\nT3 P3 Z0 D4 ;rest\n"
R_FLAT, R_FINISH, R_REST, REST_STOCK = 5.0, 3.0, 2.0, 0.15
CELL = 0.25


def rest_text(**changes) -> str:
    """The rest example job with the points by absolute path and lines replaced (``old -> new``, once each)."""
    text = REST_JOB.read_text().replace('points = "paper-example-4.json"', f'points = "{EX4.as_posix()}"')
    for old, new in changes.items():
        old = old.replace("_", " ") if old not in text else old
        assert old in text, old
        text = text.replace(old, new, 1)
    return text


@pytest.fixture(scope="module")
def rest_run(tmp_path_factory, rs274):
    """The program, what the command printed, and rs274's moves: (tool, feed?, x, y, z)."""
    text, printed, moves, _ = made_once(tmp_path_factory, "rest-job",
                                        lambda: run_job(tmp_path_factory.mktemp("rest"), rest_text(), rs274, TOOLS))
    return text, printed, moves


def _cut(h, gx, gy, moves, shape, radius):
    if shape == "flat":
        for a, b in zip(moves[:-1], moves[1:]):
            sweep_flat(h, gx, gy, a[2:], b[2:], radius)
    else:
        stamp_ball(h, gx, gy, _densified(moves, 0.1), radius)


@pytest.fixture(scope="module")
def maps(rest_run, tmp_path_factory):
    """The surface, its slope factor, and the height map after the rough, after the rest and after each finish."""
    return made_once(tmp_path_factory, "rest-maps", lambda: _maps(rest_run[2]))


def _maps(moves):
    gx = gy = np.arange(20.0, 100.0 + CELL / 2, CELL)  # the block is the box (no margin)
    fx, fy = np.meshgrid(gx, gy, indexing="ij")
    f = exact_heights(EX4, fx, fy)
    w = np.sqrt(1 + np.gradient(f, CELL, axis=0) ** 2 + np.gradient(f, CELL, axis=1) ** 2)
    of = {t: [m for m in moves if m[0] == t] for t in (1, 2, 3)}
    h = np.full(f.shape, float(f.max()) + 2 + 1e-3)
    _cut(h, gx, gy, of[1], "flat", R_FLAT)
    rough = h.copy()
    _cut(h, gx, gy, of[3], "ball", R_REST)
    rest = h.copy()
    _cut(h, gx, gy, of[2], "ball", R_FINISH)
    plain = rough.copy()
    _cut(plain, gx, gy, of[2], "ball", R_FINISH)
    return dict(f=f, w=w, rough=rough, rest=rest, finished=h, plain=plain, fx=fx, fy=fy)


@pytest.mark.slow
def test_the_rest_job_runs_its_three_tools_in_order_and_says_which_is_rest(rest_run):
    text, printed, moves = rest_run
    assert [t for t in dict.fromkeys(m[0] for m in moves)] == [1, 3, 2]
    assert "(2 ROUGH REST T3 BALL END D4 MM" in text, text[:600]
    assert re.search(r"^rough rest T3: \d+ moves, about [\d.]+ min$", printed, re.M), printed


def _above_tip(h, gx, pts, radius):
    """How far the map ``h`` stands above a ball's lower surface with its tip at each of ``pts`` (most over the
    cells under it; ``-inf`` where none)."""
    cell = gx[1] - gx[0]
    k = int(np.ceil(radius / cell)) + 1
    ix0 = np.rint((pts[:, 0] - gx[0]) / cell).astype(int)
    iy0 = np.rint((pts[:, 1] - gx[0]) / cell).astype(int)
    out = np.full(len(pts), -np.inf)
    for i in range(-k, k + 1):
        for j in range(-k, k + 1):
            ix, iy = ix0 + i, iy0 + j
            ok = (ix >= 0) & (ix < len(gx)) & (iy >= 0) & (iy < len(gx))
            cx, cy = gx[np.clip(ix, 0, len(gx) - 1)], gx[np.clip(iy, 0, len(gx) - 1)]
            d2 = (cx - pts[:, 0]) ** 2 + (cy - pts[:, 1]) ** 2
            ok &= d2 <= radius * radius
            lower = pts[:, 2] + radius - np.sqrt(np.maximum(radius * radius - d2, 0))
            out = np.where(ok, np.maximum(out, h[np.clip(ix, 0, len(gx) - 1), np.clip(iy, 0, len(gx) - 1)] - lower),
                           out)
    return out


@pytest.mark.slow
def test_rest_roughing_leaves_its_stock_and_cuts_where_the_rough_left_material(rest_run, maps):
    """No gouge: the rest ball leaves its stock everywhere.  Every run of its feed moves (from coming down to going
    up) has material the rough left above it under the ball, and most of the box the rough had cleared already.
    """
    f, rest, finished = maps["f"], maps["rest"], maps["finished"]
    assert (rest - f).min() >= REST_STOCK - 0.002, (rest - f).min()
    assert (finished - f).min() >= -0.002
    _, _, moves = rest_run
    pts = np.array([m[2:] for m in moves if m[0] == 3])
    feed = np.array([m[1] for m in moves if m[0] == 3])
    gx = np.arange(20.0, 100.0 + CELL / 2, CELL)
    edges = np.flatnonzero(np.diff(feed.astype(np.int8))) + 1
    runs = [(s, e) for s, e in zip(np.r_[1, edges], np.r_[edges, len(feed)]) if feed[s]]
    # Points at most 0.1 mm apart along each run's moves (move i from point i - 1 to point i), tagged by run.
    dense = [_densified([(0, 0, *p) for p in pts[s - 1:e]], 0.1) for s, e in runs]
    run_of = np.repeat(np.arange(len(runs)), [len(d) for d in dense])
    above = _above_tip(maps["rough"], gx, np.concatenate(dense), R_REST)
    most = np.full(len(runs), -np.inf)
    np.maximum.at(most, run_of, above)
    idle = np.flatnonzero(most <= 0.0)
    # Allowed: a run beside the block, whose ball meets the block's edge cells at its rim (the two maps' cells
    # differ there).
    beside = [bool(np.any((pts[runs[k][0]][:2] < 20) | (pts[runs[k][0]][:2] > 100))) for k in idle]
    assert len(runs) > 3000 and idle.size <= 2 and all(beside), (idle.size, [pts[runs[k][0]] for k in idle[:3]])
    # docs/roughing.md: the share of the box where the rough left more than 0.5 mm above what the rest leaves.
    took = maps["rough"] - rest
    assert round(100 * float((took > 0.5).mean())) == 47, (took > 0.5).mean()


@pytest.mark.slow
def test_with_the_rest_stage_the_finishing_ball_takes_at_most_half_a_millimetre(maps):
    """docs/roughing.md: what the 6 mm ball takes in one go, normal to the surface, with and without the rest.

    The depth it takes is the height map before it less the one after it,
    times the cosine of the slope (the material as a layer normal to the
    surface); over the whole box, edges included.
    """
    w = maps["w"]
    with_rest = (maps["rest"] - maps["finished"]) / w
    without = (maps["rough"] - maps["plain"]) / w
    vertical_without = maps["rough"] - maps["plain"]
    assert round(float(with_rest.max()), 2) == 0.46, with_rest.max()
    assert round(float(without.max()), 2) == 5.58, without.max()
    assert round(float(vertical_without.max()), 2) == 17.17, vertical_without.max()
    assert round(100 * float((without > 0.5).mean()), 1) == 40.5, (without > 0.5).mean()
    page = " ".join((Path(__file__).parents[1] / "docs" / "roughing.md").read_text().split())
    assert ("up to 17.17 mm vertically (5.58 mm normal to the surface" in page
            and "more than 0.5 mm normal over 40.5 % of the box" in page and "at most 0.46 mm normal" in page)


@pytest.mark.slow
def test_after_the_rest_stage_the_finish_meets_its_stated_cusp(rest_run, maps):
    """The rest job's finish leaves at most the cusp it states for its rows (with its chordal tolerance), as
    the plain job's does, measured the same way; and the rest stage leaves no more anywhere than rough and
    finish alone (it only takes material, and the finish passes where it passed without it)."""
    _, printed, moves = rest_run
    f, finished = maps["f"], maps["finished"]
    over, w, at = finish_excess(maps["fx"], maps["fy"], f, finished - f, [m for m in moves if m[0] == 2], printed)
    assert over.max() <= 0, at
    assert np.all(finished <= maps["plain"] + 1e-9)
    assert np.min(finished - f) >= -0.002  # and no gouge


@pytest.mark.slow
def test_rest_rapids_go_through_no_material(rest_run, maps):
    """Each run of the rest tool's rapids, pressed into the map as the moves before it left it, removes nothing."""
    _, _, moves = rest_run
    rest = [m for m in moves if m[0] == 3]
    gx = gy = np.arange(20.0, 100.0 + CELL / 2, CELL)
    h = maps["rough"].copy()
    feed = np.array([m[1] for m in rest])
    edges = np.flatnonzero(np.diff(feed.astype(np.int8))) + 1
    deepest = 0.0
    for s, e in zip(np.r_[1, edges], np.r_[edges, len(rest)]):  # move i runs from point i - 1 to point i
        if e <= s:
            continue
        pts = _densified(rest[s - 1:e], 0.1)
        if feed[s]:
            stamp_ball(h, gx, gy, pts, R_REST)
            continue
        # stamp_ball lowers only the cells within its reach of a point (k cells): compare those.
        k = int(np.ceil(R_REST / CELL)) + 1
        ix, iy = (np.rint((pts[:, c] - 20.0) / CELL).astype(int) for c in (0, 1))
        window = np.s_[max(ix.min() - k, 0):ix.max() + k + 1, max(iy.min() - k, 0):iy.max() + k + 1]
        before = h[window].copy()
        stamp_ball(h, gx, gy, pts, R_REST)
        deepest = max(deepest, float((before - h[window]).max()))
    assert deepest <= 0.002, deepest
    assert np.array_equal(h, maps["rest"])


@pytest.mark.slow
def test_the_finish_states_from_the_safe_side_what_it_takes_in_one_pass(rest_run, maps):
    """The rest job's finish (max_engagement = 0.7) states the most it takes normal to the surface, in its line and
    its header; the tests' own height map after the rest stage (pressed from rs274's moves) stands no further
    above the polynomial, normal to it, anywhere in the box.  docs/roughing.md quotes both figures."""
    text, printed, _ = rest_run
    m = re.search(r"^finish T2: .*, takes at most ([\d.]+) mm normal to the surface \(max_engagement 0\.7 mm\)$",
                  printed, re.M)
    assert m, printed
    assert f"(3 TAKES AT MOST {m.group(1)} MM NORMAL TO THE SURFACE)" in text, text[:800]
    stated, measured = float(m.group(1)), float(((maps["rest"] - maps["f"]) / maps["w"]).max())
    assert measured <= stated <= 0.7, (measured, stated)
    page = " ".join((ROOT / "docs" / "roughing.md").read_text().split())
    assert f"takes at most {stated:.2f} mm normal to the surface" in page
    assert f"the tests' own height map finds {measured:.2f} mm" in page, measured


@pytest.mark.slow
def test_a_finish_deeper_than_its_max_engagement_is_refused_with_the_figure(run_cli, tmp_path, maps):
    """The plain example job (no rest stage) with max_engagement = 0.5 on its finish: refused in one line with the
    figure, no less than how far the tests' own map after the same rough stands above the polynomial, normal to
    it; no program is written.  docs/roughing.md quotes the line."""
    text = (ROOT / "examples" / "example-4-job.toml").read_text()
    text = text.replace('points = "paper-example-4.json"', f'points = "{EX4.as_posix()}"')
    job, out = tmp_path / "plain.toml", tmp_path / "plain.ngc"
    job.write_text(text.replace("step = 0.2\n", "step = 0.2\nmax_engagement = 0.5\n", 1))
    status, stdout, err = run_cli("job", job, "-o", out)
    assert status == 2 and err.count("\n") == 1 and not stdout and not out.exists(), err
    m = re.search(r"operations\[1\] \(finish\): (ball6 would take up to ([\d.]+) mm normal to the surface at "
                  r"X[\d.]+ Y[\d.]+), more than max_engagement = 0\.5 mm: rough what stands there first", err)
    assert m, err
    measured = float(((maps["rough"] - maps["f"]) / maps["w"]).max())
    assert measured <= float(m.group(2)) <= measured + 0.25, (measured, err)
    assert m.group(1) in " ".join((ROOT / "docs" / "roughing.md").read_text().split())


BAD = [
    ({"kind = \"rough\"\ntool = \"rougher\"": "kind = \"rough\"\nrest = true\ntool = \"rougher\""},
     "operations[0].rest = true: no earlier operation leaves a stock to rest-rough"),
    ({"stepover = 0.5": "stepover = 0.5\nrest_above = 0.01"},
     "operations[2].rest_above applies to a rest finish (rest = true)"),
    ({"rest = true": "rest = true\nmacro = true"}, "operations[1].rest = true: rest roughing runs point-list raster "
                                                   "rows, not a roughing macro (macro = true)"),
    ({"rest = true": "rest = true\npattern = \"offset\"\nmilling = \"climb\"", 'direction = "y"\n': ""},
     "operations[1].rest = true: rest roughing runs point-list raster rows, not pattern = offset"),
    ({"rest = true": "rest = 1"}, "operations[1].rest = 1 must be true or false"),
    ({"stock_to_leave = 0.3": "stock_to_leave = 0.3\nmax_engagement = 1"},
     "operations[0].max_engagement does not apply to a rough operation"),
    ({"max_engagement = 0.7": "max_engagement = 0"}, "operations[2].max_engagement = 0 must be a number above 0"),
]


@pytest.mark.parametrize("changes, words", BAD, ids=[w for _, w in BAD])
def test_a_rest_option_where_it_cannot_apply_is_refused_in_one_line(run_cli, tmp_path, changes, words):
    job = tmp_path / "bad.toml"
    job.write_text(rest_text(**changes))
    out = tmp_path / "part.ngc"
    status, stdout, err = run_cli("job", job, "-o", out)
    assert status == 2 and err.count("\n") == 1 and not stdout, err
    assert str(job) in err and words in err, err
    assert not out.exists()


def _plane():
    from lagsym.grid import grid_from_points
    from lagsym.lagrange import lagrange_surface

    return lagrange_surface(grid_from_points([(0, 0, 1), (0, 10, 1), (10, 0, 1), (10, 10, 1)]))


def test_rest_cuts_only_where_the_stock_stands_above_its_floor_and_refuses_when_nothing_does():
    """A plane at z 1 and a stock map 1.3 high but for a 2 mm post 4 mm high: the rest cuts the post alone."""
    from lagsym.errors import ToolpathError
    from lagsym.machine import MachineSettings, Tool
    from lagsym.toolpath.rest import StockMap, rest_toolpath
    from lagsym.toolpath.rough import FEED, RoughSpec, Stock

    xs = ys = np.linspace(0.0, 10.0, 101)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    post = np.hypot(X - 5, Y - 5) <= 1.0
    left = StockMap(xs, ys, np.where(post, 4.0, 1.3))
    stock, spec = Stock(0, 10, 0, 10, 6.0), RoughSpec(1.0, 1.0, 0.5, 0.3)
    rp = rest_toolpath(_plane(), Tool("flat", 2.0), stock, left, spec, MachineSettings())
    feed = rp.points_mm[rp.kinds == FEED]
    assert feed[:, 2].min() >= 1.3 - 1e-9 and feed[:, 2].max() <= 4.0
    assert np.hypot(feed[:, 0] - 5, feed[:, 1] - 5).max() <= 1.0 + 1.0 + 0.5 + 1e-9  # post + radius + one step
    assert sorted(set(np.round(feed[:, 2], 6))) == [1.3, 2.0, 3.0]
    flat = StockMap(xs, ys, np.full(X.shape, 1.32))
    with pytest.raises(ToolpathError, match=r"nothing left for rest roughing with FLAT END D2 MM: the stock left "
                                            r"stands at most 0.020 mm above"):
        rest_toolpath(_plane(), Tool("flat", 2.0), stock, flat, spec, MachineSettings())
