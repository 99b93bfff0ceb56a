"""docs/export.md quotes commands with their output and numbers about the surfaces: recompute each one."""

from __future__ import annotations

import io
import shlex
from fractions import Fraction

from lagsym.cad import bezier_patch, lowest_height
from lagsym.cli import main
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface

from conftest import EXAMPLES, ROOT

DOC = (ROOT / "docs" / "export.md").read_text()


def _sessions():
    """``(command, expected output)`` for every ``$ lagsym ...`` line in the page's plain code blocks."""
    blocks, block, plain = [], None, False
    for line in DOC.splitlines():
        if line.startswith("```"):
            if block is None:
                block, plain = [], line == "```"
            else:
                if plain:
                    blocks.append(block)
                block = None
        elif block is not None:
            block.append(line)
    out = []
    for lines in blocks:
        starts = [j for j, line in enumerate(lines) if line.startswith("$ ")] + [len(lines)]
        out += [(lines[a][2:], "\n".join(lines[a + 1:b])) for a, b in zip(starts, starts[1:])]
    return out


def test_quoted_commands_print_what_the_page_says(tmp_path, monkeypatch):
    (tmp_path / "examples").symlink_to(EXAMPLES)
    monkeypatch.chdir(tmp_path)
    sessions = _sessions()
    assert len(sessions) == 5
    for command, expected in sessions:
        out, err = io.StringIO(), io.StringIO()
        status = main(shlex.split(command)[1:], out, err)
        assert (out.getvalue() + err.getvalue()).rstrip("\n") == expected, command
        assert status == (2 if "error" in expected else 0), command


def test_a_refused_base_writes_nothing(tmp_path, monkeypatch):
    (tmp_path / "examples").symlink_to(EXAMPLES)
    monkeypatch.chdir(tmp_path)
    command = next(c for c, e in _sessions() if "error" in e)
    assert main(shlex.split(command)[1:], io.StringIO(), io.StringIO()) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["examples"]


def test_example_2_numbers():
    s = lagrange_surface(read_points(EXAMPLES / "paper-example-2.json"))
    assert "(x-1)(x-4)(y-1)(y-4)/2" in DOC
    for x, y in ((Fraction(3, 2), Fraction(7, 3)), (2, 2), (Fraction(5, 2), 4)):
        assert s.exact_value(x, y) == (x - 1) * (x - 4) * (y - 1) * (y - 4) / 2
    net = bezier_patch(s).heights()
    assert [net[i][k] for i in (1, 2) for k in (1, 2)] == [Fraction(9, 2)] * 4
    assert all(v == 0 for i in range(4) for k in range(4) if i in (0, 3) or k in (0, 3) for v in [net[i][k]])
    assert s.exact_value(Fraction(5, 2), Fraction(5, 2)) == Fraction(81, 32)
    assert lowest_height(bezier_patch(s).bspline()).upper == 0
    assert "9/2, well above the surface's top, 81/32 (about 2.53) at\n(2.5, 2.5)" in DOC


def test_example_4_dip():
    s = lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))
    assert f"{float(lowest_height(bezier_patch(s)).upper):.10g}" == "0.1507663366"
    assert min(s.grid.z_range()) == 1
    assert "Example 4 dips to 0.1507663366 between its points, the\nlowest of which is at height 1." in DOC


def test_read_back_figures_are_those_the_tests_require():
    from test_cad_files import MEASURED, SAMPLES, TOLERANCE, VOLUME_RTOL

    text = " ".join(DOC.split())
    assert f"at {SAMPLES * SAMPLES} parameter points" in text
    assert f"within {TOLERANCE:g} of the data range" in text
    assert VOLUME_RTOL == 1e-9 and "to 1e-9 relative" in text
    assert f"(measured: at most {MEASURED:g}, for all four of the paper's examples, STEP and IGES)" in text


def test_high_degree_figures():
    """'a smooth 16 x 16 grid of heights 10 to 30 has coefficients near 8e6' (the grid of test_cad_files)."""
    import math

    from lagsym.grid import grid_from_table

    xs = [Fraction(i * 60, 15) for i in range(16)]
    z = [[Fraction(round(1000 * (20 + 10 * math.sin(x / 15) * math.cos(y / 20))), 1000) for y in xs] for x in xs]
    s = lagrange_surface(grid_from_table(xs, xs, z))
    lo, hi = s.grid.z_range()
    assert 10 <= lo and hi <= 30
    largest = max(abs(v) for row in bezier_patch(s).heights() for v in row)
    assert f"{float(largest):.0e}" == "8e+06"
    assert "a smooth 16 x 16 grid of heights 10 to 30 has coefficients near 8e6" in " ".join(DOC.split())
