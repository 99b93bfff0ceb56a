"""Hostile input, second round: code from names, atomic writes, messages that name the value."""

from __future__ import annotations

import dataclasses
import os

import pytest
import sympy

import lagsym
import lagsym.equation
from lagsym import LagsymError, grid_from_points, lagrange_surface, lagrange_curve, curve_from_points
from lagsym.lagrange import LagrangeSurface, lagrange_basis

GRID = [(0, 0, 1), (0, 1, 2), (1, 0, 3), (1, 1, 5), (2, 0, 1), (2, 1, 7)]

EXPLOITS = [
    "__import__('os').system('touch PWNED')",
    "x+__import__('os').system('touch PWNED')",
    "lambda",
    "x y",
    "x\ny",
    "_x",
    "",
    "1x",
    "é",
    "x" * 65,
]


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    yield tmp_path
    assert not (tmp_path / "PWNED").exists()
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("name", EXPLOITS)
def test_surface_names_are_refused_at_construction(in_tmp, name):
    g = grid_from_points(GRID)
    for kwargs in ({"x": name}, {"y": name}, {"x": sympy.Symbol(name) if name else name}):
        with pytest.raises(LagsymError, match="not a plain identifier") as info:
            s = lagrange_surface(g, **kwargs)
            # Were it accepted, these are the routes by which a name became code.
            lagsym.lambdify_surface(s)(1.0, 2.0)
            lagsym.equation.render(s, "latex", digits=3)
            lagsym.equation.render(s, "python")
        assert repr(name)[:40] in str(info.value)


@pytest.mark.parametrize("name", EXPLOITS[:3])
def test_curve_basis_and_replace_refuse_the_names(in_tmp, name):
    pts = curve_from_points([(1, 1), (2, 3), (3, 1)])
    with pytest.raises(LagsymError, match="not a plain identifier"):
        lagrange_curve(pts, x=name)
    with pytest.raises(LagsymError, match="not a plain identifier"):
        lagrange_basis([1, 2, 3], name)
    s = lagrange_surface(grid_from_points(GRID))
    with pytest.raises(LagsymError, match="not a plain identifier"):
        dataclasses.replace(s, variables=("x", name))
    with pytest.raises(LagsymError, match="not a plain identifier"):
        LagrangeSurface(grid=s.grid, coefficients=s.coefficients, variables=(name, "y"))


def test_good_names_still_evaluate_as_the_exact_polynomial(in_tmp):
    g = grid_from_points(GRID)
    u, t = sympy.Symbol("u"), sympy.Symbol("t", real=True)
    for x, y in (("u", "v"), (u, "w2"), (t, "y")):
        s = lagrange_surface(g, x=x, y=y)
        f = lagsym.lambdify_surface(s)
        for px, py, pz in GRID:
            assert f(float(px), float(py)) == pz
        # The Python text is code: run it in an empty namespace and compare with the points.
        ns: dict = {}
        exec(lagsym.equation.render(s, "python"), ns)  # noqa: S102 - the text under test
        for px, py, pz in GRID:
            assert ns["F"](px, py) == pz


# ---------------------------------------------------------------------------------------------------------------
# Writes: always a temporary beside the target and a rename; an output that is an input refused before any work.

from conftest import EXAMPLES  # noqa: E402

from lagsym.errors import OutputError  # noqa: E402
from lagsym.io import write_text  # noqa: E402

EXAMPLE1 = EXAMPLES / "paper-example-1.json"
EQUATION = "z = x**2 + 3*y\n"


def test_an_output_that_is_an_input_is_refused(run_cli, tmp_path):
    p = tmp_path / "p.json"
    p.write_bytes(EXAMPLE1.read_bytes())
    status, out, err = run_cli("equation", p, "-o", p)
    assert (status, out) == (2, "") and err == f"lagsym: error: {p}: is also an input; write the result to another file\n"
    assert p.read_bytes() == EXAMPLE1.read_bytes()
    nc = tmp_path / "p.nc"
    nc.write_text("G0 X1.\n")
    other = tmp_path / "other.nc"
    os.link(nc, other)  # the same file by another name: same device and inode
    status, out, err = run_cli("simulate", nc, "-o", other)
    assert status == 2 and err.count("\n") == 1 and "is also an input" in err
    assert nc.read_text() == "G0 X1.\n"


def test_a_dev_shm_file_is_a_file_not_a_stream(run_cli):
    # A path under /dev that is a regular file is replaced by a rename: it gets a new inode.
    folder = "/dev/shm" if os.path.isdir("/dev/shm") else None
    if folder is None:
        pytest.skip("no /dev/shm here")
    import tempfile

    with tempfile.TemporaryDirectory(dir=folder) as d:
        target = os.path.join(d, "x.csv")
        with open(target, "w") as fh:
            fh.write("old\n")
        before = os.stat(target).st_ino
        assert run_cli("equation", EXAMPLE1, "-o", target)[0] == 0
        assert os.stat(target).st_ino != before
        assert open(target).read() == EQUATION
        assert os.listdir(d) == ["x.csv"]


def test_a_legal_long_name_is_written_and_a_name_over_the_limit_refused(run_cli, tmp_path):
    name_max = os.pathconf(tmp_path, "PC_NAME_MAX")
    ok = tmp_path / ("a" * (name_max - 4) + ".txt")
    assert run_cli("equation", EXAMPLE1, "-o", ok)[0] == 0 and ok.read_text() == EQUATION
    too_long = tmp_path / ("b" * (name_max + 1))
    status, out, err = run_cli("equation", EXAMPLE1, "-o", too_long)
    assert status == 2 and err.count("\n") == 1 and "longer than the system allows" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == [ok.name]


def test_a_symlink_loop_and_a_newline_in_a_name_are_one_line(run_cli, tmp_path):
    (tmp_path / "l1").symlink_to(tmp_path / "l2")
    (tmp_path / "l2").symlink_to(tmp_path / "l1")
    status, out, err = run_cli("equation", EXAMPLE1, "-o", tmp_path / "l1")
    assert status == 2 and err.count("\n") == 1 and "symbolic links" in err
    status, out, err = run_cli("equation", tmp_path / "no\nsuch.json")
    assert status == 2 and err.count("\n") == 1 and "no\\nsuch.json" in err


def test_a_full_disk_message_says_it_once(tmp_path, monkeypatch):
    import errno

    def full(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    target = tmp_path / "out.txt"
    target.write_text("old\n")
    monkeypatch.setattr(os, "fsync", full)
    with pytest.raises(OutputError) as info:
        write_text(target, "new\n")
    assert str(info.value) == f"{target}: cannot write (no space left on the device); any earlier file there is untouched"
    assert target.read_text() == "old\n" and [p.name for p in tmp_path.iterdir()] == ["out.txt"]


# ---------------------------------------------------------------------------------------------------------------
# Wrong answers: nothing reported as ok that is not a number.

def test_nearly_equal_nodes_give_the_true_lebesgue_constant_or_a_refusal(run_cli, tmp_path):
    import json

    near = tmp_path / "near.csv"
    near.write_text("x,y,z\n1,0,1\n1,1,2\n1.0000000000000000000001,0,3\n1.0000000000000000000001,1,4\n")
    status, out, err = run_cli("check", near, "--format", "json")
    assert status == 0, err
    # Two distinct nodes: L_0 + L_1 = 1 on their span (the two lines sum to the constant 1), whatever the gap.
    found = {f["name"]: f["value"] for f in json.loads(out, parse_constant=lambda c: pytest.fail(c))["findings"]}
    assert found["lebesgue_x"] == pytest.approx(1.0, rel=1e-12) and found["lebesgue_y"] == pytest.approx(1.0)
    three = tmp_path / "three.csv"
    three.write_text("x,y,z\n0,0,1\n0,1,2\n1,0,3\n1,1,4\n1.0000000000000000000001,0,3\n1.0000000000000000000001,1,4\n")
    status, out, err = run_cli("check", three)
    assert status == 2 and out == "" and err.count("\n") == 1
    assert "nodes 1 and 1.0000000000000000000001" in err


def _job_data(title, dialect="fanuc"):
    return {"points": "p.csv", "title": title, "dialect": dialect, "stock": {"block": [0, 10, 0, 10], "top": 5},
            "tools": {"b": {"number": 1, "shape": "ball", "diameter": 6}},
            "operations": [{"kind": "finish", "tool": "b"}]}


def test_a_job_title_must_fit_one_block_of_the_control():
    from pathlib import Path

    from lagsym.job.spec import parse_job

    # A Fanuc reads 128 characters a block; the header block is "O1000 (" + title + ")".
    fits = "A" * (128 - len("O1000 ()"))
    assert parse_job(_job_data(fits), "j.toml", Path(".")).title == fits
    for title in (fits + "A", "B" * 100_000):
        with pytest.raises(LagsymError, match=f"title of {len(title):,} characters") as info:
            parse_job(_job_data(title), "j.toml", Path("."))
        assert "128" in str(info.value)


def _hollerith_strings(text: str) -> list[str]:
    """The Hollerith strings of an IGES global section, read by their counts (an independent reader)."""
    out, i = [], 0
    while i < len(text):
        j = i
        while j < len(text) and text[j].isdigit():
            j += 1
        if j > i and j < len(text) and text[j] == "H":
            n = int(text[i:j])
            out.append(text[j + 1:j + 1 + n])
            i = j + 1 + n + 1  # past the string and its delimiter
        else:
            k = min((p for p in (text.find(",", i), text.find(";", i)) if p >= 0), default=len(text))
            i = k + 1
    return out


def test_an_iges_file_named_with_accents_stays_ascii_with_true_counts(run_cli, tmp_path):
    target = tmp_path / "pièce-à-façon.igs"
    status, out, err = run_cli("export", EXAMPLE1, "-o", target)
    assert status == 0, err
    raw = target.read_bytes()
    assert raw.isascii()
    lines = raw.decode("ascii").splitlines()
    assert all(len(line) == 80 for line in lines)
    glob = "".join(line[:72] for line in lines if line[72] == "G")
    strings = _hollerith_strings(glob)
    assert strings[:4] == [",", ";", "piece-a-facon", "piece-a-facon.igs"]


@pytest.mark.parametrize("dialect, limit", [("fanuc", 128), ("haas", 128), ("linuxcnc", 255)])
def test_the_title_limits_docs_formats_quotes(dialect, limit):
    from pathlib import Path

    from lagsym.job.spec import parse_job

    assert "128 characters on a Fanuc or Haas, 255 on LinuxCNC" in (Path(__file__).parent.parent / "docs" /
                                                                      "formats.md").read_text()
    with pytest.raises(LagsymError, match=f"more than the {limit} a {dialect} control"):
        parse_job(_job_data("T" * limit, dialect), "j.toml", Path("."))
    assert parse_job(_job_data("T" * (limit - 12), dialect), "j.toml", Path(".")).dialect == dialect


# ---------------------------------------------------------------------------------------------------------------
# Internal errors: each of these was exit 70 with a Python error; now one line and exit 0-3.

def _one_line(status, err, statuses=(2,)):
    assert status in statuses, err
    assert err.count("\n") <= 1 and "internal error" not in err and "Traceback" not in err, err


def test_a_run_of_249_signs_is_read_as_their_parity(run_cli, tmp_path):
    prog = tmp_path / "signs.ngc"
    lines = ["#2=3."] + [f"#1={'-' * k}#2\nG1 X#1 F100." for k in (248, 249)] + ["#1=-+-+-#2\nG1 X#1", "M2"]
    prog.write_text("\n".join(lines) + "\n")
    status, out, err = run_cli("simulate", prog, "--dialect", "linuxcnc")
    assert status == 0, err
    xs = [float(row.split(",")[2]) for row in out.splitlines()[1:]]
    assert xs == [(-1) ** k * 3.0 for k in (248, 249, 3)]


def test_arcs_and_ends_beyond_any_travel_are_one_line(run_cli, tmp_path):
    head = "G21 G90\nG0 X0. Y0. Z5.\nG1 Z-1. F100.\n"
    cases = {"huge-ij.nc": "G02 X30. Y30. I1000000000000. J0.\n",
             "long-end.nc": "G02 X" + "1" * 400 + ". Y30. I10. J0.\n",
             "long-line.nc": "G01 X" + "1" * 400 + ".\n"}
    for name, block in cases.items():
        p = tmp_path / name
        p.write_text(head + block + "M30\n")
        status, out, err = run_cli("verify", EXAMPLE1, p, "--cell", "0.1")
        _one_line(status, err, (0, 1, 2))
        if name != "huge-ij.nc":
            assert status == 2 and "beyond any machine's travel" in err


def test_toml_nested_deep_and_a_nul_in_the_points_path_are_one_line(run_cli, tmp_path):
    deep = tmp_path / "deep.toml"
    deep.write_text("a=" + "[" * 100_000 + "]" * 100_000 + "\n")
    status, out, err = run_cli("job", deep)
    _one_line(status, err)
    assert "nested too deep" in err
    status, out, err = run_cli("dnc", "serve", deep, "--check")
    _one_line(status, err)
    nul = tmp_path / "nul.toml"
    nul.write_text('points = "a\\u0000b.csv"\ntitle = "T"\n[stock]\ntop = 5\nmargin = 0\n'
                   '[tools.b]\nnumber = 1\nshape = "ball"\ndiameter = 6\n[[operations]]\nkind = "finish"\ntool = "b"\n')
    status, out, err = run_cli("job", nul)
    _one_line(status, err)
    assert "NUL" in err


def test_a_formula_infinite_at_a_node_is_refused_in_the_growth_plot():
    from lagsym.formula import parse_formula
    from lagsym.plot.growth import degree_growth

    with pytest.raises(LagsymError, match="division by zero"):
        degree_growth(parse_formula("1/(x-x)"), (0, 1, 0, 1), degrees=[2], samples=5)


def test_ctrl_c_while_the_command_loads_is_one_line(monkeypatch):
    import io

    import lagsym.cli as cli

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "build_parser", interrupted)
    err = io.StringIO()
    assert cli.main(["equation", str(EXAMPLE1)], io.StringIO(), err) == 130
    assert err.getvalue() == "lagsym: interrupted; nothing was written\n"


def test_a_dnc_configuration_is_read_only_from_a_regular_file_within_its_limit(run_cli, tmp_path):
    from lagsym.dnc.config import MAX_CONFIG_BYTES

    status, out, err = run_cli("dnc", "serve", "/dev/zero", "--check")
    _one_line(status, err)
    assert "character device" in err
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    status, out, err = run_cli("dnc", "serve", fifo, "--check")  # would wait for a writer for ever
    _one_line(status, err)
    big = tmp_path / "big.toml"
    big.write_text("# " + "x" * MAX_CONFIG_BYTES + "\n")
    status, out, err = run_cli("dnc", "serve", big, "--check")
    _one_line(status, err)
    assert f"at most {MAX_CONFIG_BYTES} bytes" in err


def test_decimals_too_coarse_for_the_path_name_the_option(run_cli):
    status, out, err = run_cli("toolpath", EXAMPLE1, "--decimals", "0", "--stepover", "1", "--step", "1")
    _one_line(status, err)
    assert "--decimals" in err and "decimals 0 write positions 1 mm apart" in err and out == ""


def test_a_sampling_step_equal_to_the_written_resolution_is_refused_not_warned(run_cli):
    # --step 0.002 samples every 0.001 mm, which 3 decimals write as ties that round onto one position
    status, out, err = run_cli("toolpath", EXAMPLE1, "--stepover", "2", "--step", "0.002")
    _one_line(status, err)
    assert "decimals 3 write positions 0.001 mm apart" in err and "RuntimeWarning" not in err and out == ""
