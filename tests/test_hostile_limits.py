"""Hostile inputs refused at once, in one line, with the figure and what raises the limit.

Each case that ran away (minutes, gigabytes) or was taken wrongly before its
guard existed; the slow ones run in a child process within a memory limit and a
generous timeout, so that this suite itself never runs away.
"""

from __future__ import annotations

import io
import json
import random
import re
import resource
import subprocess
import sys

import pytest

from lagsym.cli import main
from lagsym.io import MAX_FILE_POINTS, file_points_limit, read_scattered_points
from lagsym.surfaces.piecewise import MAX_PIECES

from conftest import ROOT

MEMORY = 2 * 1024**3


def _limited():
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))


def _lagsym(*argv: str, timeout: float = 30) -> subprocess.CompletedProcess:
    """The command run in a fresh interpreter within 2 GB and ``timeout`` seconds."""
    try:
        return subprocess.run([sys.executable, "-m", "lagsym", *argv], capture_output=True, text=True,
                              timeout=timeout, preexec_fn=_limited)
    except subprocess.TimeoutExpired:
        pytest.fail(f"still running after {timeout} s: lagsym {' '.join(argv)}")


def _run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    return main(list(argv), out, err), out.getvalue(), err.getvalue()


def _refused(rc: int, err: str, *needles: str) -> str:
    assert rc == 2, err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for needle in needles:
        assert needle in lines[0], lines[0]
    return lines[0]


# --- F5: a points file of more points than any command can use ------------------------------------------------------

def _big_table(path, mb: int = 60) -> int:
    """A 60 MB table of x,y,z lines as a scanner might write, and how many points it holds."""
    rng = random.Random(5)
    lines = [f"{i % 1000}.123456789,{i // 1000}.123456789,{rng.random():.12f}\n" for i in range(20_000)]
    block = "".join(lines)
    count, size = 0, 0
    with open(path, "w") as fh:
        fh.write("x,y,z\n")
        while size < mb * 2**20:
            fh.write(block)
            size += len(block)
            count += len(lines)
    return count


@pytest.fixture(scope="module")
def big60(tmp_path_factory):
    folder = tmp_path_factory.mktemp("big")
    csv = folder / "big60.csv"
    count = _big_table(csv)
    text = csv.read_text().splitlines()[1:]
    js = folder / "big60.json"
    js.write_text("[" + ",".join(f"[{line}]" for line in text) + "]")
    return csv, js, count


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["csv", "json"])
@pytest.mark.parametrize("command", [["equation"], ["check"], ["fit", "-o", "OUT"], ["piecewise", "-o", "OUT"],
                                     ["curve"], ["toolpath"]])
def test_a_60_mb_points_file_is_refused_before_it_is_read(big60, tmp_path, command, kind):
    path = big60[0] if kind == "csv" else big60[1]
    argv = [a if a != "OUT" else str(tmp_path / "out.json") for a in command]
    p = _lagsym(argv[0], str(path), *argv[1:])
    line = _refused(p.returncode, p.stderr, path.name, f"more than the limit of {MAX_FILE_POINTS:,} points",
                    "--max-file-points")
    assert re.search(r"about [\d,]+ points", line)
    assert not (tmp_path / "out.json").exists()


def test_the_estimate_counts_the_points_of_a_table_and_of_json(big60):
    from lagsym.io.files import estimate_points

    csv, js, count = big60
    assert count <= estimate_points(csv.read_text()) <= count + 1
    assert count <= estimate_points(js.read_text()) <= count + 1
    assert estimate_points('{"x": [0, 1, 2], "y": [0, 1, 2], "z": [[0, 1, 2], [1, 2, 3], [2, 3, 4]]}') >= 4


def test_the_option_and_the_context_raise_the_limit(tmp_path):
    path = tmp_path / "pts.csv"
    path.write_text("x,y,z\n" + "".join(f"{i},{k},{i * k}\n" for i in range(3) for k in range(3)))
    rc, out, err = _run("equation", str(path), "--max-file-points", "5")
    _refused(rc, err, "pts.csv: about 10 points, more than the limit of 5 points", "--max-file-points")
    rc, out, err = _run("equation", str(path), "--max-file-points", "10")
    assert rc == 0, err
    with file_points_limit(5), pytest.raises(Exception, match="more than the limit of 5 points"):
        read_scattered_points(path)
    with file_points_limit(None):
        assert len(read_scattered_points(path).points) == 9


@pytest.mark.parametrize("command", ["read-probe", "fit"])
def test_probe_results_whose_header_states_more_nodes_than_the_limit_are_refused_at_once(tmp_path, command):
    """The header's node count was trusted: 'N 999999999999' made a list of every node it named as missing."""
    path = tmp_path / "results.txt"
    path.write_text("LAGSYM PROBE MM N 999999999999 R 1.0\nP 1 X 1.0 Y 1.0 Z 1.0 OK\nEND\n")
    done = _lagsym(command, str(path), timeout=30)
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert (f"results.txt: line 1: 999,999,999,999 points stated, more than the limit of {MAX_FILE_POINTS:,} points"
            in done.stderr and "--max-file-points" in done.stderr), done.stderr


def test_probe_results_are_counted_against_the_limit_and_their_missing_nodes_counted_not_listed(tmp_path):
    from lagsym.probe import read_results

    lines = "LAGSYM PROBE MM N 3 R 1.0\n" + "".join(f"P {n} X {n}.0 Y 1.0 Z 1.0 OK\n" for n in (1, 2, 3)) + "END\n"
    with file_points_limit(2), pytest.raises(Exception, match="about 5 points, more than the limit of 2 points"):
        read_results(lines, "r.txt")
    with file_points_limit(4), pytest.raises(Exception, match="r.txt: line 1: 10 points stated, more than the limit"):
        read_results("LAGSYM PROBE MM N 10 R 1.0\nP 1 X 1.0 Y 1.0 Z 1.0 OK\nEND\n", "r.txt")
    assert len(read_results(lines, "r.txt").points) == 3
    path = tmp_path / "r.txt"
    path.write_text("LAGSYM PROBE MM N 5000000 R 1.0\nP 1 X 1.0 Y 1.0 Z 1.0 OK\nEND\n")
    rc, out, err = _run("read-probe", str(path), "--max-file-points", "10000000")
    _refused(rc, err, "r.txt: node 2 and 4,999,998 more of 5,000,000 missing", "node 2")
    rc, out, err = _run("read-probe", str(path))
    _refused(rc, err, "r.txt: line 1: 5,000,000 points stated, more than the limit of 1,000,000", "--max-file-points")


@pytest.mark.slow
def test_a_fit_of_fifty_thousand_scattered_points_is_read(tmp_path):
    rng = random.Random(1)
    path = tmp_path / "scan.csv"
    path.write_text("x,y,z\n" + "".join(f"{rng.random() * 100:.4f},{rng.random() * 100:.4f},{rng.random():.4f}\n"
                                        for _ in range(50_000)))
    assert len(read_scattered_points(path).points) == 50_000


def test_the_docs_quote_the_points_limit_in_force():
    formats = " ".join((ROOT / "docs" / "formats.md").read_text().split())
    row = next(line for line in formats.split("| a points file |")[1:2])
    assert f"about {MAX_FILE_POINTS:,} points at most (`--max-file-points`" in row
    assert "a 60 MB table is refused at once" in row
    side = 501
    assert (side - 1) ** 2 == MAX_PIECES and side * side < MAX_FILE_POINTS / 2
    assert f"largest grid `lagsym piecewise` takes ({side} x {side})" in row
    assert f"(default {MAX_FILE_POINTS:,})" in (ROOT / "docs" / "cli.md").read_text()


# --- F6: TOML keys and table headers nested deep ---------------------------------------------------------------------

def _dnc_toml(tmp_path, extra: str = "") -> str:
    return (f'{extra}[[port]]\nname = "mill1"\ndevice = "/dev/ttyUSB0"\nprofile = "fanuc"\n'
            f'programs = "{tmp_path}"\nreceived = "{tmp_path}"\n')


DEEP = 100_000


@pytest.mark.parametrize("layout", ["dotted", "header", "quoted", "spaced"])
@pytest.mark.parametrize("command", ["dnc", "job", "verify"])
def test_a_toml_key_nested_deep_is_refused_before_it_is_read(tmp_path, command, layout):
    from lagsym.io.tomltext import MAX_TOML_DEPTH

    key = {"dotted": ".".join(["a"] * DEEP), "header": "[" + ".".join(["a"] * DEEP) + "]",
           "quoted": ".".join(['"a"'] * DEEP), "spaced": " . ".join(["a"] * DEEP)}[layout]
    path = tmp_path / "deep.toml"
    path.write_text('# a comment. with. dots\ntitle = "x.y.z"\n\n' + key + ("\n" if layout == "header" else " = 1\n"))
    argv = {"dnc": ["dnc", "serve", str(path), "--check"], "job": ["job", str(path), "-o", str(tmp_path / "o.nc")],
            "verify": ["verify", "--job", str(path), str(tmp_path / "none.nc")]}[command]
    p = _lagsym(*argv)
    _refused(p.returncode, p.stderr, "deep.toml: line 4:", f"{DEEP} levels deep", f"more than {MAX_TOML_DEPTH}")
    assert not (tmp_path / "o.nc").exists()


def test_the_toml_depth_check_reads_strings_comments_and_keys_as_toml_does(tmp_path):
    import tomllib

    from lagsym.errors import InputError
    from lagsym.io.tomltext import MAX_TOML_DEPTH, check_toml_depth

    deep = ".".join(["a"] * (MAX_TOML_DEPTH + 1))
    fine = ".".join(["a"] * MAX_TOML_DEPTH)
    accepted = [f'k = "{deep}"\n', f"# {deep}\n", f'k = """\n{deep}\n"""\n', f"k = '''{deep}'''\n",
                f'k = """x"" """""\nj = "{deep}"\n', f"k = '{deep}'\n", f"[{fine}]\n{fine} = 1.5\n",
                f'k = "\\\\"\nj = "{deep}"\n', "x = [" + ", ".join(["1.5"] * 100) + "]\n"]
    for text in accepted:
        tomllib.loads(text)  # each is TOML
        check_toml_depth(text, "t.toml", "a job file")
    refused = {f'k = """x""""\n{deep} = 1\n': 2, f"[{deep}]\n": 1, f"x = {{{deep} = 1}}\n": 1,
               f'b = 1\n\n{deep.replace("a", chr(34) + "a" + chr(34))} = 1\n': 3}
    for text, line in refused.items():
        tomllib.loads(text)  # TOML, only too deep
        with pytest.raises(InputError, match=rf"^t.toml: line {line}: not a job file: .* {MAX_TOML_DEPTH + 1} levels"):
            check_toml_depth(text, "t.toml", "a job file")


def test_the_docs_quote_the_toml_depth_in_force():
    from lagsym.io.tomltext import MAX_TOML_DEPTH

    formats = " ".join((ROOT / "docs" / "formats.md").read_text().split())
    assert formats.count(f"no dotted key or table header more than {MAX_TOML_DEPTH} levels deep") == 2


# --- F16: a boolean where the line takes a number --------------------------------------------------------------------

NUMERIC_LINE_SETTINGS = ["baud", "bytesize", "stopbits", "stall_timeout_s", "overrun_chars", "buffer_chars",
                         "memory_chars"]


@pytest.mark.parametrize("value", [True, False])
@pytest.mark.parametrize("name", NUMERIC_LINE_SETTINGS)
def test_a_boolean_is_no_line_setting_number(name, value):
    from lagsym.dnc import LineSettings
    from lagsym.errors import InputError

    with pytest.raises(InputError, match=rf" {str(value).lower()} is a boolean, not a number$"):
        LineSettings(**{name: value})


def test_stop_bits_true_in_a_dnc_configuration_is_refused(tmp_path):
    from lagsym.dnc import LineSettings

    assert LineSettings(stopbits=1).stopbits == 1.0 and LineSettings(stopbits=1.5).stopbits == 1.5
    for key in ("stopbits", "bytesize", "baud"):
        path = tmp_path / "dnc.toml"
        path.write_text(_dnc_toml(tmp_path) + f"\n[port.line]\n{key} = true\n")
        rc, out, err = _run("dnc", "serve", str(path), "--check")
        _refused(rc, err, "dnc.toml: port[0].line:", "true is a boolean, not a number")
    path.write_text(_dnc_toml(tmp_path) + "\n[port.line]\nstopbits = 1\n")
    assert _run("dnc", "serve", str(path), "--check")[0] == 0


def test_a_boolean_start_block_is_refused():
    from lagsym.dnc import LineSettings, parse_program
    from lagsym.dnc.transfer import transfer_segments
    from lagsym.errors import InputError

    with pytest.raises(InputError, match="--start-block True must be a block number"):
        list(transfer_segments(parse_program("O1\nM30"), LineSettings(), start_block=True))


# --- F14: nodes closer than floating point can tell apart ----------------------------------------------------------

NEAR = "1.0000000000000000000001"


@pytest.mark.parametrize("layout", ["curve", "surface", "curve-middle", "surface-middle"])
def test_nodes_closer_than_floating_point_are_refused_by_name_for_a_curve_and_a_surface(tmp_path, layout):
    xs = ["1", NEAR, "2"] if "middle" not in layout else ["0", "1", NEAR, "2"]
    path = tmp_path / "close.json"
    if layout.startswith("curve"):
        path.write_text(json.dumps([[x, str(k)] for k, x in enumerate(xs)]))
    else:
        path.write_text(json.dumps([[x, y, str(i + k)] for i, x in enumerate(xs) for k, y in enumerate("012")]))
    rc, out, err = _run("check", str(path))
    span = "1" if "middle" not in layout else "2"
    line = _refused(rc, err, f"lagsym: error: {path}: x nodes 1 and {NEAR} are closer than floating point can tell "
                             f"apart over their span of {span} (a gap of")
    assert "are equal than" not in line and out == ""


def test_nodes_far_enough_apart_are_measured_and_the_docs_quote_the_resolution():
    from fractions import Fraction

    from lagsym.conditioning import NODE_RESOLUTION, lebesgue_maximum
    from lagsym.errors import ConditioningError

    assert NODE_RESOLUTION == Fraction(1, 2**47)
    step = NODE_RESOLUTION * 2
    for nodes in ([0, step, 1], [0, Fraction(1, 2), Fraction(1, 2) + step, 1], [0, 1 - step, 1]):
        value, _ = lebesgue_maximum(nodes)
        assert 1e13 < value < 1e15
    with pytest.raises(ConditioningError, match=r"nodes 0 and 0\.00000000000000710542735760100185871124267578125 are closer"):
        lebesgue_maximum([0, NODE_RESOLUTION, 1])
    assert lebesgue_maximum([1, Fraction(NEAR)])[0] == pytest.approx(1.0, rel=1e-12)  # two nodes: always 1
    theory = " ".join((ROOT / "docs" / "theory.md").read_text().split())
    assert (f"closer than 2^-47 of the span of their axis ({float(NODE_RESOLUTION):.2g} of it, "
            f"{NODE_RESOLUTION * 2**53} units of rounding)") in theory


# --- F17: an exact basis on many nodes ------------------------------------------------------------------------------

@pytest.mark.parametrize("call", ["lagrange_basis", "basis_coefficients"])
def test_an_exact_basis_on_many_nodes_is_refused_before_the_work(call):
    from lagsym.exactsize import MAX_EXACT_MB, exact_size_mb

    size = exact_size_mb(range(3000))
    code = (f"import lagsym.lagrange as L\ntry:\n    L.{call}(range(3000))\nexcept L.InputError as e:\n"
            f"    print(e)\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=30, preexec_fn=_limited)
    assert p.returncode == 0, p.stderr
    assert p.stdout == (f"the exact basis on 3000 nodes would take an estimated {size / 1000:.3g} GB of exact "
                        f"rationals, more than the limit of {MAX_EXACT_MB} MB; use fewer points (a large grid: "
                        f"'lagsym piecewise') or raise the limit (--max-exact-mb, max_mb= in Python)\n")
    formats = " ".join((ROOT / "docs" / "equations.md").read_text().split())
    assert f"refuse one above `max_mb` ({MAX_EXACT_MB} MB," in formats
    assert f"is refused at once (an estimated {size / 1000:.3g} GB)" in formats


def test_a_basis_within_the_limit_is_made_and_the_limit_is_an_argument():
    from fractions import Fraction

    from lagsym.errors import InputError
    from lagsym.lagrange import basis_coefficients, lagrange_basis, lagrange_curve
    from lagsym.grid import curve_from_points

    assert [p.as_expr() for p in lagrange_basis([1, 2, 3])][1].expand() == lagrange_basis([1, 2, 3])[1].as_expr()
    assert basis_coefficients([1, 2, 3], max_mb=None)[0] == (Fraction(3), Fraction(-5, 2), Fraction(1, 2))
    with pytest.raises(InputError, match="basis on 40 nodes would take an estimated"):
        lagrange_basis(range(40), max_mb=0.001)
    curve = lagrange_curve(curve_from_points([(k, k * k) for k in range(40)]), max_mb=None)
    assert len(curve.basis) == 40  # the curve's own basis: its size was checked with the curve


# --- F18: variable names that are SymPy's own -----------------------------------------------------------------------

SYMPY_NAMES = ["I", "E", "pi", "oo", "nan", "zoo", "sin", "S", "N", "Q", "O", "beta", "gamma", "Symbol", "exp"]
GRID = [(1, 2, 7), (1, 3, 10), (3, 2, 15), (3, 3, 18)]


@pytest.mark.parametrize("name", SYMPY_NAMES)
@pytest.mark.parametrize("axis", ["x", "y"])
def test_a_sympy_name_is_refused_as_a_variable(name, axis):
    import sympy

    from lagsym import curve_from_points, grid_from_points, lagrange_curve, lagrange_surface
    from lagsym.errors import InputError

    message = rf"^{axis} name '{name}' is one of SymPy's own names: sympify reads it back as SymPy's {name}, "
    with pytest.raises(InputError, match=message):
        lagrange_surface(grid_from_points(GRID), **{axis: name})
    with pytest.raises(InputError, match=message):
        lagrange_surface(grid_from_points(GRID), **{axis: sympy.Symbol(name)})
    if axis == "x":
        with pytest.raises(InputError, match=message):
            lagrange_curve(curve_from_points([(0, 1), (1, 2)]), x=name)


@pytest.mark.parametrize("names", [("x", "y"), ("u", "v"), ("theta", "phi"), ("alpha", "x1"), ("lambda_", "t"),
                                   ("X", "Y"), ("a", "b")])
def test_the_sympy_format_reads_back_with_every_allowed_name(names):
    import sympy

    from lagsym import grid_from_points, lagrange_surface
    from lagsym.equation import render

    s = lagrange_surface(grid_from_points(GRID), x=names[0], y=names[1])
    back = sympy.sympify(render(s, "sympy").split(" = ", 1)[1])
    assert back.free_symbols == {sympy.Symbol(n) for n in names}
    assert sympy.expand(back - s.expr) == 0


def test_the_letters_known_as_sympy_names_are_those_sympify_keeps():
    import string

    import sympy

    from lagsym.values import SYMPY_LETTERS

    def reads_back(name):
        try:
            value = sympy.sympify(name)
        except Exception:
            return False
        return isinstance(value, sympy.Symbol) and value.name == name

    assert SYMPY_LETTERS == {c for c in string.ascii_letters if not reads_back(c)}


def test_a_one_letter_name_is_checked_without_sympy():
    code = ("import sys\nfrom lagsym.values import check_name\ncheck_name('u')\n"
            "try:\n    check_name('I')\nexcept ValueError as e:\n    print(e)\nprint('sympy' in sys.modules)\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert p.stdout.splitlines()[-1] == "False", p.stdout + p.stderr
    assert "variable name 'I' is one of SymPy's own names" in p.stdout


def test_the_docs_name_the_refused_sympy_names():
    equations = " ".join((ROOT / "docs" / "equations.md").read_text().split())
    listed = "(`I`, `E`, `N`, `O`, `Q`, `S`, `pi`, `oo`, `nan`, `zoo`, `sin`, `beta`, `gamma`, ...)"
    assert listed in equations
    from lagsym.errors import InputError
    from lagsym.values import check_name

    for name in re.findall(r"`(\w+)`", listed):
        with pytest.raises(InputError):
            check_name(name)
