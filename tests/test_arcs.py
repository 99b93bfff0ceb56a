"""Arcs in finishing programs: fitted within the tolerance, never below the cutter path, read back by rs274 and lagsym.

The arcs of a program are taken from LinuxCNC's ``rs274`` (its canonical
``ARC_FEED`` moves), tessellated here as LinuxCNC moves them, and compared
with a brute-force ball drop-cutter on the exact polynomial written in the
tests (not lagsym's evaluator or drop-cutter).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from conftest import EXAMPLES
from cutters import brute_ball
from gcheck import arc_feeds, grbl_chords, tessellate
from lagsym.errors import ProgramError
from lagsym.gcode import parse_moves
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.machine import MachineSettings, RasterSpec, Tool
from lagsym.post.program import point_program, write_program
from lagsym.toolpath import plan_toolpath

TOL = 0.005


def example2(x, y):
    """Example 2's polynomial, (x-1)(x-4)(y-1)(y-4)/2 over [1, 4]**2 (docs/export.md), in surface units."""
    return (x - 1) * (x - 4) * (y - 1) * (y - 4) / 2


def example4(x, y):
    """Example 4's surface by the basis products of its control points, in surface units."""
    import json

    pts = np.array(json.loads((EXAMPLES / "paper-example-4.json").read_text())["points"], dtype=float)
    xs, ys = np.unique(pts[:, 0]), np.unique(pts[:, 1])
    z = np.zeros((len(xs), len(ys)))
    for px, py, pz in pts:
        z[np.searchsorted(xs, px), np.searchsorted(ys, py)] = pz

    def basis(nodes, t):
        rows = []
        for n in nodes:
            row = None  # the factors multiplied in order, as a product along a stack of them would
            for m in nodes:
                if m != n:
                    row = (t - m) / (n - m) if row is None else row * ((t - m) / (n - m))
            rows.append(row)
        return np.array(rows)

    return np.einsum("ij,i...,j...->...", z, basis(xs, np.asarray(x)), basis(ys, np.asarray(y)))


CASES = {  # name: (points file, polynomial, box, scale, side step)
    "example-2": ("paper-example-2.json", example2, (1.0, 4.0, 1.0, 4.0), 10.0, 1.5),
    "example-4": ("paper-example-4.json", example4, (1.0, 5.0, 1.0, 5.0), 5.0, 1.0),
}
_PLANS = {}


def plan(name, direction, dialect):
    key = (name, direction, dialect)
    if key not in _PLANS:
        path, _, _, scale, stepover = CASES[name]
        s = lagrange_surface(read_points(EXAMPLES / path))
        settings = MachineSettings(mm_per_unit=scale, dialect=dialect, safe_z_mm=100.0)
        tp = plan_toolpath(s, Tool("ball", 6.0), RasterSpec(direction, stepover, None, None, TOL, arcs=True), settings.placement, settings.program, stock_to_leave_mm=settings.stock_to_leave_mm)
        _PLANS[key] = tp, settings, write_program(point_program(tp, settings, title=name))
    return _PLANS[key]


def run(rs274, tmp_path, text):
    path = tmp_path / "arcs.ngc"
    path.write_text(text)
    r = rs274.run(path)
    assert r.returncode == 0, f"rs274 refused the program: {r.stderr.strip()[-600:]}"
    assert "PROGRAM_END" in r.stdout
    return r.stdout


def deviations(name, arcs, tessellation=400):
    """Height of the tessellated arcs above a brute-force ball drop-cutter (mm), at a sample of their points."""
    _, f, box, scale, _ = CASES[name]
    pts = np.concatenate([tessellate(*a, n=tessellation)[1:-1] for a in arcs])
    pick = pts[np.random.default_rng(3).choice(len(pts), min(2500, len(pts)), replace=False)]
    cl = brute_ball(f, box, pick[:, 0] / scale, pick[:, 1] / scale, 3.0 / scale) * scale
    return pick[:, 2] - cl


@pytest.mark.slow
@pytest.mark.parametrize("name, direction, dialect", [("example-2", "x", "linuxcnc"), ("example-2", "y", "fanuc"),
                                                      ("example-4", "x", "fanuc"), ("example-4", "y", "linuxcnc")])
def test_arcs_pass_rs274_and_stay_between_the_cutter_path_and_the_tolerance(rs274, tmp_path, name, direction, dialect):
    """Every arc rs274 moves lies on or above the exact cutter path and at most the tolerance above it.

    Above by at most the tolerance plus a unit of the last decimal where an
    end's Z was rounded up, as for the straight moves; rs274 prints four
    decimals, so half of its last one is allowed either way.
    """
    tp, settings, text = plan(name, direction, dialect)
    arcs, straight = arc_feeds(run(rs274, tmp_path, text))
    assert len(arcs) == len(tp.arcs) > 50
    assert {a[3] for a in arcs} == {"XZ" if direction == "x" else "YZ"}
    assert straight + len(arcs) <= len(tp) - tp.arcs.blocks_saved()  # the moves the arcs replace are gone
    radii = np.array([[np.linalg.norm(a[0] - a[2]), np.linalg.norm(a[1] - a[2])] for a in arcs])
    assert np.abs(radii[:, 0] - radii[:, 1]).max() <= 0.002  # LinuxCNC's limit (rs274 would refuse it)
    dev = deviations(name, arcs)
    assert dev.min() >= -1e-4, f"an arc {-dev.min() * 1000:.2f} um below the cutter path"
    assert dev.max() <= TOL + 1e-3 + 1e-4, f"an arc {dev.max() * 1000:.2f} um above the cutter path"


def test_the_plane_is_stated_and_g17_comes_back(rs274, tmp_path):
    _, _, text = plan("example-2", "x", "linuxcnc")
    lines = text.splitlines()
    first = next(i for i, ln in enumerate(lines) if re.search(r"\bG0[23]\b", ln))
    assert lines[first].startswith("G18 G0")
    last = max(i for i, ln in enumerate(lines) if re.search(r"\bG0[23]\b", ln))
    assert "G17" in lines[last + 1:]
    assert not re.search(r"\bR-?\d", text)  # centre format only
    out = run(rs274, tmp_path, text)
    planes = re.findall(r"SELECT_PLANE\((\w+)\)", out)
    assert planes[-1] == "CANON_PLANE_XY" and "CANON_PLANE_XZ" in planes


@pytest.mark.slow
def test_grbl_arcs_leave_room_for_its_chords(rs274, tmp_path):
    """Grbl cuts an arc into chords up to $12 = 0.002 mm inside it: its arcs, so cut, stay above the path.

    rs274 reads the Grbl program (the same G-code, no tool change); each arc
    is cut into chords as Grbl does (equal angles, the chord's sag at most
    0.002 mm, at the start's radius, the last chord to the end point).
    """
    tp, _, text = plan("example-2", "x", "grbl")
    assert max(len(ln) for ln in text.splitlines()) <= 80
    arcs, _ = arc_feeds(run(rs274, tmp_path, text))
    assert len(arcs) == len(tp.arcs) > 50
    chords = []
    t = np.linspace(0, 1, 9)[1:-1]
    for arc in arcs:
        corners = grbl_chords(*arc)
        chords.append((corners[:-1, None, :] + (corners[1:] - corners[:-1])[:, None, :] * t[None, :, None])
                      .reshape(-1, 3))
    pts = np.concatenate(chords)
    pick = pts[np.random.default_rng(5).choice(len(pts), 2500, replace=False)]
    _, f, box, scale, _ = CASES["example-2"]
    dev = pick[:, 2] - brute_ball(f, box, pick[:, 0] / scale, pick[:, 1] / scale, 3.0 / scale) * scale
    assert dev.min() >= -1e-4, f"a chord {-dev.min() * 1000:.2f} um below the cutter path"


def test_lagsym_reads_the_arcs_as_rs274_moves_them(rs274, tmp_path):
    """The reader's pieces of each arc lie on rs274's arc (to its four decimals) and end where it ends."""
    _, _, text = plan("example-4", "y", "linuxcnc")
    arcs, _ = arc_feeds(run(rs274, tmp_path, text))
    moves = parse_moves(text)
    arc_lines = [i + 1 for i, ln in enumerate(text.splitlines()) if re.search(r"\bG0[23]\b", ln)]
    assert len(set(arc_lines)) == len(arcs)
    for (start, end, centre, plane, rotation), line in zip(arcs, arc_lines):
        pts = moves.points_mm[moves.line == line]
        assert np.abs(pts[-1] - end).max() <= 1e-4
        r0, r1 = np.linalg.norm(start - centre), np.linalg.norm(end - centre)
        ref = tessellate(start, end, centre, plane, rotation, n=len(pts))[1:]
        assert np.abs(pts - ref).max() <= 2e-4 + abs(r1 - r0)
        assert len(pts) > 3


@pytest.mark.slow
def test_arcs_are_off_by_default_and_the_command_reports_the_blocks(tmp_path, run_cli):
    args = ("toolpath", EXAMPLES / "paper-example-2.json", "--scale", 10, "--stepover", 1.5, "--tolerance", TOL,
            "--safe-z", 100, "--dialect", "linuxcnc")
    status, out, err = run_cli(*args)
    assert status == 0 and not re.search(r"\bG0[23]\b", out) and "G18" not in out
    status, out, err = run_cli(*args, "--arcs", "-o", tmp_path / "a.ngc")
    assert status == 0, err
    m = re.search(r"(\d+) arcs \(G18\): (\d+) feed moves before, (\d+) after", err)
    text = (tmp_path / "a.ngc").read_text()
    assert m and int(m.group(1)) == len(re.findall(r"\bG0[23]\b", text))
    assert int(m.group(3)) < int(m.group(2))


@pytest.mark.parametrize("block, what", [("G02 X1. Y1. R1.", "radius"), ("G90.1", "G90.1"),
                                         ("G01 X1. I1.", "without an arc")])
def test_the_reader_refuses_what_it_does_not_read(block, what):
    with pytest.raises(ProgramError, match=re.escape(what)):
        parse_moves(f"G21 G90\nG00 X0. Y0. Z1.\nG01 F100.\n{block}\n")


def test_the_reader_reads_arcs_in_every_plane():
    """A quarter circle in each plane, both directions, against the circle itself."""
    for plane, start, end, centre_off, ccw_end in (
            ("G17", "X1. Y0. Z0.", "X0. Y1.", "I-1. J0.", (0.0, 1.0, 0.0)),
            ("G18", "X0. Y0. Z1.", "X1. Z0.", "I0. K-1.", (1.0, 0.0, 0.0)),
            ("G19", "X0. Y1. Z0.", "Y0. Z1.", "J-1. K0.", (0.0, 0.0, 1.0))):
        m = parse_moves(f"G21 G90\nG00 {start}\n{plane} G03 {end} {centre_off} F100.\n")
        p = m.points_mm[1:]
        assert np.allclose(np.linalg.norm(p, axis=1), 1.0, atol=1e-9)
        assert np.allclose(p[-1], ccw_end)
        assert np.all(p.min(axis=0) >= -1e-9)  # the short way round: a positive turn, first axis to second
        cw = parse_moves(f"G21 G90\nG00 {start}\n{plane} G02 {end} {centre_off} F100.\n").points_mm[1:]
        assert np.any(cw.min(axis=0) < -0.5)  # the long way round


def test_plot_reads_the_arcs_as_feed_pieces():
    """``lagsym plot --show toolpath`` draws a program through ``move_points``: an arc's pieces are feed moves."""
    from lagsym.gcode import move_points

    pts, rapid = move_points("G21 G90\nG00 X0. Y0. Z1.\nG01 Z0. F100.\nG18 G03 X2. Z0. I1. K0.\nG17\nG00 Z5.\n")
    arc = pts[2:-1]
    assert len(arc) > 100 and not rapid[1:-1].any() and rapid[-1]
    assert np.allclose(np.hypot(arc[:, 0] - 1.0, arc[:, 2]), 1.0) and arc[:, 2].max() > 0.99  # G03 seen from +Y: over the top seen from the front
