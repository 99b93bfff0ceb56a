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
import tempfile
from pathlib import Path

import numpy as np
import pytest

from test_rough import EX4, R, exact_heights, moves, sweep_flat

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


def descents_into_stock(mv, limit_deg):
    """Feed moves that descend steeper than ``limit_deg`` and end with material above the tip under the tool.

    Returns (count, deepest entry mm, steepest angle of any descent that ends below material, degrees).
    """
    gx = gy = np.arange(10.0, 110.0 + CELL / 2, CELL)
    fx, fy = np.meshgrid(gx, gy, indexing="ij")
    inbox = (fx >= 20) & (fx <= 100) & (fy >= 20) & (fy <= 100)
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
    return count, deepest, steepest


@pytest.mark.slow
@pytest.mark.parametrize("extra, limit", [
    ([], 15.0),
    (["--pattern", "offset"], 15.0),
    (["--not-centre-cutting"], 3.0),
    (["--plunge-angle", "30", "--pattern", "offset"], 30.0),
])
def test_no_descent_into_stock_is_steeper_than_the_ramp_angle(rs274, extra, limit):
    """The README roughing (and its offset clearing, a non-centre-cutting mill, a stated angle): no feed move
    enters the block's material going down steeper than the ramp angle the header states.  Before ramping, the
    raster made 1,400 such moves, up to 1.86 mm deep at 75 degrees."""
    text = _program(extra)
    assert f"RAMP INTO MATERIAL AT MOST {limit:g} DEG" in text
    count, deepest, steepest = descents_into_stock(moves(rs274, text), limit)
    assert count == 0, (count, deepest)
    assert steepest <= limit + 0.01, steepest
