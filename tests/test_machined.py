"""A whole job simulated from its block (``lagsym.machined`` and ``lagsym verify --job``).

The checks are analytic: slots of known width and depth cut into a block over a
flat part, whose volumes and remaining heights follow from the tools' shapes.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from lagsym.gcode import parse_moves, tool_changes
from lagsym.grid import grid_from_table
from lagsym.lagrange import lagrange_surface
from lagsym.machine import Tool
from lagsym.machined import LEFT_BINS_MM, machine_part


FLAT = lagrange_surface(grid_from_table([0, 10], [0, 10], [[0, 0], [0, 0]]))
BLOCK = (0.0, 10.0, 0.0, 10.0, 5.0)
TOOLS = {1: Tool("flat", 4.0), 2: Tool("ball", 2.0)}
SLOT = """%
O1
G21 G90
T1 M06
G00 X-5. Y5. Z10.
G00 Z2.
G01 X15. F500.
G00 Z10.
T2 M06
G00 X-5. Y5.
G00 Z1.
G01 X15. F500.
G00 Z10.
M30
%
"""


def _part(text, **kw):
    return machine_part(FLAT, parse_moves(text), tool_changes(text), TOOLS, BLOCK, cell_mm=0.05, **kw)


def test_each_tool_removes_the_slot_its_shape_cuts():
    part = _part(SLOT)
    rough, ball = part.stages
    # The flat end cuts a slot 4 mm wide, 3 mm deep, through the 10 mm block: 120 mm3.
    assert rough.removed_mm3 == pytest.approx(120.0, rel=0.02)
    # The 2 mm ball then goes 1 mm deeper along the slot's middle: a half-cylinder of radius 1 (pi/2 mm2) over 10 mm.
    assert ball.removed_mm3 == pytest.approx(10 * math.pi / 2, rel=0.03)
    assert (rough.tool_number, ball.tool_number) == (1, 2)
    assert rough.left_mm == pytest.approx(5.0) and part.left_mm == pytest.approx(5.0)  # the uncut block beside
    j = np.argmin(np.abs(part.ys_mm - 5.0))
    assert part.final_mm[:, j] == pytest.approx(np.full(len(part.xs_mm), 1.0), abs=0.011)  # the ball's bottom
    assert part.gouge_mm == 0.0 and not part.gouges and not part.crashes


def test_the_histogram_counts_the_box():
    part = _part(SLOT)
    assert len(part.left_share) == len(LEFT_BINS_MM) + 1 and sum(part.left_share) == pytest.approx(1.0)
    # Across the block: 5 mm left beside the slot (6 of its 10 mm), 2 mm on the slot's floor beside the ball's
    # groove (2 of 10 mm), 1 to 2 mm in the groove (2 of 10 mm), nothing below 1 mm.
    assert part.left_share[-1] == pytest.approx(0.6, abs=0.02)  # 5 mm and more
    assert part.left_share[-2] == pytest.approx(0.2, abs=0.02)  # 2 to 5 mm
    assert part.left_share[-3] == pytest.approx(0.2, abs=0.02)  # 1 to 2 mm
    assert sum(part.left_share[:-3]) == pytest.approx(0.0, abs=0.01)


def test_a_rapid_through_the_block_is_a_crash_and_a_cut_below_the_part_a_gouge():
    text = SLOT.replace("G00 Z1.\nG01 X15. F500.", "G00 Z1.\nG00 X15.")
    part = _part(text)
    assert [s.tool_number for s in part.crashes] == [2] and part.stages[1].rapid_cut_mm == pytest.approx(1.0, abs=0.02)
    low = _part(SLOT.replace("G00 Z1.\nG01 X15. F500.", "G00 Z1.\nG01 Z-0.5\nX15. F500."))
    assert low.gouge_mm == pytest.approx(0.5, abs=0.011) and low.gouges
    assert "RAPID INTO MATERIAL" in "\n".join(part.summary())


def _job(tmp_path):
    pts = tmp_path / "flat.json"
    pts.write_text(json.dumps({"units": "mm", "points": [[0, 0, 0], [0, 10, 0], [10, 0, 0], [10, 10, 0]]}))
    job = tmp_path / "job.toml"
    job.write_text('points = "flat.json"\nsafe_z = 20\n[stock]\ntop = 5\n'
                   '[tools.slot]\nnumber = 1\nshape = "flat"\ndiameter = 4\n'
                   '[tools.ball]\nnumber = 2\nshape = "ball"\ndiameter = 2\n'
                   '[[operations]]\nkind = "finish"\ntool = "ball"\nstepover = 1\n')
    prog = tmp_path / "slot.nc"
    prog.write_text(SLOT)
    return job, prog


def test_verify_job_reports_each_tool_and_exits_by_what_it_finds(run_cli, tmp_path):
    job, prog = _job(tmp_path)
    status, out, err = run_cli("verify", "--job", job, prog, "--cell", "0.1")
    assert status == 0, err
    assert "T1 FLAT END D4 MM from line 4" in out and "T2 BALL END D2 MM from line 9" in out
    assert "material left     5.0000 mm at most" in out
    status, out, _ = run_cli("verify", "--job", job, prog, "--cell", "0.1", "--max-left", "1")
    assert status == 1 and "more material left than --max-left 1 mm" in out
    prog.write_text(SLOT.replace("G00 Z1.\nG01 X15. F500.", "G00 Z1.\nG00 X15."))
    status, out, _ = run_cli("verify", "--job", job, prog, "--cell", "0.1")
    assert status == 1 and "RAPID INTO MATERIAL" in out


@pytest.mark.parametrize("args, message", [
    (["--tool-diameter", "6"], "--tool-diameter is not for --job"),
    (["--scale", "2"], "--scale is not for --job"),
    (["--max-scallop", "0.1"], "--max-scallop is for a single program"),
])
def test_verify_job_refuses_the_single_tool_options(run_cli, tmp_path, args, message):
    job, prog = _job(tmp_path)
    status, _, err = run_cli("verify", "--job", job, prog, *args)
    assert status == 2 and message in err and len(err.strip().splitlines()) == 1


def test_verify_job_refuses_a_program_with_an_unknown_tool_or_no_tool_change(run_cli, tmp_path):
    job, prog = _job(tmp_path)
    prog.write_text(SLOT.replace("T2 M06", "T7 M06"))
    status, _, err = run_cli("verify", "--job", job, prog)
    assert status == 2 and "T7 (line 9)" in err and "T1, T2" in err
    prog.write_text(SLOT.replace("T1 M06\n", "").replace("T2 M06\n", ""))
    status, _, err = run_cli("verify", "--job", job, prog)
    assert status == 2 and "no tool change" in err


def test_a_fanuc_program_number_is_not_a_macro_and_a_commented_tool_change_counts(tmp_path):
    from lagsym.job import read_job
    from lagsym.machined import job_moves, machine_job

    job, _ = _job(tmp_path)
    spec = read_job(job)
    # "O1 (SLOT)" was once taken for a LinuxCNC o-word, and the point list run through the simulator.
    text = SLOT.replace("O1\n", "O1 (SLOT)\n")
    moves = job_moves(spec, text)
    assert np.array_equal(moves.feed_mm_min, parse_moves(text).feed_mm_min, equal_nan=True)
    assert np.isnan(moves.feed_mm_min[0])  # no F yet: the point-list reader's NaN, not the simulator's 0
    # In a macro program, a '#' in a comment once blanked its block, tool change and all.
    macro = SLOT.replace("G21 G90\n", "G21 G90\n#1=1.\n").replace("G00 Z1.", "G00 Z#1").replace(
        "T2 M06", "T2 M06 (TOOL #2)")
    part = machine_job(spec, macro, cell_mm=0.1)
    assert [(s.tool_number, s.first_line) for s in part.stages] == [(1, 5), (2, 10)]
    assert part.final_mm.min() == pytest.approx(1.0, abs=0.01)  # the ball went down to Z#1
