"""Roughing and jobs on a piecewise surface, against a brute-force flat end over pieces built apart from lagsym.

The reference surface is ``piecewise_check``'s (the Hermite pieces from their
definition); the programs are read by a small modal reader here, and the
flat end's bottom swept along each straight move is found per grid point
from the part of the move within the tool's radius (its height is linear
along the move, so lowest at an end of that part).
"""

from __future__ import annotations

import io
import re

import numpy as np
import pytest

from conftest import EXAMPLES
from piecewise_check import Reference

PART = EXAMPLES / "part-20x20.csv"
STOCK_MM = 0.3
ROUGH = ["--stock-above", "2", "--tool-shape", "flat", "--tool-diameter", "10", "--stepdown", "3", "--stepover", "5",
         "--step", "1", "--stock-to-leave", str(STOCK_MM), "--safe-z", "60", "--dialect", "linuxcnc"]


@pytest.fixture(scope="module")
def ref():
    return Reference(PART)


@pytest.fixture(scope="module")
def pieces(tmp_path_factory):
    from lagsym.cli import main

    path = tmp_path_factory.mktemp("pw") / "pieces.json"
    assert main(["piecewise", str(PART), "-o", str(path)], io.StringIO(), io.StringIO()) == 0
    return path


def moves_of(text, start_line=0, stop_line=None):
    """The straight moves (G00/G01, modal) of a plain program between two lines, as (a, b) arrays of X, Y, Z."""
    pos, mode, known = {"X": 0.0, "Y": 0.0, "Z": None}, None, False
    a, b = [], []
    for n, line in enumerate(text.splitlines()):
        line = re.sub(r"\(.*?\)", "", line).upper()
        words = dict((w[0], float(w[1:])) for w in re.findall(r"[A-Z][-+.\d]+", line))
        if "G" in words and words["G"] in (0.0, 1.0):
            mode = int(words["G"])
        new = dict(pos)
        new.update({k: v for k, v in words.items() if k in "XYZ"})
        moved = any(k in words for k in "XYZ") and mode in (0, 1)
        if moved and known and start_line <= n and (stop_line is None or n < stop_line):
            a.append([pos["X"], pos["Y"], pos["Z"]])
            b.append([new["X"], new["Y"], new["Z"]])
        pos = new
        known = pos["Z"] is not None
    return np.array(a), np.array(b)


def flat_cut(a, b, radius, gx, gy):
    """Lowest height the flat bottom of radius ``radius`` reaches over every point of ``gx`` x ``gy`` (inf: never)."""
    out = np.full((len(gx), len(gy)), np.inf)
    for p, q in zip(a, b):
        i0, i1 = np.searchsorted(gx, min(p[0], q[0]) - radius), np.searchsorted(gx, max(p[0], q[0]) + radius)
        j0, j1 = np.searchsorted(gy, min(p[1], q[1]) - radius), np.searchsorted(gy, max(p[1], q[1]) + radius)
        if i0 >= i1 or j0 >= j1:
            continue
        X, Y = np.meshgrid(gx[i0:i1], gy[j0:j1], indexing="ij")
        d = q[:2] - p[:2]
        # |p + t d - P|^2 <= r^2:  (d.d) t^2 - 2 t d.(P - p) + |P - p|^2 - r^2 <= 0
        ex, ey = X - p[0], Y - p[1]
        A, B, C = d @ d, -2 * (d[0] * ex + d[1] * ey), ex * ex + ey * ey - radius * radius
        if A == 0:
            lo = np.where(C <= 0, 0.0, np.nan)
            hi = lo
        else:
            disc = B * B - 4 * A * C
            root = np.sqrt(np.where(disc >= 0, disc, np.nan))
            lo, hi = np.maximum((-B - root) / (2 * A), 0.0), np.minimum((-B + root) / (2 * A), 1.0)
            lo, hi = np.where(lo <= hi, lo, np.nan), np.where(lo <= hi, hi, np.nan)
        z = np.fmin(p[2] + lo * (q[2] - p[2]), p[2] + hi * (q[2] - p[2]))
        out[i0:i1, j0:j1] = np.fmin(out[i0:i1, j0:j1], np.where(np.isnan(z), np.inf, z))
    return out


def above_surface(ref, a, b, radius, step=0.2):
    """The flat end's lowest bottom less the reference surface over the box, on a ``step`` grid."""
    gx = np.arange(ref.bx[0], ref.bx[-1] + step / 2, step)
    gy = np.arange(ref.by[0], ref.by[-1] + step / 2, step)
    X, Y = np.meshgrid(gx, gy, indexing="ij")
    return flat_cut(a, b, radius, gx, gy) - ref(X, Y)


@pytest.mark.slow
def test_rough_leaves_the_stock_on_the_pieces(tmp_path, ref, pieces):
    from lagsym.cli import main

    nc = tmp_path / "rough.ngc"
    out, err = io.StringIO(), io.StringIO()
    assert main(["rough", str(pieces), *ROUGH, "-o", str(nc)], out, err) == 0, err.getvalue()
    a, b = moves_of(nc.read_text())
    left = above_surface(ref, a, b, 5.0)
    assert np.isfinite(left).all()  # every point of the box was passed over
    # never below the stock to leave (the program rounds to 0.0005 mm), and down to it somewhere
    assert STOCK_MM - 0.001 <= float(left.min()) <= STOCK_MM + 0.01


@pytest.mark.slow
def test_rough_macro_is_refused_in_one_line(tmp_path, pieces):
    from lagsym.cli import main

    nc = tmp_path / "rough.ngc"
    out, err = io.StringIO(), io.StringIO()
    assert main(["rough", str(pieces), *ROUGH, "--macro", "-o", str(nc)], out, err) == 2
    assert len(err.getvalue().strip().splitlines()) == 1
    assert "one polynomial" in err.getvalue() and "361" in err.getvalue() and not nc.exists()


JOB = """points = "{points}"
dialect = "linuxcnc"
safe_z = 60

[stock]
top_above = 2

[tools.rougher]
number = 1
shape = "flat"
diameter = 10

[tools.ball6]
number = 2
shape = "ball"
diameter = 6

[[operations]]
kind = "rough"
tool = "rougher"
stepdown = 3
stepover = 5
step = 1
stock_to_leave = {stock}{macro}

[[operations]]
kind = "finish"
tool = "ball6"
stepover = 3
step = 1
"""


@pytest.mark.slow
def test_a_job_on_the_pieces(tmp_path, ref, pieces):
    from lagsym.cli import main

    job = tmp_path / "job.toml"
    job.write_text(JOB.format(points=pieces.as_posix(), stock=STOCK_MM, macro=""))
    nc = tmp_path / "job.ngc"
    out, err = io.StringIO(), io.StringIO()
    assert main(["job", str(job), "-o", str(nc)], out, err) == 0, err.getvalue()
    text = nc.read_text()
    change = next(n for n, line in enumerate(text.splitlines()) if re.match(r"T2 M0?6", line))
    left = above_surface(ref, *moves_of(text, stop_line=change), 5.0)
    assert STOCK_MM - 0.001 <= float(left.min()) <= STOCK_MM + 0.01
    # the whole job simulated from its block on the pieces: no gouge
    out, err = io.StringIO(), io.StringIO()
    assert main(["verify", "--job", str(job), str(nc), "--cell", "0.4"], out, err) == 0, out.getvalue()
    assert re.search(r"worst gouge +0\.0000 mm", out.getvalue())
    # a roughing macro in the job is refused in one line, naming the operation
    job.write_text(JOB.format(points=pieces.as_posix(), stock=STOCK_MM, macro="\nmacro = true"))
    out, err = io.StringIO(), io.StringIO()
    assert main(["job", str(job), "-o", str(tmp_path / "m.ngc")], out, err) == 2
    assert len(err.getvalue().strip().splitlines()) == 1 and "operations[0]" in err.getvalue()
    assert not (tmp_path / "m.ngc").exists()
