"""Resuming a drip feed: the modal set-up before a block, and what a resume refuses to replay."""

from __future__ import annotations

import pytest

from lagsym.dnc import find_block, parse_program, resume_setup
from lagsym.errors import InputError
from simcontrol import PROGRAM


def test_resume_setup_restores_modes_retracts_and_approaches():
    p = parse_program(PROGRAM)
    setup = resume_setup(p, 11)
    # The program plunged at F300 (block 8) and cuts at F600: the feed-down uses the plunge feed.
    assert setup == ("(RESUME AT BLOCK 11)", "G21 G17 G90 G54", "T2 M6", "S4000 M3", "G0 Z25.",
                     "G0 X20. Y10.", "M8", "G1 Z-1. F300.", "G2 F600.")
    assert resume_setup(p, 11, safe_z="40")[4] == "G0 Z40."


@pytest.mark.parametrize("text, start, words", [
    (PROGRAM, 1, "outside the program"),
    (PROGRAM, 99, "outside the program"),
    ("O1\nG21 G90\n#1=5\nG0 Z#1\nG1 X1. F100.", 5, "macro variables"),
    # calls, jumps and expressions written without spaces or without a '#' (once read as plain words)
    ("O1\nG21 G90\nG0 X1. Y1. Z5.\nM98P100\nG1 Z-1. F100.\nX3.", 6, "macro variables"),
    ("O1\nG21 G90\nG0 X1. Y1. Z5.\nN5G65P9010\nG1 Z-1. F100.\nX3.", 6, "macro variables"),
    ("O1\nG21 G90\nG0 X1. Y1. Z5.\nG0 X[1.+1.]\nG1 Z-1. F100.\nX3.", 6, "macro variables"),
    ("O1\nG90 G0 Z5.\nG1 X1. F100.", 3, "G20 or G21"),
    ("O1\nG21 G90\nG0 X1. Y1. Z5.\nG81 Z-2. R1. F100.\nX2.", 5, "canned cycle G81 is still on"),
    ("O1\nG21 G90\nG0 X1. Y1. Z5.\nG41 D1 G1 X2. F100.\nX3.", 5, "cutter compensation G41"),
    ("O1\nG21 G90 G92 X0 Y0 Z0\nG0 Z5.\nX2.", 4, "G92 shifts"),
    ("O1\nG21 G90\nG0 X1. Y1. Z5.\nG91 G28 Z0.\nG90 G1 X2. F100.\nX3.", 6, "Z position"),
    ("O1\nG21 G90\nG1 X1. Y1. Z-1. F100.\nX2.", 4, "safe-z"),
])
def test_resume_refuses_what_it_cannot_replay(text, start, words):
    with pytest.raises(InputError, match=words):
        resume_setup(parse_program(text, "p.nc"), start)


def test_resume_after_a_drilling_cycle_and_a_return_home():
    text = ("O1\nG21 G17 G90 G54\nG91 G28 Z0.\nG90 T3 M6\nS1200 M3\nG0 X0. Y0. Z30.\n"
            "G98 G81 X5. Y5. Z-4. R2. F80.\nX10.\nG80\nG0 Z30.\nG1 Z-1. F150.\nX20.\nX30.")
    setup = resume_setup(parse_program(text), 13)
    assert setup[1:] == ("G21 G17 G90 G54", "T3 M6", "S1200 M3", "G0 Z30.", "G0 X20. Y5.", "G1 Z-1. F150.")


def test_resume_restores_feed_mode_and_constant_surface_speed():
    text = ("O1\nG21 G17 G90 G54 G95\nT1 M6\nG96 S180 M3\nG0 X0. Y0. Z10.\nG1 Z-2. F0.05\n"
            "G1 X5. F0.2\nX10.\nX15.")
    setup = resume_setup(parse_program(text), 9)
    assert setup == ("(RESUME AT BLOCK 9)", "G21 G17 G90 G54 G95", "T1 M6", "G96 S180 M3", "G0 Z10.",
                     "G0 X10. Y0.", "G1 Z-2. F0.05", "F0.2")


def test_find_block_by_what_the_control_shows():
    p = parse_program("O1\nN10 G21 G90\nN20 G0 Z5.\nN30 G1 X1. F100.\nN30 X2.\nX3.", "p.nc")
    assert find_block(p, "N20") == 3 and find_block(p, "N0020") == 3
    assert find_block(p, "x3.") == 6
    with pytest.raises(InputError, match="N30 is blocks 4, 5"):
        find_block(p, "N30")
    with pytest.raises(InputError, match="no block is N40"):
        find_block(p, "N40")


def test_a_fault_within_the_set_up_asks_for_the_program_from_the_start():
    """A drip feed that stops before the machine has run past the set-up (no X, Y and Z yet) names no resume
    block that resume_setup would refuse: the program goes again from the start."""
    from lagsym.dnc import profile
    from lagsym.dnc.resume import first_resumable_block
    from lagsym.dnc.sender import Sender
    from lagsym.dnc.transfer import transfer_segments
    from simcontrol import program_text

    program = parse_program(program_text(200))
    start = first_resumable_block(program)
    assert start == 8  # O1000, G21 G17 G90 G54, T1 M6, S3000 M3, G0 Z50., G0 X0. Y0., G1 Z-1. F600.: units, X Y Z, feed
    with pytest.raises(InputError, match="no feed"):
        resume_setup(program, 7)
    resume_setup(program, start)
    settings = profile("fanuc", buffer_chars=100)
    segments = transfer_segments(program, settings, "drip")
    for sure, says in ((150, "then send again"), (1000, "then resume with --start-block")):
        sender = Sender(None, segments, settings, "drip", "loop://", progress=None, log=None, resumable_from=start)
        sender.known = sender.left = sender.pos = sure
        fault = sender.fault("the control held XOFF", "release the feed hold")
        assert says in str(fault), str(fault)
        assert fault.start_block in (1, None) or fault.start_block >= start
