"""Programs as blocks: the numbering ``--start-block`` uses and what a 7-bit line cannot carry."""

from __future__ import annotations

import pytest

from lagsym.dnc import parse_program
from lagsym.dnc.blocks import check_drip
from lagsym.errors import InputError


def test_blocks_are_the_non_empty_lines_inside_the_percent_framing():
    p = parse_program("%\r\nO1000\r\n\r\nG21 G90 \r\nM30\r\n%\r\n")
    assert p.blocks == ("O1000", "G21 G90", "M30")
    assert p.block(1) == "O1000"


@pytest.mark.parametrize("text, words", [
    ("O1\nG0 X1.\x13\n", "DC3"),
    ("O1\nG0 X1.é\n", "7-bit"),
    ("O1\n%\nG0 X1.\n", "after the closing %"),
    ("%\n\n%\n", "no blocks"),
])
def test_programs_a_line_cannot_carry_are_refused_with_the_line(text, words):
    with pytest.raises(InputError, match=words):
        parse_program(text, "p.nc")


@pytest.mark.parametrize("block", ["WHILE[#1LT3]DO1", "END1", "GOTO10", "IF[#1GT0]GOTO5", "N20M99", "M99P10",
                                   "o100 endwhile"])
def test_a_drip_feed_refuses_loops_jumps_and_returns_however_written(block):
    with pytest.raises(InputError, match="loops or jumps"):
        check_drip(parse_program(f"O1\n#1=0\n{block}\nM30", "p.nc"))


@pytest.mark.parametrize("block", ["G65 P9010 A1.", "M98P100", "#1=#1+1.", "IF[#1GT0]THEN#2=1", "G1 X1. (GOTO 10)",
                                   "5 END PGM 1 MM"])
def test_a_drip_feed_may_call_and_compute(block):
    check_drip(parse_program(f"O1\n{block}\nM30", "p.nc"))
