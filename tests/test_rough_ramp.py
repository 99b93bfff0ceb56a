"""Roughing never drops the flat end's bottom face into material steeper than the tool's ramp angle.

The check is independent of lagsym's planner: LinuxCNC's rs274 reads the
program, a flat end is swept along every move it reports over a height map
of the block (``sweep_flat``, written in the tests), and before each feed
move that descends, the material under the tool's footprint at the move's
end is compared with the tip there.  A descent steeper than the ramp angle
that ends below material is the bottom face entering solid stock.
"""

from __future__ import annotations

import io
import math
import re
import tempfile
from pathlib import Path

import numpy as np
import pytest

from test_rough import EX4, R, STEPDOWN, STOCK, exact_heights, moves, sweep_flat

README = ["rough", str(EX4), "--scale", "20", "--stock-above", "2", "--tool-shape", "flat", "--tool-diameter", "10",
          "--stepdown", "2", "--stepover", "5", "--stock-to-leave", "0.3", "--safe-z", "90", "--dialect", "linuxcnc"]
CELL = 0.25
TOL_MM = 0.01  # material above the tip counted as entered: more than the program's 0.001 mm rounding allows
ROUND_MM = 2e-3  # two coordinates rounded to 0.001 mm can steepen a descent by this much


def _program(extra):
    from lagsym.cli import main

    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "rough.ngc"
        err = io.StringIO()
        assert main(README + extra + ["-o", str(out)], io.StringIO(), err) == 0, err.getvalue()
        return out.read_text()


def _cells():
    """The height maps' cell centres (the box and 10 mm of air around it): axes, grids, and the cells in the box."""
    gx = gy = np.arange(10.0, 110.0 + CELL / 2, CELL)
    fx, fy = np.meshgrid(gx, gy, indexing="ij")
    return gx, gy, fx, fy, (fx >= 20) & (fx <= 100) & (fy >= 20) & (fy <= 100)


def descents_into_stock(mv, limit_deg):
    """Feed moves that descend steeper than ``limit_deg`` and end with material above the tip under the tool.

    Returns (count, deepest entry mm, steepest angle of any descent that ends below material in degrees, the
    height map after the program).
    """
    gx, gy, fx, fy, inbox = _cells()
    top = float(exact_heights(EX4, *np.meshgrid(np.linspace(20, 100, 401), np.linspace(20, 100, 401))).max()) + 2
    h = np.where(inbox, top, -np.inf)  # the block is the box: air around it
    k = int(math.ceil(R / CELL))
    slope = math.tan(math.radians(limit_deg))
    count, deepest, steepest, pos = 0, 0.0, 0.0, None
    for kind, x, y, z in mv:
        if pos is not None and kind == "F" and z < pos[2]:
            i, j = int(round((x - gx[0]) / CELL)), int(round((y - gy[0]) / CELL))
            lo_i, lo_j = max(i - k, 0), max(j - k, 0)
            wx, wy = fx[lo_i:i + k + 1, lo_j:j + k + 1], fy[lo_i:i + k + 1, lo_j:j + k + 1]
            under = (wx - x) ** 2 + (wy - y) ** 2 <= (R - CELL) ** 2  # the footprint, less the grid's own cell
            window = h[lo_i:i + k + 1, lo_j:j + k + 1]
            above = float(np.max(np.where(under, window, -np.inf), initial=-np.inf)) - z
            run, drop = math.hypot(x - pos[0], y - pos[1]), pos[2] - z
            if above > TOL_MM:
                steepest = max(steepest, math.degrees(math.atan2(drop - ROUND_MM, run)))
                if drop > slope * run + ROUND_MM:
                    count += 1
                    deepest = max(deepest, min(above, drop))
        if pos is not None:
            sweep_flat(h, gx, gy, pos, (x, y, z), R)
        pos = (x, y, z)
    return count, deepest, steepest, h


def left_above_reach(mv, h):
    """The most material the map ``h`` holds above what the flat end reaches from the centres the moves pass
    (the lowest lattice drop-cutter height over those centres covering a cell) plus the stock, inside the box."""
    gx, gy, fx, fy, inbox = _cells()
    f = np.where(inbox, exact_heights(EX4, np.clip(fx, 20, 100), np.clip(fy, 20, 100)), -np.inf)
    k = int(round(R / CELL))
    off = [(i, j) for i in range(-k, k + 1) for j in range(-k, k + 1) if (i * i + j * j) * CELL * CELL <= R * R]
    pad = np.pad(f, k, constant_values=-np.inf)
    cl = np.full(f.shape, -np.inf)  # the most over the offsets, one offset at a time
    for i, j in off:
        np.maximum(cl, pad[k + i:k + i + len(gx), k + j:k + j + len(gy)], out=cl)
    passed = np.zeros(cl.shape, dtype=bool)
    for _, x, y, _ in mv:
        i, j = int(round((x - gx[0]) / CELL)), int(round((y - gy[0]) / CELL))
        if 0 <= i < len(gx) and 0 <= j < len(gy):
            passed[i, j] = True
    padc = np.pad(np.where(passed, cl, np.inf), k, constant_values=np.inf)
    reach = np.full(f.shape, np.inf)
    for i, j in off:
        np.minimum(reach, padc[k + i:k + i + len(gx), k + j:k + j + len(gy)], out=reach)
    assert (h[inbox] - f[inbox]).min() >= STOCK - 0.002, "the roughing cut into the stock to leave"
    return float((h[inbox] - (np.maximum(reach[inbox], f[inbox]) + STOCK)).max())


def _page():
    return (Path(__file__).resolve().parent.parent / "docs" / "roughing.md").read_text()


def _cycle(text):
    return float(re.search(r"CYCLE TIME ABOUT (\S+) MIN", text).group(1))


@pytest.mark.slow
@pytest.mark.parametrize("extra, limit, quoted", [
    ([], 15.0, "for the raster (the\nsteepest {s:.2f})"),
    (["--pattern", "offset"], 15.0, "the offset clearing ({s:.2f})"),
    (["--not-centre-cutting"], 3.0, "`--not-centre-cutting` ({s:.2f})"),
    (["--plunge-angle", "30", "--pattern", "offset"], 30.0, None),
])
def test_no_descent_into_stock_is_steeper_than_the_ramp_angle(rs274, extra, limit, quoted):
    """The README roughing (and its offset clearing, a non-centre-cutting mill, a stated angle): no feed move
    enters the block's material going down steeper than the ramp angle the header states, and what is left
    above the tool's reach stays within a step-down; the figures docs/roughing.md quotes."""
    text = _program(extra)
    assert f"RAMP INTO MATERIAL AT MOST {limit:g} DEG" in text
    mv = moves(rs274, text)
    count, deepest, steepest, h = descents_into_stock(mv, limit)
    assert count == 0, (count, deepest)
    assert limit - 1.0 < steepest <= limit + 0.01, steepest  # the stated angle is the one used, and held
    left = left_above_reach(mv, h)
    assert left <= STEPDOWN, left
    page = " ".join(_page().split())
    if quoted:
        assert " ".join(quoted.format(s=steepest).split()) in page
        what = {"[]": "0.75 mm with the ramps", "['--pattern', 'offset']": "0.74 for the offset clearing",
                "['--not-centre-cutting']": "0.86 at 3 degrees"}[str(extra)]
        assert f"{left:.2f}" in what and what in page, (left, what)
    if not extra:
        assert f"{len(text)} bytes and its cycle time from 120.2 to {_cycle(text):.1f} min" in page


@pytest.mark.slow
@pytest.mark.parametrize("extra", [[], ["--pattern", "offset"]])
def test_a_plunge_angle_of_90_descends_as_the_surface_falls(rs274, extra):
    """``--plunge-angle 90`` (a centre-cutting mill that may plunge) is taken, not ignored: it plans as before
    the ramps, and the descents into stock docs/roughing.md quotes are its."""
    text = _program(["--plunge-angle", "90"] + extra)
    assert "RAMP INTO MATERIAL AT MOST 90 DEG" in text
    mv = moves(rs274, text)
    count, deepest, steepest, h = descents_into_stock(mv, 15.0)
    assert count > 0 and steepest > 60, (count, steepest)
    page = " ".join(_page().split())
    what = "the raster does so in" if not extra else "the offset clearing in"
    assert f"{what} {count} moves, up to {deepest:.2f} mm deep and {steepest:.0f} degrees steep" in page
    if not extra:
        assert f"grows from {len(text)} to" in page and f"cycle time from {_cycle(text):.1f} to" in page
        assert f"on that height map {left_above_reach(mv, h):.2f} mm at 90 degrees" in " ".join(_page().split())


@pytest.mark.parametrize("extra, words", [
    (["--plunge-angle", "0"], "--plunge-angle"),
    (["--plunge-angle", "91"], "--plunge-angle"),
    (["--not-centre-cutting", "--plunge-angle", "90"], "cannot make"),
    (["--plunge-angle", "0.5", "--max-points", "110000"], "with its ramps at 0.5 degrees is"),
])
@pytest.mark.slow
def test_a_tool_that_may_not_plunge_is_refused_where_it_would(run_cli, tmp_path, extra, words):
    out = tmp_path / "r.nc"
    status, _, err = run_cli(*README, *extra, "-o", out)
    assert status == 2 and words in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


JOB = """points = "{points}"
dialect = "linuxcnc"
scale = 20
safe_z = 90

[stock]
top_above = 2

[tools.rougher]
number = 1
shape = "flat"
diameter = 10
{extra}

[[operations]]
kind = "rough"
tool = "rougher"
stepdown = 30
stepover = 5
step = 1
"""


@pytest.mark.parametrize("extra, status, words", [
    ("centre_cutting = false", 0, "RAMP INTO MATERIAL AT MOST 3 DEG"),
    ("centre_cutting = false\nplunge_angle = 5", 0, "RAMP INTO MATERIAL AT MOST 5 DEG"),
    ("plunge_angle = 40", 0, "RAMP INTO MATERIAL AT MOST 40 DEG"),
    ("centre_cutting = \"no\"", 2, "tools.rougher.centre_cutting = 'no' must be true or false"),
    ("plunge_angle = 0", 2, "tools.rougher.plunge_angle = 0"),
    ("centre_cutting = false\nplunge_angle = 90", 2, "cannot make"),
])
@pytest.mark.slow
def test_the_job_file_gives_the_tool_its_ramp(run_cli, tmp_path, extra, status, words):
    job = tmp_path / "j.toml"
    job.write_text(JOB.format(points=EX4.as_posix(), extra=extra))
    out = tmp_path / "j.ngc"
    got, _, err = run_cli("job", job, "-o", out)
    assert got == status, err
    assert words in (out.read_text() if status == 0 else err)


def _left_above_surface(h):
    """Material the height map ``h`` holds above the exact surface plus the stock, over the box's cells."""
    _, _, fx, fy, inbox = _cells()
    left = h[inbox] - (exact_heights(EX4, fx[inbox], fy[inbox]) + STOCK)
    return float(left.mean()), float(left.max())


@pytest.mark.slow
@pytest.mark.parametrize("extra, limit", [([], 15.0), (["--not-centre-cutting"], 3.0),
                                          (["--plunge-angle", "90"], 90.0)])
def test_the_roughing_macro_ramps_at_the_tool_angle(rs274, extra, limit):
    """The roughing macro, run by rs274 (the control computes every tip): no feed move enters the block's
    material going down steeper than the angle its header states, a plunging one (90) does, and the material
    each leaves above the surface plus the stock is the figure docs/roughing.md quotes."""
    text = _program(["--macro", "--stepdown", "6"] + extra)  # a third of the README's levels: the same rows
    assert f"RAMP INTO MATERIAL AT MOST {limit:g} DEG" in text
    mv = moves(rs274, text)
    count, deepest, steepest, h = descents_into_stock(mv, min(limit, 15.0))
    page = " ".join(_page().split())
    mean, most = _left_above_surface(h)
    if limit < 90:
        assert count == 0 and limit - 1.0 < steepest <= limit + 0.01, (count, deepest, steepest)
        assert f"{mean:.2f} mm on average and {most:.2f} at most" in page, (mean, most)
    else:
        assert count > 0 and steepest > 60, (count, steepest)
        assert f"plunging macro descends into material in {count} moves, up to {deepest:.2f} mm" in page
        assert f"leaves {mean:.2f} mm on average above the surface plus the stock ({most:.2f} at most" in page
