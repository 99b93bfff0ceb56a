"""A whole program read block by block: its framing, its units, and what in it is a macro.

Every reader of a program in lagsym (the point-list reader, the simulator,
the DNC sender's drip check and resume, verify's resolution, a job's
simulation) asks these questions through :mod:`lagsym.gcode.program`, so the
tests here also show the programs the readers once read differently.
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from lagsym.errors import InputError
from lagsym.gcode import (MACRO_USES, first_line_with, is_macro, macro_uses, numeric_words, parse_moves,
                          program_blocks, program_units)
from lagsym.simulate import simulate


def test_program_blocks_end_at_the_closing_percent_and_run_a_deleted_block():
    text = "%\nO1 (A)\n\n/G0 X1.\n%\nG1 Z-9.\n"
    assert [(no, block) for no, _, block in program_blocks(text)] == [(2, "O1 (A)"), (4, "G0 X1.")]
    assert [no for no, _, _ in program_blocks("G0 X1.\r\n\r\nG1 Z1.")] == [1, 3]


@pytest.mark.parametrize("text, units", [
    ("G21 G90\nG1 X1.\n", "mm"),
    ("G20\nG1 X1.\n", "inch"),
    ("G90G20\nG1 X1.\n", "inch"),  # words without spaces: the G20 regex verify had missed it
    ("g 20\n", "inch"),
    ("G21 (G20 NOT HERE) ; nor G20\n", "mm"),
    ("G21\nG20\n", "inch"),
    ("G1 X20. Y21.\n", None),
    ("%\nG21\n%\nG20\n", "mm"),  # after the closing % a control reads nothing
])
def test_program_units_read_as_words(text, units):
    assert program_units(text) == units


@pytest.mark.parametrize("block, uses", [
    ("G1 X1. Y2. Z3. F100.", set()),
    ("O1000 (DEMO)", set()),  # a Fanuc program number, not an o-word
    ("T2 M06 (TOOL #2 [BALL])", set()),  # comments are text
    ("G1 X1. ; WHILE #1", set()),
    ("#1=2.", {"variable"}),
    ("G1 X[1.+2.]", {"expression"}),
    ("WHILE [#1 LT 10.] DO1", {"variable", "expression", "loop"}),
    ("END1", {"loop"}),
    ("DO 2", {"loop"}),
    ("GOTO10", {"jump"}),
    ("N10 IF [#1 GT 0] GOTO 20", {"variable", "expression", "condition", "jump"}),
    ("IF [#1 GT 0] THEN #2=1.", {"variable", "expression", "condition"}),
    ("N10M98P100", {"call"}),
    ("G65 P9010 A1.", {"call"}),
    ("M99P10", {"return"}),
    ("o100 while [#<n> LE 19.]", {"variable", "expression", "loop"}),
    ("o100 endwhile", {"loop"}),
    ("  o101 endif", {"condition"}),
    ("o<probe> call", {"call"}),
    ("o100 sub", {"return"}),
    ("#<while> = 1.", {"variable"}),  # a name, not the keyword
    ("5 END PGM 1 MM", set()),  # Heidenhain's end of program is not a loop end
])
def test_macro_uses_name_what_a_block_holds_beyond_words(block, uses):
    assert macro_uses(block) == uses


def test_is_macro_reads_a_block_or_a_program():
    assert is_macro("O1000 (DEMO)\nG21\nG1 X1. Z#1\n")
    assert not is_macro("%\nO1000 (DEMO)\nT2 M06 (TOOL #2)\nG1 X1.\n%\n#1=2.\n")
    assert is_macro("M99", ("loop", "jump", "return")) and not is_macro("M98 P10", ("loop", "jump", "return"))
    with pytest.raises(InputError, match="macro use 'loops' is not one of variable, expression"):
        is_macro("G1 X1.", ("loops",))
    assert set(MACRO_USES) == {u for b in ("#1=1", "X[1]", "END1", "GOTO1", "IF[1]THEN#1=1", "M98", "M99")
                               for u in macro_uses(b)}


def test_first_line_with_a_word_whatever_its_value():
    text = "(STOCK TOP Z73.5)\n#1=2.\nIF [#1 GT 0] THEN #26=1.\nG0 X0 Y0 ; Z later\nG1 Z[#1-1.]\n"
    assert first_line_with(text, "Z") == 5
    assert first_line_with("o100 while [#<z> LT 2]\nG1 z#<z>\n", "z") == 2
    assert first_line_with("G0 X1.\n", "Z") is None


@pytest.mark.parametrize("program, what", [
    ("G1 X1 (a (b) Y2.", "a comment inside a comment"),  # the old reader took 'Y2.' for a word
    ("G1 X1 (a (b) c) Y2.", "a comment inside a comment"),
    ("G1 X1 (open\nG1 Y2.", "unclosed comment"),
])
def test_a_comment_inside_a_comment_is_refused_as_linuxcnc_does(program, what):
    with pytest.raises(Exception, match=what):
        parse_moves(program)


def test_the_simulator_stops_at_the_closing_percent_as_the_point_list_reader():
    text = "%\nO1\nG21\nG0 X1. Y2. Z3.\n%\nG0 X9.\n"
    sim = simulate(text, "fanuc", 8)
    assert [m.x for m in sim.moves] == [1.0] == parse_moves(text).points_mm[:, 0].tolist()


@pytest.mark.parametrize("dialect", ["fanuc", "linuxcnc"])
def test_the_simulator_runs_a_deleted_block_as_the_point_list_reader(dialect):
    """Block delete off, the switch's usual place: ``/G0 Z50.`` runs for both readers (the simulator had skipped it)."""
    text = "G21\nG0 X1. Y2. Z3.\n/G0 Z50.\n G1 X4. F100.\n"
    sim = simulate(text, dialect, 8)
    assert [(m.x, m.z) for m in sim.moves] == [(1.0, 3.0), (1.0, 50.0), (4.0, 50.0)]
    assert parse_moves(text).points_mm[:, [0, 2]].tolist() == [[1.0, 3.0], [1.0, 50.0], [4.0, 50.0]]


def test_simulated_moves_are_the_one_moves_type():
    text = "O1\nG20\n#1=0.5\nG0 X1. Y2.\nG1 Z-#1 F10.\nX[#1*4.]\nM30\n"
    moves = simulate(text, "fanuc", 8).moves.to_moves(25.4, first_line_with(text, "Z"))
    assert moves.points_mm.tolist() == [[25.4, 50.8, 0.0], [25.4, 50.8, -12.7], [50.8, 50.8, -12.7]]
    assert moves.rapid.tolist() == [True, False, False] and moves.line.tolist() == [4, 5, 6]
    assert moves.feed_mm_min.tolist()[1:] == [254.0, 254.0] and moves.z_known.tolist() == [False, True, True]
    assert not moves.points_mm.flags.writeable
    assert len(simulate("G21\n", "fanuc", 8).moves.to_moves()) == 0


@settings(max_examples=500, deadline=None)
@given(st.lists(st.text(alphabet="GMXOo#[]%/ ()WHILEDNTF;0125689.+\r\x0c\t", max_size=14), max_size=8))
def test_is_macro_of_a_program_is_macro_uses_of_its_blocks(lines):
    text = "\n".join(lines)
    assert is_macro(text) == any(macro_uses(block) for _, _, block in program_blocks(text))
    assert program_units(text) == _units(block for _, _, block in program_blocks(text))


def _units(blocks):
    """program_units read the slow way: every word of every block."""
    found = set()
    for block in blocks:
        found |= {round(float(v), 1) for k, v in numeric_words(block, strict=False) if k == "G"} & {20.0, 21.0}
    return "inch" if 20.0 in found else "mm" if found else None
