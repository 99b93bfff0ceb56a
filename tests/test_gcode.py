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
    ("G0 X1\nG28\n", "G28 is not a straight or circular move"),
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
