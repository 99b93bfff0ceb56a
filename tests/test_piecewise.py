"""Piecewise surfaces: exact C1 joins, reproduction, the file, drop-cutter and the toolpath across borders."""

from __future__ import annotations

import io
import re
import math
from fractions import Fraction

import numpy as np
import pytest
import sympy

from lagsym.errors import GridError, InputError
from lagsym.export.piecewisejson import parse_piecewise_json, write_piecewise_json
from lagsym.grid import grid_from_table
from lagsym.machine import Placement, RasterSpec, Tool
from lagsym.surfaces import HermiteBasis, HermiteSurface
from lagsym.surfaces.piecewise import CONTINUITY, lagrange_slopes, piecewise_surface
from lagsym.toolpath import drop_cutter, plan_toolpath

X, Y = sympy.symbols("x y")


def wavy_grid(n, m=None, size=40):
    """A smooth part sampled on an uneven ``n x m`` grid, heights rounded to exact 3-decimal numbers."""
    m = m or n
    xs = [Fraction(size * i, n - 1) + (Fraction(1, 7) if 0 < i < n - 1 and i % 3 == 1 else 0) for i in range(n)]
    ys = [Fraction(size * k, m - 1) for k in range(m)]

    def f(x, y):
        return 5 * math.sin(x / 6) * math.cos(y / 8) + 0.02 * x * y

    return grid_from_table(xs, ys, [[Fraction(round(f(float(x), float(y)), 3)).limit_denominator(1000) for y in ys]
                                    for x in xs])


def reference_surface(grid) -> HermiteSurface:
    """The same surface built apart from lagsym's exact code: slopes by NumPy's second-order differences (the
    3-point parabola's slope, inside and at the ends), pieces by the float bicubic Hermite comparison surface."""
    x, y, z = grid.x_array, grid.y_array, grid.z_array
    zx = np.gradient(z, x, axis=0, edge_order=2)
    zy = np.gradient(z, y, axis=1, edge_order=2)
    zxy = np.gradient(zx, y, axis=1, edge_order=2)
    return HermiteSurface("reference", HermiteBasis(tuple(x)), HermiteBasis(tuple(y)), z, zx, zy, zxy)


@pytest.mark.slow
def test_continuity_is_exact_across_every_border():
    s = piecewise_surface(wavy_grid(7, 6))
    assert s.continuity == CONTINUITY == "C1"
    n, m = s.shape
    g = s.grid
    for i in range(n):
        for k in range(m):
            p = s.expr(i, k)
            if i + 1 < n:  # the border x = x[i+1] with the piece to the right
                q, xb = s.expr(i + 1, k), sympy.Rational(g.x[i + 1])
                for d in (lambda e: e, lambda e: sympy.diff(e, X), lambda e: sympy.diff(e, Y),
                          lambda e: sympy.diff(e, X, Y)):
                    assert sympy.expand(d(p).subs(X, xb) - d(q).subs(X, xb)) == 0
            if k + 1 < m:  # the border y = y[k+1] with the piece above
                q, yb = s.expr(i, k + 1), sympy.Rational(g.y[k + 1])
                for d in (lambda e: e, lambda e: sympy.diff(e, X), lambda e: sympy.diff(e, Y)):
                    assert sympy.expand(d(p).subs(Y, yb) - d(q).subs(Y, yb)) == 0


def test_it_is_not_c2_in_general():
    s = piecewise_surface(wavy_grid(6, 5))
    xb = sympy.Rational(s.grid.x[2])
    jumps = [sympy.expand(sympy.diff(s.expr(1, k), X, 2).subs(X, xb) - sympy.diff(s.expr(2, k), X, 2).subs(X, xb))
             for k in range(4)]
    assert any(j != 0 for j in jumps)


def test_through_every_control_point():
    g = wavy_grid(8, 5)
    s = piecewise_surface(g)
    for i, x in enumerate(g.x):
        for k, y in enumerate(g.y):
            assert s.exact_value(x, y) == g.z[i][k]
            # also from every piece that has the node as a corner
            for a in (i - 1, i):
                for b in (k - 1, k):
                    if 0 <= a < s.shape[0] and 0 <= b < s.shape[1]:
                        assert s.expr(a, b).subs({X: sympy.Rational(x), Y: sympy.Rational(y)}) == \
                            sympy.Rational(g.z[i][k])


def test_reproduces_biquadratics_exactly():
    xs = [Fraction(v) for v in (0, 1, Fraction(5, 2), 4, 7)]
    ys = [Fraction(v) for v in (-1, 0, Fraction(1, 3), 2)]
    f = (3 * X**2 - X + Fraction(1, 2)) * (Y**2 + 2 * Y - 5) + X * Y
    s = piecewise_surface(grid_from_table(xs, ys, [[Fraction(str(f.subs({X: x, Y: y}))) for y in ys] for x in xs]))
    assert all(sympy.expand(s.expr(i, k) - f) == 0 for i in range(4) for k in range(3))
    pw = s.piecewise()
    assert pw.subs({X: Fraction(3, 2), Y: Fraction(1, 5)}) == f.subs({X: Fraction(3, 2), Y: Fraction(1, 5)})


def test_slopes_are_the_parabolas():
    nodes = [Fraction(0), Fraction(1), Fraction(3), Fraction(4)]
    vals = [Fraction(2), Fraction(-1), Fraction(5), Fraction(0)]
    slopes = lagrange_slopes(nodes, vals)
    for i in range(4):
        lo = min(max(i - 1, 0), 1)
        par = sympy.interpolate(list(zip(nodes[lo:lo + 3], vals[lo:lo + 3])), X)
        assert slopes[i] == sympy.diff(par, X).subs(X, nodes[i])


def test_pieces_are_the_reference_surface():
    g = wavy_grid(9, 7)
    s = piecewise_surface(g)
    ref = reference_surface(g)
    rng = np.random.default_rng(3)
    px, py = rng.uniform(0, 40, 300), rng.uniform(0, 40, 300)
    got = np.array([float(s.exact_value(Fraction(a), Fraction(b))) for a, b in zip(px, py)])
    assert np.abs(got - ref.evaluate(px, py)).max() < 1e-12
    assert np.abs(s.evaluator.fast_points(px, py) - got).max() < 1e-12
    # derivatives of the float evaluator against the exact pieces
    i, k = s.locate(Fraction(px[0]), Fraction(py[0]))
    dx = sympy.diff(s.expr(i, k), X).subs({X: sympy.Float(px[0], 30), Y: sympy.Float(py[0], 30)})
    assert abs(s.evaluator.fast_points(px[0], py[0], dx=1) - float(dx)) < 1e-11


def test_too_few_nodes_refused():
    g = grid_from_table([0, 1], [0, 1, 2], [[0, 1, 2], [1, 2, 3]])
    with pytest.raises(GridError, match="at least 3 x 3 nodes"):
        piecewise_surface(g)


def test_file_round_trip_and_tampering():
    s = piecewise_surface(wavy_grid(5, 4))
    buf = io.StringIO()
    write_piecewise_json(buf, s)
    text = buf.getvalue()
    back = parse_piecewise_json(text, "s.json")
    assert back == s and back.coefficients(2, 1) == s.coefficients(2, 1)
    doc = __import__("json").loads(text)
    doc["zx"][1][2] = "1/3"
    with pytest.raises(InputError, match=r"zx\[1\]\[2\] = 1/3 is not the 3-point Lagrange slope"):
        parse_piecewise_json(__import__("json").dumps(doc), "s.json")


def brute_ball(ref, grid, cx, cy, radius, n=161):
    """A dense lattice over the disc on the reference surface: a lower bound of the exact drop-cutter value."""
    x0, x1, y0, y1 = (float(v) for v in grid.bounds)
    t = np.linspace(-radius, radius, n)
    gx, gy = np.meshgrid(t, t)
    inside = gx**2 + gy**2 <= radius**2
    out = []
    for a, b in zip(cx, cy):
        px, py = a + gx[inside], b + gy[inside]
        ok = (px >= x0) & (px <= x1) & (py >= y0) & (py <= y1)
        px, py = px[ok], py[ok]
        z = ref.evaluate(px, py) + np.sqrt(np.maximum(radius**2 - (px - a) ** 2 - (py - b) ** 2, 0)) - radius
        out.append(z.max())
    return np.array(out)


@pytest.mark.slow
def test_drop_cutter_across_borders_against_brute_force():
    g = wavy_grid(20)
    s = piecewise_surface(g)
    ref = reference_surface(g)
    # positions on and beside borders, at corners of cells, and past the box
    xb, yb = [float(v) for v in g.x], [float(v) for v in g.y]
    rng = np.random.default_rng(7)
    cx = np.concatenate([[xb[5], xb[6] + 1e-9, xb[10], -1.0, 41.0], rng.uniform(-2, 42, 40)])
    cy = np.concatenate([[yb[3], yb[7], yb[10] - 1e-9, 20.0, yb[19]], rng.uniform(-2, 42, 40)])
    z = drop_cutter(s, cx, cy, 3.0)
    lower = brute_ball(ref, g, cx, cy, 3.0, n=401)
    assert np.all(z >= lower)  # no gouge
    # and close: a rim contact on the box edge (positions past the box) the lattice sees only to ~sqrt(2 R h)
    assert np.all(z - lower < 0.03)
    inside = (cx > 3) & (cx < 37) & (cy > 3) & (cy < 37)
    assert np.all((z - lower)[inside] < 2e-3)


@pytest.mark.slow
def test_toolpath_is_gouge_free_across_borders():
    g = wavy_grid(20)
    s = piecewise_surface(g)
    ref = reference_surface(g)
    tp = plan_toolpath(s, Tool("ball", 6.0), RasterSpec("x", 4.0, 1.0), Placement(1.0))
    p = tp.points_mm
    # the brute force at the points nearest a border (within 0.2 mm), and at some others
    bx = np.array([float(v) for v in g.x])
    near = np.abs(p[:, 0, None] - bx[None, :]).min(axis=1) < 0.2
    pick = np.flatnonzero(near)[::3][:150]
    pick = np.union1d(pick, np.random.default_rng(1).choice(len(p), 50, replace=False))
    lower = brute_ball(ref, g, p[pick, 0], p[pick, 1], 3.0, n=201)
    assert np.all(p[pick, 2] >= lower)
    # every row crosses 19 borders: the path's points lie on both sides of each
    row0 = p[tp.rows == 0]
    assert all(((row0[:, 0] < v) .any() and (row0[:, 0] > v).any()) for v in (float(x) for x in g.x[1:-1]))


def test_bspline_patch_is_the_pieces():
    """The one B-spline, cut at its knots by knot insertion (its own code), gives back every piece exactly."""
    from lagsym.cad import piecewise_patch

    s = piecewise_surface(wavy_grid(6, 5))
    p = piecewise_patch(s)
    assert (p.degree_u, p.degree_v) == (3, 3)
    assert sorted(set(p.knots_u)) == list(s.grid.x) and p.knots_u.count(s.grid.x[2]) == 2
    pieces = p.bezier_pieces()
    assert len(pieces) == 20
    rng = np.random.default_rng(5)
    for bp in pieces:
        x0, x1, y0, y1 = bp.box
        for a, b in rng.integers(0, 10, (3, 2)):
            u, v = x0 + (x1 - x0) * Fraction(int(a), 9), y0 + (y1 - y0) * Fraction(int(b), 9)
            assert bp.point(u, v) == (u, v, s.exact_value(u, v))


@pytest.mark.slow
@pytest.mark.parametrize("suffix", [".step", ".igs"])
def test_cad_file_read_back_by_opencascade(tmp_path, suffix):
    pytest.importorskip("OCP")
    from test_cad_files import bspline_faces, occ_points, read_back

    from lagsym.cad import piecewise_patch
    from lagsym.export.cad import write_cad

    s = piecewise_surface(wavy_grid(20))
    path = tmp_path / ("s" + suffix)
    write_cad(path, piecewise_patch(s), units="mm")
    faces = bspline_faces(read_back(path))
    assert len(faces) == 1
    occ = faces[0][1]
    assert (occ.NbUKnots(), occ.NbVKnots()) == (20, 20) and occ.UMultiplicity(2) == 2
    us = np.linspace(0, 40, 41)[1:-1] + 0.013
    got = occ_points(occ, us, us)
    want = np.array([[float(s.exact_value(Fraction(u), Fraction(v))) for v in us] for u in us])
    lo, hi = s.grid.z_range()
    assert np.abs(got[:, :, 2] - want).max() <= 1e-12 * float(hi - lo)


@pytest.mark.slow
def test_command_line(tmp_path):
    from lagsym.cli import main

    g = wavy_grid(12)
    src = tmp_path / "g.csv"
    src.write_text("x,y,z\n" + "".join(f"{x},{y},{g.z[i][k]}\n" if g.z[i][k].denominator == 1 else
                                       f"{x},{y},{float(g.z[i][k])}\n"
                                       for i, x in enumerate(map(float, g.x)) for k, y in enumerate(map(float, g.y))))
    out, err = io.StringIO(), io.StringIO()
    dst = tmp_path / "s.json"
    assert main(["piecewise", str(src), "-o", str(dst)], out, err) == 0
    assert "11 x 11 = 121 exact bicubic pieces through 12 x 12 points, C1" in out.getvalue()
    s = parse_piecewise_json(dst.read_text())
    assert s.exact_value(s.grid.x[3], s.grid.y[4]) == Fraction(s.grid.z[3][4])
    for cmd in (["macro", str(dst)], ["check", str(dst)]):
        out, err = io.StringIO(), io.StringIO()
        assert main(cmd, out, err) == 2
        assert len(err.getvalue().strip().splitlines()) == 1 and "piece" in err.getvalue()
    out, err = io.StringIO(), io.StringIO()
    nc = tmp_path / "p.nc"
    assert main(["toolpath", str(dst), "--stepover", "4", "--step", "2", "--tool-diameter", "6", "-o", str(nc)],
                out, err) == 0
    assert nc.read_text().startswith("%") and "cutter locations" in err.getvalue()


def test_the_measured_data_page_quotes_the_figures(tmp_path, monkeypatch):
    """docs/measured-data.md's piecewise figures, from the commands and from the formula the example was made from."""
    from conftest import EXAMPLES, ROOT

    from lagsym.cli import main
    from lagsym.io import read_points

    page = " ".join((ROOT / "docs" / "measured-data.md").read_text().split())
    src = EXAMPLES / "part-20x20.csv"
    out, err = io.StringIO(), io.StringIO()
    main(["check", str(src)], out, err)
    amp = re.search(r"surface amplification of data errors: (\S+) ", out.getvalue()).group(1)
    over = re.search(r"overshoot between nodes: (\S+) sampled, .*; at most (\S+) \((\S+) of the data range",
                     out.getvalue()).groups()
    assert f"up to {amp} times" in page
    assert f"overshoots by {over[0]} (at most {over[1]}, {over[2]} of the data range)" in page
    monkeypatch.chdir(tmp_path)
    (tmp_path / "examples").symlink_to(EXAMPLES)
    out, err = io.StringIO(), io.StringIO()
    assert main(["piecewise", "examples/part-20x20.csv", "-o", "pieces.json"], out, err) == 0
    assert "$ lagsym piecewise examples/part-20x20.csv -o pieces.json " + out.getvalue().strip() in page
    # the pieces against the formula, on the float reference surface
    g = read_points(src)
    ref = reference_surface(g)
    t = np.linspace(0, 38, 761)
    gx, gy = np.meshgrid(t, t, indexing="ij")
    d = ref.evaluate_grid(t, t) - (10 + 5 * np.sin(gx / 6) * np.cos(gy / 8) + 0.02 * gx * gy)
    assert f"within {np.abs(d).max():.3f} mm of the formula" in page
    assert f"(RMS {np.sqrt((d ** 2).mean()):.4f} mm;" in page


def brute_flat(ref, grid, cx, cy, radius, corner=0.0, n=201):
    """Brute force for a flat end or a bull nose: the highest of the reference surface less the cutter's profile."""
    x0, x1, y0, y1 = (float(v) for v in grid.bounds)
    t = np.linspace(-radius, radius, n)
    gx, gy = np.meshgrid(t, t)
    d = np.hypot(gx, gy)
    inside = d <= radius
    flat = radius - corner
    prof = np.where(d <= flat, 0.0, corner - np.sqrt(np.maximum(corner**2 - (d - flat) ** 2, 0.0)))[inside]
    out = []
    for a, b in zip(cx, cy):
        px, py = a + gx[inside], b + gy[inside]
        ok = (px >= x0) & (px <= x1) & (py >= y0) & (py <= y1)
        out.append((ref.evaluate(px[ok], py[ok]) - prof[ok]).max())
    return np.array(out)


@pytest.mark.parametrize("shape, corner", [("flat", None), ("bull", 1.0)])
def test_flat_and_bull_cutters_across_borders(shape, corner):
    g = wavy_grid(12, 10)
    s = piecewise_surface(g)
    ref = reference_surface(g)
    rng = np.random.default_rng(11)
    cx, cy = rng.uniform(-1, 41, 12), rng.uniform(-1, 41, 12)
    cx[:3] = [float(g.x[4]), float(g.x[7]), float(g.x[2])]
    z = drop_cutter(s, cx, cy, 2.5, shape, corner=corner)
    lower = brute_flat(ref, g, cx, cy, 2.5, 0.0 if corner is None else corner)
    assert np.all(z >= lower)
    assert np.all(z - lower < 0.03)


def test_a_point_tool_is_the_surface():
    g = wavy_grid(8, 6)
    s = piecewise_surface(g)
    z = drop_cutter(s, [float(g.x[3]), 12.5], [float(g.y[2]), 30.25], 0.0)
    assert z[0] == float(g.z[3][2])
    assert abs(z[1] - float(s.exact_value(Fraction(12.5), Fraction(30.25)))) < 1e-12


@pytest.mark.parametrize("change, message", [
    ({"x": 3}, '"x" should be a list'),
    ({"z": [1, 2]}, '"z" should be a list of rows'),
    ({"y": ["0", "1e999999", "2"]}, "y\\[1\\]: '1e999999' is out of range"),
    ({"version": 2}, "version 2 is not 1"),
    ({"units": "furlong"}, "units"),
])
def test_bad_files_are_refused_in_one_line(change, message):
    buf = io.StringIO()
    write_piecewise_json(buf, piecewise_surface(wavy_grid(4, 3)))
    doc = __import__("json").loads(buf.getvalue())
    doc.update(change)
    with pytest.raises(InputError, match=message) as e:
        parse_piecewise_json(__import__("json").dumps(doc), "bad.json")
    assert "\n" not in str(e.value)


def test_a_pieces_evaluator_is_the_one_made_from_the_piece_bit_for_bit():
    """The evaluator made straight from a piece's local coefficients equals the one made the long way, through
    the piece as a Lagrange surface and its exact change of basis."""
    from lagsym.evaluate import surface_evaluator

    s = piecewise_surface(wavy_grid(9, 7))
    for i, k in [(0, 0), (3, 2), (7, 5), (4, 0)]:
        a, b = s.piece_evaluator(i, k), surface_evaluator(s.piece(i, k))
        assert (a.x_offset, a.x_scale, a.y_offset, a.y_scale, a.data_range, a.bounds) == \
            (b.x_offset, b.x_scale, b.y_offset, b.y_scale, b.data_range, b.bounds)
        for name in ("coefficients", "x_nodes", "y_nodes", "x_exact", "y_exact", "node_values"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert s.piece_evaluator(3, 2) is s.piece_evaluator(3, 2)


@pytest.mark.parametrize("parts", [1, 4])
def test_no_point_of_a_part_lies_above_its_bound(parts):
    """Each part's bound, checked against exact values of the piece at rational points of the part (corners,
    edges and inside); the parts' bounds are no higher than the whole piece's."""
    g = wavy_grid(6, 5)
    s = piecewise_surface(g)
    tops = s.evaluator.part_upper_heights(parts)
    f = [Fraction(j, 8) for j in range(9)]
    for i, k in [(0, 0), (2, 3), (4, 1)]:
        x0, x1, y0, y1 = s.box(i, k)
        for p in range(parts):
            for q in range(parts):
                u0, v0 = x0 + (x1 - x0) * Fraction(p, parts), y0 + (y1 - y0) * Fraction(q, parts)
                du, dv = (x1 - x0) / parts, (y1 - y0) / parts
                values = [s.exact_value(u0 + du * a, v0 + dv * b) for a in f for b in f]
                assert max(values) <= Fraction(tops[i, k, p, q])
        assert tops[i, k].max() <= s.evaluator.upper_heights[i, k] + 1e-9


def test_drops_share_out_among_worker_processes_with_the_same_values():
    from lagsym.toolpath.workers import Workers

    s = piecewise_surface(wavy_grid(14, 12))
    rng = np.random.default_rng(5)
    cx, cy = rng.uniform(-1.7, 41.7, 6000), rng.uniform(-1.7, 41.7, 6000)
    alone = drop_cutter(s, cx, cy, 2.5)
    with Workers(s.evaluator, 2) as workers:
        assert workers.parallel
        shared = drop_cutter(s, cx, cy, 2.5, workers=workers)
    assert np.array_equal(alone, shared)


@pytest.mark.parametrize("parts", [4, 16])
@pytest.mark.parametrize("corner", [3.0, 1.0, 0.0])
def test_what_a_piece_can_lift_the_tool_to_is_never_understated(parts, corner):
    """The bound drop-cutter rules pieces out by, against the float reference surface (built apart from lagsym)
    less the cutter's profile on a dense grid of each piece's cell within the tool's reach."""
    from lagsym.toolpath.droppieces import _piece_bounds, _piece_pairs

    g = wavy_grid(9, 8)
    s, ref, radius = piecewise_surface(g), reference_surface(g), 3.0
    rng = np.random.default_rng(3)
    cx, cy = rng.uniform(-2, 42, 25), rng.uniform(-2, 42, 25)
    pos, i, k = _piece_pairs(s.evaluator, cx, cy, radius)
    bound = _piece_bounds(s.evaluator, cx, cy, (pos, i, k), radius, corner, parts=parts)
    t = np.linspace(0.0, 1.0, 61)
    flat = radius - corner
    for p, a, b, top in zip(pos, i, k, bound):
        x0, x1, y0, y1 = (float(v) for v in s.box(int(a), int(b)))
        px, py = np.meshgrid(x0 + (x1 - x0) * t, y0 + (y1 - y0) * t)
        d = np.hypot(px - cx[p], py - cy[p])
        near = d <= radius
        if not near.any():
            continue
        prof = np.where(d <= flat, 0.0, corner - np.sqrt(np.maximum(corner**2 - (d - flat) ** 2, 0.0)))
        assert (ref.evaluate(px[near], py[near]) - prof[near]).max() <= top + 1e-9


def test_every_pieces_jets_at_once_are_each_pieces_own():
    """The jets made for all pieces at once (for the worker processes) are those of each piece's evaluator."""
    from lagsym.toolpath.newton import jet_coefficients

    s = piecewise_surface(wavy_grid(9, 7))
    jets = s.evaluator.piece_jets
    assert jets.shape == (8, 6, 24, 4)
    for i in range(8):
        for k in range(6):
            assert np.array_equal(jets[i, k], jet_coefficients(s.piece_evaluator(i, k)))
