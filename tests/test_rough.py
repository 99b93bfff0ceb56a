"""Z-level roughing: checked on what LinuxCNC's rs274 does with the program, against the exact surface in NumPy.

The independent check sweeps a flat end mill along every move rs274 reports
over a height map of the block (written here, not lagsym's), and compares
it with the interpolating polynomial evaluated from the control points
(Lagrange basis products, written here too).
"""

from __future__ import annotations

import json
import re
import tempfile
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent
EX4 = ROOT / "examples" / "paper-example-4.json"
SCALE, R, STEPDOWN, STOCK, STEPOVER = 20.0, 5.0, 2.0, 0.3, 5.0
_MOVE = re.compile(r"^\s*\d+\s+N\S*\s+(STRAIGHT_FEED|STRAIGHT_TRAVERSE)\((.*)\)\s*$")


def exact_heights(path, x_mm, y_mm):
    """The Lagrange surface through the control points at machine (x, y), mm, by the basis products."""
    pts = np.array(json.loads(Path(path).read_text())["points"], dtype=float)
    xs, ys = np.unique(pts[:, 0]), np.unique(pts[:, 1])
    z = np.zeros((len(xs), len(ys)))
    for px, py, pz in pts:
        z[np.searchsorted(xs, px), np.searchsorted(ys, py)] = pz

    def basis(nodes, t):
        out = []
        for i, n in enumerate(nodes):
            b = np.ones_like(t)
            for j, m in enumerate(nodes):
                if j != i:
                    b = b * (t - m) / (n - m)
            out.append(b)
        return np.array(out)

    u, v = np.asarray(x_mm) / SCALE, np.asarray(y_mm) / SCALE
    return np.einsum("ij,i...,j...->...", z, basis(xs, u), basis(ys, v)) * SCALE


def moves(rs274, text, tools="T1 P1 Z0 D10 ;r\nT2 P2 Z0 D6 ;b\n"):
    """rs274's moves in program order: (kind, x, y, z) with kind 'F' feed or 'T' traverse."""
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "p.ngc"
        p.write_text(text)
        r = rs274.run(p, tool_table=tools)
    assert r.returncode == 0 and "PROGRAM_END" in r.stdout, r.stderr[-500:]
    out = []
    for line in r.stdout.splitlines():
        m = _MOVE.match(line)
        if m:
            out.append(("F" if m.group(1) == "STRAIGHT_FEED" else "T", *map(float, m.group(2).split(",")[:3])))
    return out


def sweep_flat(h, gx, gy, p0, p1, radius):
    """Lower the height map where a flat end of ``radius`` moving straight from p0 to p1 passes; return the
    lowest tip height over each cell it covers (nan elsewhere) and the cells' material above that before."""
    lo_x, hi_x = min(p0[0], p1[0]) - radius, max(p0[0], p1[0]) + radius
    lo_y, hi_y = min(p0[1], p1[1]) - radius, max(p0[1], p1[1]) + radius
    # The cells within the move's box: a window of the (increasing) axes, so the map is read and written in place.
    ix = slice(np.searchsorted(gx, lo_x, "left"), np.searchsorted(gx, hi_x, "right"))
    iy = slice(np.searchsorted(gy, lo_y, "left"), np.searchsorted(gy, hi_y, "right"))
    if ix.stop <= ix.start or iy.stop <= iy.start:
        return 0.0
    qx, qy = np.meshgrid(gx[ix], gy[iy], indexing="ij")
    dx, dy = p1[0] - p0[0], p1[1] - p0[1]
    a = dx * dx + dy * dy
    ex, ey = qx - p0[0], qy - p0[1]
    c = ex * ex + ey * ey - radius * radius
    if a < 1e-18:
        cover, zlow = c <= 0, np.full(qx.shape, min(p0[2], p1[2]))
    else:
        b = -2 * (dx * ex + dy * ey)
        disc = b * b - 4 * a * c
        s = np.sqrt(np.maximum(disc, 0))
        r1, r2 = (-b - s) / (2 * a), (-b + s) / (2 * a)
        cover = (disc >= 0) & (r1 <= 1) & (r2 >= 0)
        t1, t2 = np.clip(r1, 0, 1), np.clip(r2, 0, 1)
        z1, z2 = p0[2] + t1 * (p1[2] - p0[2]), p0[2] + t2 * (p1[2] - p0[2])
        zlow = np.minimum(z1, z2)
    sub = h[ix, iy]
    removed = np.where(cover, np.maximum(sub - zlow, 0), 0).max(initial=0.0)
    h[ix, iy] = np.where(cover, np.minimum(sub, zlow), sub)
    return float(removed)


@pytest.fixture(scope="module")
def program():
    from lagsym.cli import main
    import io

    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "rough.ngc"
        err = io.StringIO()
        status = main(["rough", str(EX4), "--scale", "20", "--stock-above", "2", "--tool-shape", "flat",
                       "--tool-diameter", "10", "--stepdown", "2", "--stepover", "5", "--stock-to-leave", "0.3",
                       "--safe-z", "90", "--dialect", "linuxcnc", "-o", str(out)], io.StringIO(), err)
        assert status == 0, err.getvalue()
        return out.read_text(), err.getvalue()


@pytest.mark.slow
def test_roughing_example_4_is_gouge_free_and_clears_the_block(rs274, program):
    """No cut below surface + stock; everywhere the block is down to one step-down above what the tool reaches."""
    text, _ = program
    mv = moves(rs274, text)
    cell = 0.5
    gx = gy = np.arange(10.0, 110.0 + cell / 2, cell)
    fx, fy = np.meshgrid(gx, gy, indexing="ij")
    inbox = (fx >= 20) & (fx <= 100) & (fy >= 20) & (fy <= 100)
    f = np.where(inbox, exact_heights(EX4, np.clip(fx, 20, 100), np.clip(fy, 20, 100)), -np.inf)
    top = float(exact_heights(EX4, *np.meshgrid(np.linspace(20, 100, 401), np.linspace(20, 100, 401))).max()) + 2
    h = np.where(inbox, top, -np.inf)  # the block is the box (no margin): air around it
    pos = None
    for kind, x, y, z in mv:
        if pos is not None:
            removed = sweep_flat(h, gx, gy, pos, (x, y, z), R)
            if kind == "T" or (x, y) == pos[:2]:
                assert removed <= 1e-6, f"a rapid or a plunge at {pos} -> {(x, y, z)} cut {removed} mm of stock"
        pos = (x, y, z)
    left = np.where(inbox, h, 0.0) - np.where(inbox, f, 0.0)
    assert left[inbox].min() >= STOCK - 0.002, "the roughing cut into the stock to leave"
    # What the tool can reach: the lowest flat-end CL over centres on the rows (y = 20, 25, ..., 100) covering a cell.
    k = int(round(R / cell))
    off = [(i, j) for i in range(-k, k + 1) for j in range(-k, k + 1) if (i * i + j * j) * cell * cell <= R * R]
    pad = np.pad(f, k, constant_values=-np.inf)
    cl = np.max([pad[k + i:k + i + len(gx), k + j:k + j + len(gy)] for i, j in off], axis=0)
    on_row = np.isclose((gy - 20) % STEPOVER, 0) & (gy >= 20) & (gy <= 100)
    cl_rows = np.where(on_row[None, :], cl, np.inf)
    padc = np.pad(cl_rows, k, constant_values=np.inf)
    reach = np.min([padc[k + i:k + i + len(gx), k + j:k + j + len(gy)] for i, j in off], axis=0)
    assert np.isfinite(reach[inbox]).all(), "a cell of the box no row comes within the radius of"
    slope = max(np.abs(np.diff(f[inbox].reshape(161, 161), axis=0)).max(), 0) / cell
    tol = slope * cell + 0.2  # the grid's own error of the maximum, plus the sag allowance
    excess = np.where(inbox, h - (np.maximum(reach, f) + STOCK), -np.inf)
    assert excess.max() <= STEPDOWN + tol, excess.max()


@pytest.mark.slow
def test_raster_roughing_leaves_at_most_a_step_down_at_the_box_edges_too(rs274, program):
    """rs274's moves swept through a height map of the block (0.25 mm cells): nowhere, the start edge x = 20
    included, is more than one step-down left above what the flat end reaches from the rows (the lowest
    lattice drop-cutter height over the row centres covering a cell, tool centres beside the box included),
    and nowhere less than the stock.  A tool beside the box rests on what is under it, not on the height at the
    box edge: that rule left 3.84 mm at X20 Y100 above a surface rising 9 mm over the first 5 mm."""
    text, _ = program
    cell = 0.25
    gx = gy = np.arange(10.0, 110.0 + cell / 2, cell)
    fx, fy = np.meshgrid(gx, gy, indexing="ij")
    inbox = (fx >= 20) & (fx <= 100) & (fy >= 20) & (fy <= 100)
    f = np.where(inbox, exact_heights(EX4, np.clip(fx, 20, 100), np.clip(fy, 20, 100)), -np.inf)
    h = np.where(inbox, float(f.max()) + 2, -np.inf)
    pos = None
    for _, x, y, z in moves(rs274, text):
        if pos is not None:
            sweep_flat(h, gx, gy, pos, (x, y, z), R)
        pos = (x, y, z)
    k = int(round(R / cell))
    off = [(i, j) for i in range(-k, k + 1) for j in range(-k, k + 1) if (i * i + j * j) * cell * cell <= R * R]
    pad = np.pad(f, k, constant_values=-np.inf)
    cl = np.max([pad[k + i:k + i + len(gx), k + j:k + j + len(gy)] for i, j in off], axis=0)
    on_row = np.isclose((gy - 20) % STEPOVER, 0) & (gy >= 20) & (gy <= 100)
    padc = np.pad(np.where(on_row[None, :], cl, np.inf), k, constant_values=np.inf)
    reach = np.min([padc[k + i:k + i + len(gx), k + j:k + j + len(gy)] for i, j in off], axis=0)
    left = h[inbox] - f[inbox]
    excess = h[inbox] - (np.maximum(reach[inbox], f[inbox]) + STOCK)
    worst = int(np.argmax(excess))
    assert excess[worst] <= STEPDOWN, (excess[worst], fx[inbox][worst], fy[inbox][worst])
    assert left.min() >= STOCK - 0.002


@pytest.mark.slow
def test_every_roughing_position_is_above_the_flat_drop_cutter_height(rs274, program):
    """Each feed end point over the box is at least stock above the dense lattice drop-cutter height (a lower bound)."""
    text, _ = program
    pts = np.array([m[1:] for m in moves(rs274, text) if m[0] == "F"])
    over = (pts[:, 0] >= 20) & (pts[:, 0] <= 100) & (pts[:, 1] >= 20) & (pts[:, 1] <= 100)
    p = pts[over][::7]
    a = np.linspace(-R, R, 41)
    ox, oy = np.meshgrid(a, a)
    inside = ox ** 2 + oy ** 2 <= R * R
    ox, oy = ox[inside], oy[inside]
    qx = np.clip(p[:, 0, None] + ox[None, :], 20, 100)
    qy = np.clip(p[:, 1, None] + oy[None, :], 20, 100)
    cl = exact_heights(EX4, qx, qy).max(axis=1)
    assert (p[:, 2] - cl).min() >= STOCK - 0.002


@pytest.mark.slow
@pytest.mark.parametrize("dialect", ["fanuc", "linuxcnc", "grbl"])
@pytest.mark.parametrize("milling", ["zigzag", "climb"])
def test_every_dialect_passes_rs274(rs274, run_cli, tmp_path, dialect, milling):
    out = tmp_path / "r.nc"
    status, _, err = run_cli("rough", EX4, "--scale", "20", "--stock-above", "2", "--tool-diameter", "10",
                             "--stepdown", "10", "--stepover", "5", "--step", "1", "--safe-z", "90",
                             "--milling", milling, "--dialect", dialect, "-o", out)
    assert status == 0, err
    mv = moves(rs274, out.read_text())
    assert min(m[3] for m in mv if m[0] == "F") >= 3.0


@pytest.mark.slow
def test_climb_rows_keep_the_material_on_the_right(rs274, run_cli, tmp_path):
    """One-way climb rows along x, advancing in +y on the first level: every cutting row runs in -x."""
    out = tmp_path / "r.ngc"
    status, _, err = run_cli("rough", EX4, "--scale", "20", "--stock-above", "2", "--stepdown", "80",
                             "--stepover", "5", "--safe-z", "90", "--milling", "climb", "--dialect", "linuxcnc",
                             "-o", out)
    assert status == 0, err
    mv = moves(rs274, out.read_text())
    rows = [(a, b) for a, b in zip(mv, mv[1:]) if b[0] == "F" and a[2] == b[2] and a[3] == b[3] and a[1] != b[1]]
    assert rows and all(b[1] < a[1] for a, b in rows)


@pytest.mark.parametrize("args, words", [
    (("--stock-top", "10"), "below the surface's highest point"),
    (("--stock-above", "2", "--flute-length", "1"), "larger than the flute length"),
    (("--stock-above", "2", "--reach", "30"), "cannot reach"),
    (("--stock-above", "2", "--stepover", "12"), "wider than the tool"),
    (("--stock-above", "2", "--block", "30,90,20,100"), "does not cover"),
    (("--stock-above", "2", "--tool-shape", "drill"), "shape = 'drill' is not one of ball, flat"),
    (("--stock-above", "2", "--pattern", "offset", "--direction", "y"), "--direction y does not apply"),
    (("--stock-above", "2", "--pattern", "offset", "--milling", "zigzag"), "cuts every rectangle one way"),
    (("--stock-above", "2", "--pattern", "offset", "--macro"), "a roughing macro runs raster rows"),
])
@pytest.mark.slow
def test_bad_roughing_requests_get_one_line_and_exit_2(run_cli, args, words):
    status, out, err = run_cli("rough", EX4, "--scale", "20", "--safe-z", "90", *args)
    assert status == 2 and words in err and err.count("\n") == 1 and not out, err


@pytest.mark.slow
def test_offset_clearing_is_gouge_free_and_clears_the_block(rs274, run_cli, tmp_path):
    """Concentric rectangles at every level: the same checks as the raster's, with what the tool can reach
    taken over the centres the program's feed moves pass (every 0.5 mm along them)."""
    out = tmp_path / "offset.ngc"
    status, _, err = run_cli("rough", EX4, "--scale", "20", "--stock-above", "2", "--tool-diameter", "10",
                             "--stepdown", "2", "--stepover", "5", "--stock-to-leave", "0.3", "--safe-z", "90",
                             "--pattern", "offset", "--dialect", "linuxcnc", "-o", out)
    assert status == 0, err
    mv = moves(rs274, out.read_text())
    cell = 0.5
    gx = gy = np.arange(10.0, 110.0 + cell / 2, cell)
    fx, fy = np.meshgrid(gx, gy, indexing="ij")
    inbox = (fx >= 20) & (fx <= 100) & (fy >= 20) & (fy <= 100)
    f = np.where(inbox, exact_heights(EX4, np.clip(fx, 20, 100), np.clip(fy, 20, 100)), -np.inf)
    top = float(exact_heights(EX4, *np.meshgrid(np.linspace(20, 100, 401), np.linspace(20, 100, 401))).max()) + 2
    h = np.where(inbox, top, -np.inf)
    pos, centres, entries = None, [], []
    for kind, x, y, z in mv:
        if pos is not None:
            removed = sweep_flat(h, gx, gy, pos, (x, y, z), R)
            if kind == "T" or (x, y) == pos[:2]:
                assert removed <= 1e-6, f"a rapid or a plunge at {pos} -> {(x, y, z)} cut {removed} mm of stock"
                if kind != "T":
                    entries.append((x, y))
            else:
                n = int(np.ceil(np.hypot(x - pos[0], y - pos[1]) / cell)) + 1
                centres += list(zip(np.linspace(pos[0], x, n), np.linspace(pos[1], y, n)))
        pos = (x, y, z)
    # every level comes down beside the block, clear of it by more than the tool radius
    assert entries and all(min(x - 20, 100 - x, y - 20, 100 - y) < -R for x, y in entries)
    assert (np.where(inbox, h, 0.0) - np.where(inbox, f, 0.0))[inbox].min() >= STOCK - 0.002
    k = int(round(R / cell))
    off = [(i, j) for i in range(-k, k + 1) for j in range(-k, k + 1) if (i * i + j * j) * cell * cell <= R * R]
    pad = np.pad(f, k, constant_values=-np.inf)
    cl = np.max([pad[k + i:k + i + len(gx), k + j:k + j + len(gy)] for i, j in off], axis=0)
    on_path = np.zeros(cl.shape, dtype=bool)
    c = np.array(centres)
    ix, iy = np.rint((c[:, 0] - gx[0]) / cell).astype(int), np.rint((c[:, 1] - gy[0]) / cell).astype(int)
    keep = (ix >= 0) & (ix < len(gx)) & (iy >= 0) & (iy < len(gy))
    on_path[ix[keep], iy[keep]] = True
    padc = np.pad(np.where(on_path, cl, np.inf), k, constant_values=np.inf)
    reach = np.min([padc[k + i:k + i + len(gx), k + j:k + j + len(gy)] for i, j in off], axis=0)
    assert np.isfinite(reach[inbox]).all(), "a cell of the box no centre of the path comes within the radius of"
    slope = max(np.abs(np.diff(f[inbox].reshape(161, 161), axis=0)).max(), 0) / cell
    excess = np.where(inbox, h - (np.maximum(reach, f) + STOCK), -np.inf)
    assert excess.max() <= STEPDOWN + slope * cell + 0.2, excess.max()


def test_offset_rectangles_run_clockwise_for_climb(rs274, run_cli, tmp_path):
    """Climb milling with the middle uncut: the first side after the lead-in runs up the block's left edge (+y)."""
    out = tmp_path / "o.ngc"
    status, _, err = run_cli("rough", EX4, "--scale", "20", "--stock-above", "2", "--stepdown", "80",
                             "--safe-z", "90", "--pattern", "offset", "--dialect", "linuxcnc", "-o", out)
    assert status == 0, err
    feeds = [m for m in moves(rs274, out.read_text()) if m[0] == "F"]
    lead = [m for m in feeds if m[2] == 20.0 and m[1] <= 20.0]
    assert lead and min(m[1] for m in lead) < 15.0  # fed in from beside the block along its edge
    left = [m for m in feeds if m[1] == 20.0 and m[2] > 20.0]
    assert left and left[0][2] < left[-1][2]
