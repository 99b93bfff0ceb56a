"""Rest finishing: a finish with ``rest = true`` passes only where the operations before left material.

The example (examples/example-4-rest-finish-job.toml: a 10 mm flat end, a
6 mm ball, then a 2 mm ball marked rest) is run through LinuxCNC's rs274, and
so is the same job with the 2 mm ball's whole raster (``rest`` left out).
Their moves are pressed, tool by tool, into a NumPy height map of the block
written in the tests (the flat end swept exactly along each move, a ball
stamped at most 0.1 mm apart along it) and compared with the interpolating
polynomial evaluated from the control points.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from conftest import made_once
from test_job import EX4, _densified, _machined, _tight_hollows, run_job, stamp_ball

from lagsym.errors import ToolpathError
from lagsym.machine import Tool
from lagsym.toolpath.rest import StockMap
from lagsym.toolpath.restfinish import rest_finish

ROOT = Path(__file__).resolve().parent.parent
JOB = ROOT / "examples" / "example-4-rest-finish-job.toml"
TOOLS = "T1 P1 Z0 D10 ;rougher\nT2 P2 Z0 D6 ;ball6\nT3 P3 Z0 D2 ;ball2\n"
R_BALL, R_SMALL = 3.0, 1.0
CELL = 0.25


def _text(rest: bool) -> str:
    text = JOB.read_text().replace('points = "paper-example-4.json"', f'points = "{EX4.as_posix()}"')
    return text if rest else text.replace("rest = true\n", "")


@pytest.fixture(scope="module")
def runs(tmp_path_factory, rs274):
    """The job with the rest finish and with the small ball's whole raster: (program, printed, rs274's moves)."""
    return {rest: made_once(tmp_path_factory, f"rest-finish-{rest}",
                            lambda rest=rest: run_job(tmp_path_factory.mktemp("rf"), _text(rest), rs274, TOOLS)[:3])
            for rest in (True, False)}


def _maps(moves_rest, moves_full):
    # The rough and the 6 mm finish, as the plain job's test cuts them (the same tools, numbers and cells).
    fx, fy, f, _, left = _machined(moves_rest)
    gx, gy = fx[:, 0], fy[0, :]
    before = f + left
    h = before.copy()
    stamp_ball(h, gx, gy, _densified([m for m in moves_rest if m[0] == 3], 0.1), R_SMALL)
    full = before.copy()
    stamp_ball(full, gx, gy, _densified([m for m in moves_full if m[0] == 3], 0.1), R_SMALL)
    return dict(f=f, before=before, rest=h, full=full, fx=fx, fy=fy)


@pytest.fixture(scope="module")
def maps(runs, tmp_path_factory):
    return made_once(tmp_path_factory, "rest-finish-maps", lambda: _maps(runs[True][2], runs[False][2]))


@pytest.mark.slow
def test_the_rest_finish_passes_in_runs_and_says_so(runs):
    text, printed, moves = runs[True]
    _, printed_full, moves_full = runs[False]
    m = re.search(r"finish rest T3: (\d+) moves, about ([\d.]+) min, in (\d+) runs over ([\d.]+) % of its raster",
                  printed)
    assert m, printed
    full = re.search(r"finish T3: (\d+) moves, about ([\d.]+) min", printed_full)
    assert int(m[1]) < 0.2 * int(full[1]) and float(m[2]) < 0.25 * float(full[2]), (m[0], full[0])
    assert "(3 FINISH REST T3 BALL END D2 MM" in text
    small = [mv for mv in moves if mv[0] == 3]
    entries = sum(1 for a, b in zip(small[:-1], small[1:]) if not a[1] and b[1])  # rapid, then feed: a run begins
    assert entries == int(m[3]) > 1
    page = " ".join((ROOT / "docs" / "toolpaths.md").read_text().split())
    assert (f"{m[1]} moves ({m[3]} runs, {float(m[4]):.1f} % of its raster) where the whole raster takes "
            f"{full[1]}") in page


@pytest.mark.slow
def test_where_the_whole_raster_would_cut_the_rest_finish_cuts_too(maps):
    """No gouge; nowhere much more left than the small ball's whole raster leaves: the rest finish lets stand
    what lagsym's stock map (0.2 mm cells) shows at most 0.02 mm above the tool's tip.  docs/toolpaths.md quotes
    the most, normal to the surface and vertically."""
    f, rest, full = maps["f"], maps["rest"], maps["full"]
    assert np.min(rest - f) >= -0.002, np.min(rest - f)
    _, w = _tight_hollows(f, CELL, R_BALL)
    more = rest - full
    k = np.unravel_index(np.argmax(more / w), more.shape)
    assert (more / w).max() <= 0.02 + 0.005, ((more / w).max(), maps["fx"][k], maps["fy"][k])
    page = " ".join((ROOT / "docs" / "toolpaths.md").read_text().split())
    assert (f"at most {(more / w).max():.3f} mm normal to the surface ({more.max():.3f} mm vertically) more than "
            "the whole raster") in page


@pytest.mark.slow
def test_the_rest_finish_takes_what_the_finishing_ball_left_in_hollows_tighter_than_it(maps):
    """docs/toolpaths.md: the most left normal to the surface, a ball radius inside the box, before and after."""
    f, fx, fy = maps["f"], maps["fx"], maps["fy"]
    tight, w = _tight_hollows(f, CELL, R_BALL)
    inner = (fx >= 20 + R_BALL) & (fx <= 100 - R_BALL) & (fy >= 20 + R_BALL) & (fy <= 100 - R_BALL)
    before = float(((maps["before"] - f) / w)[inner].max())
    after = float(((maps["rest"] - f) / w)[inner].max())
    hollow_before = float(((maps["before"] - f) / w)[inner & tight].max())
    hollow_after = float(((maps["rest"] - f) / w)[inner & tight].max())
    assert after < 0.6 * before and hollow_after < hollow_before / 2, (before, after, hollow_before, hollow_after)
    page = " ".join((ROOT / "docs" / "toolpaths.md").read_text().split())
    assert (f"at most {before:.3f} mm normal to the surface before it and {after:.3f} mm after it; in the hollows "
            f"tighter than the 6 mm ball, {hollow_before:.3f} mm before and {hollow_after:.3f} mm after") in page


def test_a_rest_finish_over_a_stock_left_below_its_reach_is_refused_with_the_figure():
    xs = np.arange(0.0, 10.5, 0.5)
    row = type("Row", (), dict(points_mm=np.column_stack([xs, np.full(21, 1.0), np.zeros(21)]),
                               rows=np.zeros(21, dtype=int), tool=Tool("ball", 1.0)))
    left = StockMap(xs, np.arange(5.0), np.full((21, 5), 0.03))
    with pytest.raises(ToolpathError, match=r"stands at most 0\.030 mm above what it reaches \(less than 0\.05 mm\)"):
        rest_finish(row, left, 10.0, above_mm=0.05)
