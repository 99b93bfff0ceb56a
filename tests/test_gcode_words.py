"""The one word tokenizer: what it splits, what it refuses, and that its comments are LinuxCNC's."""

from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from lagsym.controls import CONTROLS
from lagsym.errors import ProgramError
from lagsym.gcode import WordError, numeric_words, parse_moves, strip_comments, words
from lagsym.gcode import limits
from lagsym.macro import fanuc, heidenhain, linuxcnc

from gcheck import interpret


def test_numeric_words_in_block_order_with_upper_case_letters():
    assert numeric_words("n10 g1 x-.5 Y 2. F+200") == [("N", "10"), ("G", "1"), ("X", "-.5"), ("Y", "2."),
                                                      ("F", "+200")]
    assert numeric_words("G01 X1.0 (FEED) Y2.0") == [("G", "01"), ("X", "1.0"), ("Y", "2.0")]
    assert numeric_words("(ONLY A COMMENT)") == []


@pytest.mark.parametrize("block, match", [
    ("G1 X#1", "cannot read 'X#1'"),
    ("G1 X[1+2]", "cannot read"),
    ("G1 X1 $", "cannot read '\\$'"),
    ("G1 X1 (open", "unclosed comment"),
    ("G1 X1 (open ; x", "unclosed comment"),
])
def test_numeric_words_refuses_anything_else(block, match):
    with pytest.raises(WordError, match=match):
        numeric_words(block)


def test_lenient_numeric_words_pass_over_what_is_not_a_number():
    assert numeric_words("G1 X#1 Y2.", strict=False) == [("G", "1"), ("Y", "2.")]
    assert numeric_words("t1 m6 $", strict=False) == [("T", "1"), ("M", "6")]


def test_the_first_comment_to_start_wins():
    assert strip_comments("G1 X1. ; note (open").strip() == "G1 X1."
    assert strip_comments("G1 (a;b) X1.").split() == ["G1", "X1."]
    assert numeric_words("G1 X1. ; note (open") == [("G", "1"), ("X", "1.")]


def test_a_fanuc_semicolon_is_not_a_comment():
    assert strip_comments("#1=2. ;", semicolon=False) == "#1=2. ;"
    with pytest.raises(WordError):
        numeric_words("G1 X1. ;", semicolon=False)


def test_words_keep_variables_expressions_and_functions_whole():
    assert words("G1 X#112 Y[#1 + [2.*#2]] Z-#3 F#<feed>") == [
        ("G", "1"), ("X", "#112"), ("Y", "[#1 + [2.*#2]]"), ("Z", "-#3"), ("F", "#<feed>")]
    assert words("x sqrt[#1] y-ABS[#2]") == [("X", "sqrt[#1]"), ("Y", "-ABS[#2]")]
    assert words("G1 X") == [("G", "1"), ("X", "")]


@pytest.mark.parametrize("block, match", [("G1 $1", "cannot read"), ("G1 X#<feed", "'#<' without its '>'")])
def test_words_refuse_what_is_not_a_word(block, match):
    with pytest.raises(WordError, match=match):
        words(block)


def test_comments_are_read_as_rs274_reads_them(rs274):
    # A ';' comment hides a '(' after it; a comment between the digits of a number ends the number.
    good = "G21 G90\nG1 X1.5 F100. ; to the corner (open\nM2\n"
    feeds, _ = interpret(rs274, good)
    assert parse_moves(good).feeds.tolist() == feeds.tolist() == [[1.5, 0.0, 0.0]]
    bad = "G21 G90\nG1 X1.(c)5 F100.\nM2\n"
    with pytest.raises(AssertionError, match="rs274 refused"):
        interpret(rs274, bad)
    with pytest.raises(ProgramError, match="line 2: cannot read '5'"):
        parse_moves(bad)


def test_the_macro_writers_keep_the_controls_limits():
    # One home: the writers and the checks hold no limits of their own; a macro's variables are ones the control reads.
    for module in (fanuc, linuxcnc, heidenhain, limits):
        assert not any(hasattr(module, n) for n in ("MAX_BLOCK", "VARIABLE_RANGES", "LIMITS")), module.__name__
    for c in CONTROLS.values():
        for ranges in c.macro_variables.values():
            assert all(any(lo <= a and b <= hi for lo, hi in c.variables) for a, b in ranges), c.name


@settings(max_examples=300)
@given(st.lists(st.sampled_from(["G0", "G00", "G1", "G01", "G1.5", "G010", "G2", "X", "Y", "Z", "F", "x", "N10",
                                 "(C)", "X1.2.3"]), max_size=6),
       st.lists(st.sampled_from(["1", "-.5", "+2.", "12.345", "0", ".", ""]), min_size=6, max_size=6),
       st.sampled_from([" ", "", "  "]))
def test_the_plain_move_fast_path_reads_what_numeric_words_reads(letters, values, gap):
    """Whenever ``plain_move`` takes a block, ``numeric_words`` finds the same words in it."""
    from lagsym.gcode.words import plain_move

    block = gap.join(w + (v if len(w) == 1 else "") for w, v in zip(letters, values)).strip()
    fast = plain_move(block)
    if fast is None:
        return
    slow = dict(numeric_words(block))
    assert len(slow) == len(numeric_words(block))  # each letter once
    g = slow.pop("G", None)
    assert fast[0] == (None if g is None else g.lstrip("0") or "0")
    assert fast[1:] == tuple(slow.pop(k, None) for k in "XYZF") and not slow
