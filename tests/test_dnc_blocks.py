"""Programs as blocks: the numbering ``--start-block`` uses and what a 7-bit line cannot carry."""

from __future__ import annotations

import pytest

from lagsym.dnc import parse_program
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
