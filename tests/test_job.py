"""Whole jobs: bad job files refused in one line; Example 4's job checked by rs274 and by a height map of the block.

The independent check runs the program through LinuxCNC's rs274 with its
tool table, then cuts a NumPy height map of the block with each tool's own
shape along the moves rs274 reports (a flat end swept exactly along each
move, a ball stamped at most 0.1 mm apart along it), and compares the result
with the interpolating polynomial evaluated from the control points.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from test_rough import exact_heights, sweep_flat

ROOT = Path(__file__).resolve().parent.parent
JOB = ROOT / "examples" / "example-4-job.toml"
EX4 = ROOT / "examples" / "paper-example-4.json"
TOOLS = "T1 P1 Z0 D10 ;rougher\nT2 P2 Z0 D6 ;ball\n"
R_FLAT, R_BALL, STOCK = 5.0, 3.0, 0.3
_LINE = re.compile(r"^\s*\d+\s+N\S*\s+(\w+)\((.*)\)\s*$")


def job_text(**changes) -> str:
    """The example job file with the points given by absolute path and lines replaced (``old -> new``)."""
    text = JOB.read_text().replace('points = "paper-example-4.json"', f'points = "{EX4.as_posix()}"')
    for old, new in changes.items():
        assert old.replace("_", " ") in text or old in text, old
        text = text.replace(old if old in text else old.replace("_", " "), new, 1)
    return text


BAD = [
    ({"rapid = 5000": "rapid = 5000\nspeed = 3"}, "unknown key 'speed'"),
    ({"scale = 20": 'scale = "20"'}, "scale = '20' must be a number"),
    ({'dialect = "linuxcnc"': 'dialect = "haas"'}, "dialect = 'haas' is not one of fanuc, linuxcnc, grbl"),
    ({'coolant = "flood"': 'coolant = "oil"'}, "coolant = 'oil' is not one of off, flood, mist"),
    ({"diameter = 10": "diameter = -10"}, "tools.rougher.diameter = -10 must be a number above 0"),
    ({'tool = "ball6"': 'tool = "ball8"'}, "tool = 'ball8' is not one of rougher, ball6"),
    ({"stepover = 0.5": "stepover = 0.5\nmilling = 'climb'"}, "milling does not apply to a finish operation"),
    ({"top_above = 2": "top = 10"}, "below the surface's highest point"),
    ({"flute_length = 25": "flute_length = 1.5"}, "step-down 2 mm is larger than the flute length 1.5 mm"),
    ({"reach = 80": "reach = 30", "stepover = 5": "stepover = 10\nstep = 2"}, "the tool cannot reach: the cut goes"),
    ({"safe_z = 90": "safe_z = 60"}, "is not above the stock top"),
    ({"[stock]": "[stock]\nheight = 3"}, "unknown key stock.'height'"),
    ({"scale = 20": "scale = 20 20"}, "not a valid TOML job file"),
    ({"stepover = 5": "stepover = 5\nprecision = 8"}, "operations[0].precision applies to a roughing macro only"),
    ({"stepover = 5": "stepover = 5\nmacro = 1"}, "operations[0].macro = 1 must be true or false"),
    ({"stepover = 5": "stepover = 5\nmacro = true", 'dialect = "linuxcnc"': 'dialect = "grbl"'},
     "operations[0].macro: a roughing macro is written for fanuc or linuxcnc, not 'grbl'"),
    ({"stepover = 5": "stepover = 5\nmacro = true\nmilling = 'climb'"}, "a roughing macro cuts zig-zag only"),
    ({"stepover = 5": "stepover = 5\nmacro = true\nprecision = 12"}, "precision = 12 is not one of 8, 15"),
]


@pytest.mark.parametrize("changes, words", BAD, ids=[w for _, w in BAD])
def test_bad_job_files_get_one_line_naming_the_file_and_exit_2(run_cli, tmp_path, changes, words):
    job = tmp_path / "bad.toml"
    job.write_text(job_text(**changes))
    out = tmp_path / "part.ngc"
    status, stdout, err = run_cli("job", job, "-o", out)
    assert status == 2 and err.count("\n") == 1 and not stdout, err
    assert str(job) in err and words.replace("'", "") in err.replace("'", ""), err
    assert not out.exists()


def _calls(rs274, text: str):
    """rs274's canonical calls of the program, in order: (name, arguments)."""
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "part.ngc"
        p.write_text(text)
        r = rs274.run(p, tool_table=TOOLS)
    assert r.returncode == 0 and "PROGRAM_END" in r.stdout, r.stderr[-500:]
    return [(m.group(1), m.group(2)) for m in map(_LINE.match, r.stdout.splitlines()) if m]


@pytest.fixture(scope="module")
def job_run(tmp_path_factory, rs274):
    """The example job's program, what the command printed, and rs274's moves tagged with the tool in the spindle."""
    import io

    from lagsym.cli import main

    d = tmp_path_factory.mktemp("job")
    job = d / "job.toml"
    job.write_text(job_text())
    err = io.StringIO()
    assert main(["job", str(job), "-o", str(d / "part.ngc")], io.StringIO(), err) == 0, err.getvalue()
    text = (d / "part.ngc").read_text()
    tool, moves, calls = 0, [], _calls(rs274, text)
    for name, argv in calls:
        if name == "CHANGE_TOOL":
            tool = int(argv)
        elif name in ("STRAIGHT_FEED", "STRAIGHT_TRAVERSE"):
            moves.append((tool, name == "STRAIGHT_FEED", *map(float, argv.split(",")[:3])))
    return text, err.getvalue(), moves, [c[0] for c in calls]


def test_the_job_program_changes_tools_in_order_with_speeds_and_coolant(job_run):
    text, printed, moves, calls = job_run
    assert [t for t in dict.fromkeys(m[0] for m in moves)] == [1, 2]
    assert calls.index("FLOOD_ON") < calls.index("CHANGE_TOOL") + 5
    assert "T1 M06" in text and "G43 H1" in text and "T2 M06" in text and "G43 H2" in text
    assert "S8000 M03" in text and "S10000 M03" in text and "M08" in text
    total = float(re.search(r"cycle time about ([\d.]+) min", printed).group(1))
    per_op = [float(v) for v in re.findall(r": \d+ moves, about ([\d.]+) min", printed)]
    assert len(per_op) == 2 and abs(sum(per_op) - total) <= 0.1 + 1e-9
    assert f"CYCLE TIME ABOUT {total:.1f} MIN" in text


def stamp_ball(h, gx, gy, pts, radius):
    """Lower ``h`` wherever a ball end of ``radius`` with its tip at each of ``pts`` (N, 3) reaches."""
    cell = gx[1] - gx[0]
    k = int(np.ceil(radius / cell)) + 1
    ix0 = np.rint((pts[:, 0] - gx[0]) / cell).astype(int)
    iy0 = np.rint((pts[:, 1] - gy[0]) / cell).astype(int)
    flat = h.reshape(-1)
    for i in range(-k, k + 1):
        for j in range(-k, k + 1):
            ix, iy = ix0 + i, iy0 + j
            ok = (ix >= 0) & (ix < len(gx)) & (iy >= 0) & (iy < len(gy))
            d2 = (gx[np.clip(ix, 0, len(gx) - 1)] - pts[:, 0]) ** 2 + (gy[np.clip(iy, 0, len(gy) - 1)] - pts[:, 1]) ** 2
            ok &= d2 <= radius * radius
            z = pts[ok, 2] + radius - np.sqrt(radius * radius - d2[ok])
            np.minimum.at(flat, ix[ok] * len(gy) + iy[ok], z)


def _densified(moves, spacing):
    """The end points of the moves and points at most ``spacing`` apart along each."""
    p = np.array([m[2:] for m in moves])
    out = [p[:1]]
    for a, b in zip(p[:-1], p[1:]):
        n = max(int(np.ceil(np.hypot(*(b[:2] - a[:2])) / spacing)), 1)
        out.append(a + (b - a) * (np.arange(1, n + 1) / n)[:, None])
    return np.concatenate(out)


@pytest.fixture(scope="module")
def machined(job_run):
    """The block cut by the roughing, then by the finishing: grid, surface, and material left after each."""
    _, _, moves, _ = job_run
    cell = 0.25
    gx = gy = np.arange(20.0, 100.0 + cell / 2, cell)  # the block is the box (no margin)
    fx, fy = np.meshgrid(gx, gy, indexing="ij")
    f = exact_heights(EX4, fx, fy)
    h = np.full(f.shape, float(f.max()) + 2 + 1e-3)
    rough = [m for m in moves if m[0] == 1]
    for a, b in zip(rough[:-1], rough[1:]):
        sweep_flat(h, gx, gy, a[2:], b[2:], R_FLAT)
    left_rough = h - f
    stamp_ball(h, gx, gy, _densified([m for m in moves if m[0] == 2], 0.1), R_BALL)
    return fx, fy, f, left_rough, h - f


def test_the_job_cuts_no_gouge(machined):
    """Rough then finish from the block: the roughing leaves its stock, nothing is cut below the surface."""
    _, _, _, left_rough, left = machined
    assert left_rough.min() >= STOCK - 0.002, left_rough.min()
    assert left.min() >= -0.002, f"gouge of {-left.min():.4f} mm"


@pytest.mark.xfail(strict=True, reason="open: 0.069 mm is left at (91, 45.25) mm where the cusp bound of rows "
                   "0.5 mm apart is 0.012 mm: along the rows the surface is a hollow of radius 2.78 mm there "
                   "(F_xx = 0.36 / mm), tighter than the 3 mm ball, which rests on both walls (its tip 0.2 mm "
                   "above the surface at x = 91) and cannot reach the bottom at any side step; the bound "
                   "does not allow for that")
def test_the_job_leaves_at_most_the_finishing_cusp(machined):
    """Away from the box edges, what the finish leaves is at most the cusp of its rows on the local slope."""
    fx, fy, f, _, left = machined
    cell = 0.25
    # The largest cusp between rows 0.5 mm apart on a slope of angle a across them: the flat cusp of rows
    # 0.5 / cos a apart, measured vertically.
    inner = (fx >= 20 + R_BALL) & (fx <= 100 - R_BALL) & (fy >= 20 + R_BALL) & (fy <= 100 - R_BALL)
    cos = 1 / np.sqrt(1 + np.gradient(f, cell, axis=1) ** 2)
    bound = (R_BALL - np.sqrt(R_BALL ** 2 - (0.25 / cos) ** 2)) / cos + 0.002
    worst = np.unravel_index(np.argmax(np.where(inner, left - bound, -np.inf)), left.shape)
    assert (left - bound)[inner].max() <= 0, (left[worst], bound[worst], fx[worst], fy[worst])
