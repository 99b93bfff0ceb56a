"""Work that would run away is estimated from the input and refused before it starts, with the figure.

A case that ran away before its estimate existed is run here in a child process
with a memory limit and a timeout, so that this suite itself never runs away.
"""

from __future__ import annotations

import re
import resource
import subprocess
import sys
from fractions import Fraction
from math import comb

import flint
import pytest

from lagsym import (LagsymError, curve_from_points, grid_from_points, grid_from_table, lagrange_curve,
                    lagrange_surface)
from lagsym.evaluate import chebyshev_transform
from lagsym.exactsize import MAX_EXACT_MB, MAX_EXACT_S, exact_size_mb, exact_time_limit

from conftest import EXAMPLES

MEMORY = 2 * 1024**3


def _limited():
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))


def _child(code: str, timeout: float = 30) -> subprocess.CompletedProcess:
    """``code`` run by a fresh interpreter within 2 GB and ``timeout`` seconds."""
    try:
        return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout,
                              preexec_fn=_limited)
    except subprocess.TimeoutExpired:
        pytest.fail(f"still running after {timeout} s: {code}")


def _poly_mul(p, q):
    out = [Fraction(0)] * (len(p) + len(q) - 1)
    for i, a in enumerate(p):
        for j, b in enumerate(q):
            out[i + j] += a * b
    return out


def _basis_bits(nodes) -> int:
    """The bits of every reduced rational of the Lagrange basis on ``nodes``, by the textbook products."""
    bits = 0
    for i, xi in enumerate(nodes):
        p = [Fraction(1)]
        for j, xj in enumerate(nodes):
            if j != i:
                p = _poly_mul(p, [-xj / (xi - xj), 1 / (xi - xj)])
        bits += sum(c.numerator.bit_length() + c.denominator.bit_length() for c in p)
    return bits


NODE_SETS = [
    [Fraction(i) for i in range(12)],
    [Fraction(i, 10) for i in range(15)],
    [Fraction(1000 + 7 * i) for i in range(10)],
    [Fraction(137 * i + 13 * i * i, 10_000) for i in range(14)],
    [Fraction(1, 3), Fraction(2, 7), Fraction(5, 11), Fraction(9, 4), Fraction(-3, 13)],
]


@pytest.mark.parametrize("nodes", NODE_SETS, ids=range(len(NODE_SETS)))
def test_the_estimate_bounds_the_real_size_of_the_basis(nodes):
    real = _basis_bits(nodes)
    estimate = exact_size_mb(nodes) * 8e6
    assert real <= estimate
    assert estimate <= 8 * real  # an estimate, not a figure off by orders of magnitude


def test_a_curve_over_the_limit_is_refused_with_the_figure_before_any_work():
    pts = curve_from_points([(Fraction(i, 10), i % 7) for i in range(60)])
    size = exact_size_mb(pts.x)
    with pytest.raises(LagsymError) as e:
        lagrange_curve(pts, max_mb=size / 2)
    text = str(e.value)
    assert f"{size:.3g} MB" in text and f"{size / 2:.3g} MB" in text and "--max-exact-mb" in text
    assert lagrange_curve(pts, max_mb=size).coefficients == lagrange_curve(pts, max_mb=None).coefficients


def test_a_surface_over_the_limit_is_refused_with_the_figure():
    g = grid_from_table(range(40), range(3), [[i * k for k in range(3)] for i in range(40)])
    size = exact_size_mb(g.x, g.y, [v for row in g.z for v in row])
    with pytest.raises(LagsymError, match=r"40 x 3 nodes .*estimated .* MB.*--max-exact-mb"):
        lagrange_surface(g, max_mb=size * 0.9)
    assert lagrange_surface(g, max_mb=size * 1.1).exact_value(7, 2) == 14


def _write_curve(path, n):
    path.write_text("x,y\n" + "".join(f"{i / 10:.1f},{(i * 37) % 101 / 10}\n" for i in range(n)))


@pytest.mark.parametrize("command", ["curve", "check", "plot"])
def test_a_curve_of_1000_points_is_refused_at_once_by_the_command(tmp_path, command):
    # Before the estimate this ran over a minute and 3,000 points aborted inside GMP.
    f = tmp_path / "c.csv"
    _write_curve(f, 1000)
    out = tmp_path / "out.png"
    extra = f", '-o', {str(out)!r}" if command == "plot" else ""
    r = _child(f"import sys; from lagsym.cli import main; sys.exit(main([{command!r}, {str(f)!r}{extra}]))")
    assert r.returncode == 2, r.stderr
    assert r.stderr.count("\n") == 1 and "curve through 1000 points" in r.stderr, r.stderr
    assert f"limit of {MAX_EXACT_MB} MB" in r.stderr and "--max-exact-mb" in r.stderr
    figure = exact_size_mb([Fraction(i, 10) for i in range(1000)])
    assert f"{figure / 1000:.3g} GB" in r.stderr
    assert not out.exists()


def test_a_1000_by_3_grid_is_refused_and_the_option_raises_the_limit(tmp_path, run_cli):
    f = tmp_path / "g.csv"
    f.write_text("x,y,z\n" + "".join(f"{i / 10:.1f},{k},{(i * k) % 13}\n" for i in range(1000) for k in range(3)))
    r = _child(f"import sys; from lagsym.cli import main; sys.exit(main(['equation', {str(f)!r}]))")
    assert r.returncode == 2 and "1000 x 3 nodes" in r.stderr and "GB" in r.stderr, r.stderr
    small = tmp_path / "s.csv"
    small.write_text("x,y,z\n" + "".join(f"{i},{k},{i + k}\n" for i in range(20) for k in range(3)))
    status, _, err = run_cli("equation", small, "--max-exact-mb", "0.001")
    assert status == 2 and "20 x 3 nodes" in err and "limit of 0.001 MB" in err
    status, out, _ = run_cli("equation", small, "--max-exact-mb", "1")
    assert status == 0 and "x + y" in out.replace("y + x", "x + y")


def _chebyshev_by_solving(nodes):
    """The power-to-Chebyshev matrix by an exact solve of the T_k's power coefficients (the definition)."""
    n = len(nodes)
    offset, scale, _ = chebyshev_transform(nodes)
    o, h = Fraction(offset), Fraction(scale)
    shift = flint.fmpq_mat(n, n, [_fmpq(comb(q, p) * o ** (q - p) * h**p) if q >= p else 0
                                  for p in range(n) for q in range(n)])
    rows = [[1] + [0] * (n - 1), [0, 1] + [0] * (n - 2)][:n]
    for k in range(2, n):
        rows.append([2 * (rows[k - 1][p - 1] if p else 0) - rows[k - 2][p] for p in range(n)])
    cheb = flint.fmpq_mat(n, n, [rows[k][p] for p in range(n) for k in range(n)])
    return cheb.solve(shift)


def _fmpq(v: Fraction):
    return flint.fmpq(v.numerator, v.denominator)


@pytest.mark.parametrize("nodes", NODE_SETS[:4] + [[Fraction(0)], [Fraction(1), Fraction(3)]])
def test_the_chebyshev_change_of_basis_is_the_solved_one(nodes):
    assert chebyshev_transform(nodes)[2] == _chebyshev_by_solving(nodes)


@pytest.mark.slow
def test_the_change_of_basis_of_100_decimal_nodes_takes_no_minute():
    # 100 nodes with four decimals: over a minute by a general exact solve (and 'check' or 'sample'
    # on a 100 x 100 grid of such nodes over two minutes); the closed form takes under a second.
    code = ("from fractions import Fraction; from lagsym.evaluate import chebyshev_transform; "
            "chebyshev_transform([Fraction(13700 * i + 130 * i * i, 10000) for i in range(100)]); print('done')")
    r = _child(code, timeout=20)
    assert r.returncode == 0 and r.stdout.strip() == "done", r.stderr


def test_the_docs_quote_the_limit_and_the_figures_in_force():
    from pathlib import Path

    docs = Path(__file__).resolve().parent.parent / "docs"
    cli, formats = (docs / "cli.md").read_text(), (docs / "formats.md").read_text()
    curve = [Fraction(i, 10) for i in range(1000)]
    figures = [f"{exact_size_mb(curve) / 1000:.2g} GB", f"{exact_size_mb(curve[:500]):.3g} MB"]
    assert figures == ["2.7 GB", "306 MB"]
    assert f"`--max-exact-mb` ({MAX_EXACT_MB} MB)" in cli and f"at most {MAX_EXACT_MB} MB (`--max-exact-mb`)" in formats
    assert "points 0.1 apart: 2.7 GB; of 500 points: 306 MB" in cli.replace("\n", " ")
    assert "a curve of 1000 points 0.1 apart (2.7 GB)" in formats
    assert f"`--max-exact-s` ({MAX_EXACT_S:g} s)" in cli.replace("\n", " ")
    assert f"to end more than {MAX_EXACT_S:g} s after the command began (`--max-exact-s`" in formats


def test_a_power_of_powers_in_a_formula_is_refused_with_its_size_before_it_is_computed(tmp_path):
    # Before, exact_value and 'plot --show growth' never ended on this formula.
    text = "((((x+1e300)**64)**64)**64)**64"
    inner = Fraction(10**300 + 1) ** 64  # the first power, computed here; the second would be 64 times its bits
    bits = (inner.numerator.bit_length() + inner.denominator.bit_length()) * 64
    r = _child(f"from lagsym.formula import parse_formula; parse_formula({text!r}).exact_value(0, 0)", timeout=20)
    assert r.returncode == 1 and f"about {bits:,} bits" in r.stderr and "limit of 1,000,000" in r.stderr, r.stderr
    points = tmp_path / "p.csv"
    points.write_text("x,y,z\n" + "".join(f"{i},{k},{i * k}\n" for i in range(3) for k in range(3)))
    image = tmp_path / "g.png"
    r = _child("import sys; from lagsym.cli import main; "
               f"sys.exit(main(['plot', {str(points)!r}, '--show', 'growth', {text!r}, '-o', {str(image)!r}]))")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and f"about {bits:,} bits" in r.stderr, r.stderr
    assert not image.exists()


def test_a_power_within_the_limit_is_exact_and_the_limit_is_the_callers():
    from lagsym.formula import FormulaError, parse_formula

    f = parse_formula("(x + 1/3)**64")
    assert f.exact_value(1, 0) == Fraction(4, 3) ** 64
    bits = ((4).bit_length() + (3).bit_length()) * 64
    with pytest.raises(FormulaError, match=rf"about {bits} bits, more than the limit of 100 \(max_bits=\)"):
        f.exact_value(1, 0, max_bits=100)


def test_the_formula_limit_docs_formats_quotes_is_in_force():
    from pathlib import Path

    from lagsym.formula import MAX_EXACT_BITS, MAX_EXACT_EXPONENT

    formats = (Path(__file__).resolve().parent.parent / "docs" / "formats.md").read_text()
    assert f"integer powers within +-{MAX_EXACT_EXPONENT} and no power of more than {MAX_EXACT_BITS} bits" in formats


ARC = "G02 X30. Y30. I80000. J0.\n"  # most of a circle of 80 m radius: about 145,000 pieces


@pytest.mark.slow
def test_a_program_of_long_arcs_is_refused_as_it_is_read_with_the_count(tmp_path, run_cli):
    # Before, 300 such lines (7 KB) exhausted memory in verify (MemoryError, exit 70).
    from lagsym.gcode import parse_moves

    head = "G21 G90\nG00 X0 Y0 Z60\n"
    total = len(parse_moves(head + ARC + "M30\n", max_points=None).points_mm)
    program = tmp_path / "arcs.nc"
    program.write_text(head + ARC + "M30\n")
    points = tmp_path / "p.csv"
    points.write_text("x,y,z\n" + "".join(f"{i * 20},{k * 20},{i + k}\n" for i in range(3) for k in range(3)))
    status, _, err = run_cli("verify", points, program, "--max-moves", total - 1)
    assert status == 2 and err.count("\n") == 1, err
    assert f"line 3: the moves so far make {total:,} points" in err and f"limit of {total - 1:,}" in err
    assert "--max-moves" in err
    program.write_text(head + ARC * 300 + "M30\n")
    r = _child(f"import sys; from lagsym.cli import main; sys.exit(main(['verify', {str(points)!r}, {str(program)!r}]))")
    assert r.returncode == 2 and "more than the limit of 2,000,000; raise the limit (--max-moves)" in r.stderr, r.stderr


def test_the_move_limit_docs_cli_quotes_is_in_force():
    from pathlib import Path

    from lagsym.gcode.moves import MAX_MOVE_POINTS

    cli = (Path(__file__).resolve().parent.parent / "docs" / "cli.md").read_text().replace("\n", " ")
    assert f"`--max-moves` ({MAX_MOVE_POINTS:.0e} points".replace("e+0", "e") in cli


def test_a_program_of_too_many_lines_is_refused_before_it_is_read(tmp_path, run_cli):
    # Before, 60 MB of '#100=[#100+1.]' ran without end and a 20 MB program exhausted memory.
    from lagsym.simulate import MAX_PROGRAM_LINES

    body = "#100=[#100+1.]\n"
    program = tmp_path / "p.nc"
    program.write_text("%\nO1000\n#100=0.\n" + body * 40 + "M30\n%\n")
    lines = program.read_text().count("\n") + 1
    status, _, err = run_cli("simulate", program, "--max-lines", lines - 1)
    assert status == 2 and err.count("\n") == 1, err
    assert f"p.nc: {lines:,} lines, more than the limit of {lines - 1:,}" in err and "--max-lines" in err
    status, out, err = run_cli("simulate", program, "--max-lines", lines)
    assert status == 0 and f"{40 + 2} blocks executed" in err, err
    program.write_text("%\nO1000\n#100=0.\n" + body * (MAX_PROGRAM_LINES * 3) + "M30\n%\n")
    r = _child(f"import sys; from lagsym.cli import main; sys.exit(main(['simulate', {str(program)!r}]))")
    lines = MAX_PROGRAM_LINES * 3 + 6
    assert r.returncode == 2 and f"{lines:,} lines, more than the limit of {MAX_PROGRAM_LINES:,}" in r.stderr, r.stderr


def test_the_line_limit_the_docs_quote_is_in_force():
    from pathlib import Path

    from lagsym.simulate import MAX_PROGRAM_LINES

    docs = Path(__file__).resolve().parent.parent / "docs"
    cli = (docs / "cli.md").read_text().replace("\n", " ")
    assert f"`--max-lines` ({MAX_PROGRAM_LINES}) lines" in cli
    assert f"at most {MAX_PROGRAM_LINES} lines (`--max-lines`)" in (docs / "formats.md").read_text()


def test_a_job_on_too_large_a_grid_names_the_option_job_has(tmp_path, run_cli):
    points = tmp_path / "p.csv"
    points.write_text("x,y,z\n" + "".join(f"{i},{k},{(i + k) % 3}\n" for i in range(30) for k in range(3)))
    job = tmp_path / "j.toml"
    job.write_text(f'points = "{points}"\ndialect = "linuxcnc"\nsafe_z = 90\n\n[stock]\ntop_above = 2\n\n[tools.ball6]\nnumber = 2\n'
                   'shape = "ball"\ndiameter = 6\n\n[[operations]]\nkind = "finish"\ntool = "ball6"\n')
    out = tmp_path / "j.nc"
    status, _, err = run_cli("job", job, "-o", out, "--max-exact-mb", "0.001", "--accept-conditioning")
    assert status == 2 and "30 x 3 nodes" in err and "limit of 0.001 MB" in err and "--max-exact-mb" in err, err
    assert not out.exists()


@pytest.mark.slow
def test_sigterm_acts_within_seconds_during_the_exact_products(tmp_path):
    """A 60x60 grid of decimal nodes: its exact products took one FLINT call of several seconds, deaf to signals.

    Now they run a few rows at a time (``exactsize.stepped_product``): the
    signal sent while they run stops the command within a few seconds, with
    its one line, where it used to wait for the whole product.
    """
    import random
    import signal
    import time

    rng = random.Random(5)
    xs = [round(i * 0.337 + rng.random() * 0.1, 6) for i in range(60)]
    path = tmp_path / "g60.csv"
    path.write_text("x,y,z\n" + "\n".join(f"{a:.6f},{b * 1.0001:.6f},{rng.random():.4f}" for a in xs for b in xs))
    proc = subprocess.Popen([sys.executable, "-m", "lagsym", "check", str(path), "--max-exact-s", "1e6"],
                            stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    time.sleep(3.0)  # start-up and reading done; the exact products run for many seconds from here
    assert proc.poll() is None
    sent = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    waited = time.monotonic() - sent
    assert proc.returncode == 128 + signal.SIGTERM and "stopped by SIGTERM" in err
    assert waited < 3.0, f"SIGTERM acted after {waited:.1f} s"


@pytest.mark.slow
def test_a_tolerance_finer_than_the_written_positions_is_refused_at_once(tmp_path, run_cli):
    """A job's ``tolerance = 0.000001`` planned for minutes inside the workers (8.8 million samples, under the
    point limit); it cannot be held at 3 decimals anyway.  Every strategy refuses it in one line naming the figures,
    and more decimals let it through."""
    import time

    job = (EXAMPLES / "example-4-job.toml").read_text().replace("step = 0.2", "step = 0.2\ntolerance = 0.000002")
    (tmp_path / "paper-example-4.json").write_text((EXAMPLES / "paper-example-4.json").read_text())
    (tmp_path / "job.toml").write_text(job)
    started = time.monotonic()
    status, out, err = run_cli("job", str(tmp_path / "job.toml"), "-o", str(tmp_path / "job.ngc"))
    assert status == 2 and err.count("\n") == 1, err
    assert "job.toml: operations[1] (finish): a chordal tolerance of 2e-06 mm is finer than the 0.001 mm" in err
    assert time.monotonic() - started < 60 and not (tmp_path / "job.ngc").exists()
    points = str(EXAMPLES / "paper-example-4.json")
    for extra in ([], ["--strategy", "waterline", "--scallop", "0.05"]):
        status, _, err = run_cli("toolpath", points, "--tolerance", "0.0005", *extra, "-o", str(tmp_path / "a.nc"))
        assert status == 2 and "a chordal tolerance of 0.0005 mm is finer than the 0.001 mm" in err, err
    status, _, err = run_cli("toolpath", points, "--tolerance", "0.0005", "--decimals", "4", "--stepover", "0.5",
                             "-o", str(tmp_path / "a.nc"))
    assert status == 0, err


def _decimal_grid(n: int, seed: int) -> list[tuple[str, str, str]]:
    import random

    rng = random.Random(seed)
    xs = [f"{i}.{rng.randint(100, 999)}" for i in range(n)]
    ys = [f"{i}.{rng.randint(100, 999)}" for i in range(n)]
    return [(x, y, f"{rng.randint(0, 9999) / 1000:.3f}") for x in xs for y in ys]


@pytest.mark.slow
@pytest.mark.parametrize("command", ["check", "sample"])
def test_an_exact_computation_foreseen_past_the_time_limit_is_refused_a_few_seconds_in(tmp_path, command):
    """'check' and 'sample' on a 100x100 grid of nodes with three decimals: 35 KB, 32 MB estimated (under the size
    limit), over a minute of exact products.  Refused with the foreseen time, within seconds, nothing written."""
    import time

    path = tmp_path / "g100.csv"
    path.write_text("x,y,z\n" + "".join(",".join(row) + "\n" for row in _decimal_grid(100, 3)))
    extra = ["--nx", "20", "--ny", "20", "-o", str(tmp_path / "s.csv")] if command == "sample" else []
    started = time.monotonic()
    r = subprocess.run([sys.executable, "-m", "lagsym", command, str(path), *extra], capture_output=True, text=True,
                       timeout=120)
    waited = time.monotonic() - started
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    m = re.search(r"g100.csv: the exact surface through 100 x 100 nodes would take about (\d+) s here .* more than "
                  r"the limit of 15 s; .*--max-exact-s", r.stderr)
    assert m and int(m[1]) > MAX_EXACT_S, r.stderr  # a foreseen 15.3 s reads "16", not "15"
    assert waited < MAX_EXACT_S, f"refused after {waited:.1f} s"
    assert not (tmp_path / "s.csv").exists()


@pytest.mark.slow
@pytest.mark.slow
def test_the_bezier_form_for_cad_is_timed_like_the_polynomial():
    """export's change to the Bezier form (two exact products as long as the polynomial's) ran outside the clock:
    a 70 x 70 grid spent 11.6 s there after its polynomial, under any --max-exact-s."""
    from lagsym.cad.convert import bezier_patch

    with exact_time_limit(None):
        surface = lagrange_surface(_exact_grid(_decimal_grid(50, 3)))
    with exact_time_limit(0.001), pytest.raises(LagsymError, match=r"the exact Bezier form of the surface through "
                                                                   r"50 x 50 nodes would take about \d+ s"):
        bezier_patch(surface)


def test_the_time_limit_is_the_callers_in_python():
    grid = _exact_grid(_decimal_grid(70, 4))
    with exact_time_limit(1.0), pytest.raises(LagsymError, match=r"70 x 70 nodes would take about .* limit of 1 s"):
        lagrange_surface(grid)  # products of about 4 s each here: refused half a second into the first
    small = _exact_grid(_decimal_grid(4, 5))
    with exact_time_limit(None):
        assert lagrange_surface(small).coefficients == lagrange_surface(small).coefficients


def _exact_grid(rows):
    return grid_from_points([tuple(Fraction(v) for v in row) for row in rows])


@pytest.mark.slow
@pytest.mark.parametrize("command", ["compare", "simulate"])
def test_compare_and_simulate_take_the_time_limit_too(tmp_path, run_cli, command):
    """Both build the exact surface from a points file; the limit they are refused by is one they take."""
    path = tmp_path / "g70.csv"
    path.write_text("x,y,z\n" + "".join(",".join(row) + "\n" for row in _decimal_grid(70, 6)))
    program = tmp_path / "p.nc"
    program.write_text("%\nO1000\nG21 G90\nG01 X1. Y1. Z1. F100.\nM30\n%\n")
    args = [str(path)] if command == "compare" else [str(program), "--surface", str(path)]
    status, _, err = run_cli(command, *args, "--max-exact-s", "0.5")
    assert status == 2 and "70 x 70 nodes would take about" in err and "limit of 0.5 s" in err, err
