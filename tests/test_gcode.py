"""The point-list G-code reader agrees with LinuxCNC's interpreter and refuses what it cannot read."""

from __future__ import annotations

import numpy as np
import pytest

from lagsym.errors import ProgramError
from lagsym.gcode import parse_moves
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import MachineSettings, RasterSpec, Tool
from lagsym.post.program import point_program, write_program
from lagsym.toolpath import plan_toolpath

from conftest import EXAMPLES
from gcheck import interpret

HANDWRITTEN = """%
O0007 (HAND WRITTEN)
N10 G20 G90 G17 ; inches
N20 G0 X1 Y.5 Z2.
N30 G1 Z-.1 F10.
N40 X2.
N50 G91 Y0.25 Z+0.05 (incremental)
N60 X-1.
N70 G90 G21 G01 X10. Y10. Z1.
N80 G00 Z50.
N90 M30
%
"""


def test_reads_what_rs274_does(rs274):
    moves = parse_moves(HANDWRITTEN)
    feeds, travs = interpret(rs274, HANDWRITTEN)
    np.testing.assert_allclose(moves.points_mm[~moves.rapid], feeds, atol=1e-4)
    np.testing.assert_allclose(moves.points_mm[moves.rapid], travs, atol=1e-4)
    assert moves.line.tolist() == [4, 5, 6, 7, 8, 9, 10]
    assert moves.feed_mm_min[1] == pytest.approx(254.0)


@pytest.mark.parametrize("dialect", ["fanuc", "linuxcnc", "grbl"])
def test_reads_every_dialect_lagsym_writes(rs274, dialect):
    surf = lagrange_surface(read_points(EXAMPLES / "paper-example-2.json"))
    s = MachineSettings(dialect=dialect, mm_per_unit=10.0, safe_z_mm=300.0, units="inch", line_ending="crlf")
    tp = plan_toolpath(surf, Tool("ball", 4.0), RasterSpec("x", 5.0, 2.0), s.placement, s.program, stock_to_leave_mm=s.stock_to_leave_mm)
    text = write_program(point_program(tp, s))
    moves = parse_moves(text)
    feeds, _ = interpret(rs274, text)
    np.testing.assert_allclose(moves.feeds, feeds, atol=1e-4 * 25.4)
    # up to safe Z, over the start, down to the feed height, back up at the end
    assert np.count_nonzero(moves.rapid) == 4


@pytest.mark.parametrize("text, match", [
    ("G0 X1\nG2 X2 Y2 R1\n", "by its radius"),
    ("G0 X1\nG28\n", "G28 moves through the reference point"),
    ("G0 X1 (open comment\n", "unclosed comment"),
    ("X1 Y2\n", "before any G00"),
    ("G0 X1 X2\n", "X given twice"),
    ("G1 X1 Q3\n", "Q3"),
    ("G1 X1 #1=2\n", "cannot read"),
])
def test_refuses_what_it_cannot_read_and_names_the_line(text, match):
    with pytest.raises(ProgramError, match=match) as info:
        parse_moves(text, source="part.nc")
    assert "part.nc, line" in str(info.value)


def test_stops_at_the_closing_percent_and_skips_comments():
    moves = parse_moves("%\nG1 X1 F1 ;c\n(G1 X9)\n%\nG1 X5\n")
    assert moves.points_mm.tolist() == [[1.0, 0.0, 0.0]]
    assert moves.path_mm.shape == (2, 3)


def test_moves_are_read_only():
    moves = parse_moves("G1 X1 F1\n")
    with pytest.raises(ValueError):
        moves.points_mm[0, 0] = 3.0


# A main program and its subprogram in one file, as LinuxCNC (2.9) and a Fanuc run it: M98 moves the tool to the
# subprogram's X5 Y5 Z0, which a reader that skipped the call would never see.
CALLED = "G21 G90\nG1 X1. Y1. Z1. F100.\nM98 P2000\nM30\nO2000\nG1 X5. Y5. Z0.\nM99\n%\n"


def test_a_subprogram_call_moves_the_tool_and_is_refused_naming_its_line(rs274):
    feeds, _ = interpret(rs274, CALLED)
    assert [5.0, 5.0, 0.0] in feeds.tolist()  # the call moves the tool: skipping it would report another path
    with pytest.raises(ProgramError, match=r"part.nc, line 3: M98 calls a subprogram") as info:
        parse_moves(CALLED, source="part.nc")
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("block, words", [
    ("M98 P2000", "M98 calls a subprogram"), ("M97 P20", "M97 calls a subprogram"),
    ("M198 P2000", "M198 calls a subprogram"), ("M99", "M99 returns from a subprogram"),
    ("G65 P9010 A1.", "G65 calls a macro"), ("G66 P9010", "G66 calls a macro"),
    ("G81 X1. Y1. Z-1. R1.", "G81 is a canned cycle"), ("G83 X1. Y1. Z-1. R1. Q1.", "G83 is a canned cycle"),
    ("G04 X1.", "G04 dwells"), ("G53 G0 Z0.", "G53 moves in machine coordinates"),
    ("G52 X10.", "G52 shifts the coordinates"), ("G68 X0 Y0 R30.", "G68 rotates the coordinates"),
    ("G51 X0 Y0 P2", "G51 scales the coordinates"), ("G41 D1", "G41 offsets the path"),
    ("G10 L2 P1 X5.", "G10 sets offsets"), ("M47", "M47 may call a subprogram or move the tool"),
])
def test_calls_cycles_shifts_and_unknown_m_codes_are_refused(block, words):
    with pytest.raises(ProgramError, match=words) as info:
        parse_moves(f"G21 G90\nG1 X1. Y1. Z1. F100.\n{block}\nG1 X2.\nM30\n", source="part.nc")
    assert "part.nc, line 3:" in str(info.value)


def test_a_move_after_the_end_is_refused_and_set_up_words_pass(rs274):
    with pytest.raises(ProgramError, match="line 4: a move after the end of the program .M02 or M30 on line 3."):
        parse_moves("G21 G90\nG1 X1. Y1. Z1. F100.\nM30\nG1 X5.\n", source="part.nc")
    # the set-up words a program may hold (tool, length offset, work offsets, path control, spindle, coolant,
    # stops) move nothing: read as rs274 reads them, and a move on the M30 block is made
    text = ("G21 G90 G17 G40 G49 G80 G94 G64 P0.01\nT1 M06\nG59.1\nG00 G43 H1 Z50.\nS1000 M03\nM08\n"
            "G0 X1. Y2.\nM01\nG1 Z-1. F100.\nM00\nX3. M09\nG61\nM05\nG0 Z60. M30\n")
    moves = parse_moves(text)
    feeds, travs = interpret(rs274, text)
    assert moves.points_mm[moves.rapid].tolist() == travs.tolist()
    assert moves.points_mm[~moves.rapid].tolist() == feeds.tolist()
