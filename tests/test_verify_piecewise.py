"""Verify on a piecewise surface: gouge and material left against a brute-force swept ball over the pieces.

The reference builds the pieces of ``examples/part-20x20.csv`` apart from
lagsym: the points read by the csv module as exact decimals, the slopes at
the nodes by the 3-point Lagrange parabola in Fractions, and each cell the
bicubic Hermite patch of its corners evaluated in NumPy from the cubic
Hermite basis functions.  The swept ball is ``swept_check``'s golden-section
search; nothing here comes from ``lagsym.verify`` or lagsym's evaluators.
"""

from __future__ import annotations

import io
from fractions import Fraction

import numpy as np
import pytest

from lagsym.gcode import parse_moves
from lagsym.io import read_points
from lagsym.machine import MachineSettings, Placement, RasterSpec, Tool
from lagsym.surfaces.piecewise import piecewise_surface
from lagsym.toolpath import plan_toolpath
from lagsym.verify import program_resolution_mm, simulate_cut

from conftest import EXAMPLES
from piecewise_check import Reference
from swept_check import swept_ball_window

PART = EXAMPLES / "part-20x20.csv"
RADIUS = 3.0
DEFECT_MM = 0.01


@pytest.fixture(scope="module")
def ref():
    return Reference(PART)


@pytest.fixture(scope="module")
def plan():
    surface = piecewise_surface(read_points(PART))
    s = MachineSettings(dialect="linuxcnc", mm_per_unit=1.0, safe_z_mm=40.0)
    tp = plan_toolpath(surface, Tool("ball", 2 * RADIUS), RasterSpec("x", 3.0, 1.0), s.placement, s.program)
    return surface, tp


def program(points, safe_z=40.0):
    """A plain program through ``points`` (mm) at feed, four decimals."""
    lines = ["G21 G90", f"G00 Z{safe_z:.4f}", f"G00 X{points[0][0]:.4f} Y{points[0][1]:.4f}"]
    lines += [f"G01 X{x:.4f} Y{y:.4f} Z{z:.4f} F600." for x, y, z in points]
    lines += [f"G00 Z{safe_z:.4f}", "M30"]
    return "\n".join(lines) + "\n"


def feed_moves(moves):
    known = np.asarray(moves.z_known)
    use = np.flatnonzero(known & np.concatenate([[False], known[:-1]]) & ~np.asarray(moves.rapid))
    return moves.path_mm[use], moves.path_mm[use + 1]


def brute(ref, a, b, centre, half, step=0.01):
    """Deepest gouge and most material left (height, and normal to the surface) over a window, brute force."""
    x0, x1 = max(centre[0] - half, ref.bx[0]), min(centre[0] + half, ref.bx[-1])
    y0, y1 = max(centre[1] - half, ref.by[0]), min(centre[1] + half, ref.by[-1])
    gx, gy = np.arange(x0, x1 + step / 2, step), np.arange(y0, y1 + step / 2, step)
    near = ((np.minimum(a[:, 0], b[:, 0]) <= x1 + RADIUS) & (np.maximum(a[:, 0], b[:, 0]) >= x0 - RADIUS)
            & (np.minimum(a[:, 1], b[:, 1]) <= y1 + RADIUS) & (np.maximum(a[:, 1], b[:, 1]) >= y0 - RADIUS))
    cut = swept_ball_window(a[near], b[near], RADIUS, gx, gy)
    X, Y = np.meshgrid(gx, gy, indexing="ij")
    above = cut - ref(X, Y)
    normal = above / np.sqrt(1.0 + ref(X, Y, dx=1) ** 2 + ref(X, Y, dy=1) ** 2)
    return dict(gouge=max(0.0, -float(above.min())), left_height=float(above.max()), left_normal=float(normal.max()))


@pytest.mark.slow
def test_the_reference_is_the_pieces(ref, plan):
    """The test's own pieces agree with lagsym's exact ones, on and off the borders."""
    surface, _ = plan
    for x, y in ((2, 4), (3.3, 17.9), (20, 21.7), (37.99, 0.01), (38, 38), (13.25, 26)):
        exact = float(surface.exact_value(Fraction(x).limit_denominator(1000), Fraction(y).limit_denominator(1000)))
        assert abs(float(ref(x, y)) - exact) < 1e-12


def test_curvature_is_bounded_on_every_piece(ref, plan):
    """The certified Hessian bound is above the reference's curvature on a dense grid of every piece, borders
    included (the second derivatives jump there, and each side is sampled from its own piece)."""
    surface, _ = plan
    top, most = surface.evaluator.curvature_limits()
    u = np.linspace(0.0, 1.0, 9)
    xs = (ref.bx[:-1, None] + np.diff(ref.bx)[:, None] * u[None, :]).ravel()
    ys = (ref.by[:-1, None] + np.diff(ref.by)[:, None] * u[None, :]).ravel()
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    # The end of each cell is evaluated from that cell: nudge inside.
    X = X - 1e-9 * (np.tile(u, len(ref.bx) - 1)[:, None] == 1.0)
    Y = Y - 1e-9 * (np.tile(u, len(ref.by) - 1)[None, :] == 1.0)
    fxx, fyy, fxy = ref(X, Y, dx=2), ref(X, Y, dy=2), ref(X, Y, dx=1, dy=1)
    mid, rad = 0.5 * (fxx + fyy), np.sqrt(0.25 * (fxx - fyy) ** 2 + fxy**2)
    assert float((mid + rad).max()) <= top
    assert float((np.abs(mid) + rad).max()) <= most
    # and not wildly above: within the span of the Bezier control points of a cubic
    assert top < 3 * float((mid + rad).max())


@pytest.mark.slow
def test_a_clean_program_on_the_pieces(ref, plan):
    """No gouge reported or found; the material left bound above the brute force, around its worst place and on
    windows across piece borders."""
    surface, tp = plan
    text = program(np.array(tp.points_mm))
    moves = parse_moves(text)
    report = simulate_cut(surface, moves, tp.tool, Placement(1.0), cell_mm=0.2,
                          program_resolution_mm=program_resolution_mm(text), max_left_mm=np.inf)
    assert not report.gouges and not report.crashes, report.summary()
    a, b = feed_moves(moves)
    for centre in (report.left_at, (20.0, 20.0), (10.0, 30.0), (30.0, 8.0), (36.0, 36.0)):
        got = brute(ref, a, b, centre, 0.3)
        assert got["gouge"] <= report.gouge_limit_mm, centre
        assert report.left_mm >= got["left_normal"] - 1e-7, centre
        assert report.left_height_mm >= got["left_height"] - 1e-7 or report.left_mm > got["left_normal"], centre
    # The bound is close: the brute force at its own worst place is within a cell's worth of it.
    assert brute(ref, a, b, report.left_at, 0.3)["left_normal"] > 0.9 * report.left_mm


@pytest.mark.slow
def test_a_point_a_hundredth_deeper_is_caught(ref, plan):
    """One cutter location on a piece border 0.01 mm lower: a gouge, reported at least as deep as it is."""
    surface, tp = plan
    p = np.array(tp.points_mm)
    k = int(np.argmin(np.abs(p[:, 0] - 20.0) + np.abs(p[:, 1] - 18.0)))
    p[k, 2] -= DEFECT_MM
    text = program(p)
    moves = parse_moves(text)
    report = simulate_cut(surface, moves, tp.tool, Placement(1.0), cell_mm=0.2,
                          program_resolution_mm=program_resolution_mm(text), max_left_mm=np.inf)
    a, b = feed_moves(moves)
    ref_gouge = brute(ref, a, b, report.gouge_at, 0.25, step=0.005)["gouge"]
    assert ref_gouge > 0.5 * DEFECT_MM > report.gouge_limit_mm
    assert report.gouges and report.fails, report.summary()
    assert report.gouge_mm >= ref_gouge - 1e-7
    assert report.gouge_mm <= ref_gouge + 2e-4
    # where the reference finds it: near the lowered point
    assert np.hypot(report.gouge_at[0] - p[k, 0], report.gouge_at[1] - p[k, 1]) < RADIUS


@pytest.mark.slow
def test_command_line_verifies_a_piecewise_file(tmp_path, plan):
    from lagsym.cli import main

    surface, tp = plan
    pieces = tmp_path / "pieces.json"
    assert main(["piecewise", str(PART), "-o", str(pieces)], io.StringIO(), io.StringIO()) == 0
    p = np.array(tp.points_mm)
    nc = tmp_path / "p.ngc"
    nc.write_text(program(p))
    out, err = io.StringIO(), io.StringIO()
    args = ["verify", str(pieces), str(nc), "--tool-diameter", "6", "--cell", "0.4", "--max-left", "5"]
    assert main(args, out, err) == 0, err.getvalue()
    assert "worst gouge" in out.getvalue() and ": none" in out.getvalue()
    k = int(np.argmin(np.abs(p[:, 0] - 20.0) + np.abs(p[:, 1] - 18.0)))
    p[k, 2] -= DEFECT_MM
    nc.write_text(program(p))
    out, err = io.StringIO(), io.StringIO()
    assert main(args, out, err) == 1
    assert "GOUGE" in out.getvalue()


@pytest.mark.slow
def test_the_measured_data_page_quotes_verify(tmp_path, monkeypatch):
    """docs/measured-data.md's verify run on the pieces, from the commands it shows."""
    import re

    from conftest import ROOT

    from lagsym.cli import main

    page = (ROOT / "docs" / "measured-data.md").read_text()
    monkeypatch.chdir(tmp_path)
    (tmp_path / "examples").symlink_to(EXAMPLES)
    for cmd in ("piecewise examples/part-20x20.csv -o pieces.json",
                "toolpath pieces.json --tool-diameter 6 --stepover 2 --step 1 -o pieces.nc"):
        assert f"$ lagsym {cmd}\n" in page
        assert main(cmd.split(), io.StringIO(), io.StringIO()) == 0
    cmd = "verify pieces.json pieces.nc --tool-diameter 6 --max-left 0.5"
    out = io.StringIO()
    assert main(cmd.split(), out, io.StringIO()) == 0
    assert f"$ lagsym {cmd}\n{out.getvalue()}" in page
    left = float(re.search(r"material left +(\S+) mm", out.getvalue()).group(1))
    assert f"leaves cusps of {left:.1f} mm" in " ".join(page.split())
