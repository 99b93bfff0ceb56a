"""The real interpreter the G-code tests rely on is there and interprets."""

from pathlib import Path


def test_rs274_interprets_a_feed_move(rs274, tmp_path: Path):
    prog = tmp_path / "t.ngc"
    prog.write_text("G21 G90\nG0 X1. Y2. Z3.\nG1 X2.5 Y1. Z0.1 F100.\nM2\n")
    r = rs274.run(prog)
    assert r.returncode == 0, r.stderr
    assert "STRAIGHT_FEED(2.5000, 1.0000, 0.1000" in r.stdout
