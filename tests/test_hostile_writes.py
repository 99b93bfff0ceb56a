"""Hostile writes: every output checked against the inputs and the other outputs, a full disk under VTK, paths
past the system's limits, file names with control characters, a header that does not match its rows."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from conftest import EXAMPLES

EXAMPLE4 = EXAMPLES / "paper-example-4.json"
PROGRAM = "%\nO1000\nG0 X1. Y1. Z5.\nM30\n%\n"


def _refused(status, out, err, needle):
    assert (status, out) == (2, ""), (status, out, err)
    assert err.count("\n") == 1 and err.startswith("lagsym: error: ") and needle in err, err


# F1: an output option other than -o naming an input, or two outputs naming one file.

def test_print_output_naming_the_program_is_refused(run_cli, tmp_path):
    p = tmp_path / "p.nc"
    p.write_text(PROGRAM)
    _refused(*run_cli("simulate", p, "--print-output", p, "-o", tmp_path / "out.csv"),
             f"--print-output {p}: is also an input")
    assert p.read_text() == PROGRAM and not (tmp_path / "out.csv").exists()


def test_print_output_naming_the_surface_is_refused(run_cli, tmp_path):
    p, s = tmp_path / "p.nc", tmp_path / "s.json"
    p.write_text(PROGRAM)
    s.write_bytes(EXAMPLE4.read_bytes())
    other = tmp_path / "same.json"
    os.link(s, other)  # the same file by another name: device and inode, not the name, decide
    _refused(*run_cli("simulate", p, "--surface", s, "--print-output", other), "is also an input")
    assert s.read_bytes() == EXAMPLE4.read_bytes()


def test_two_outputs_naming_one_file_are_refused(run_cli, tmp_path):
    p = tmp_path / "p.nc"
    p.write_text(PROGRAM)
    out = tmp_path / "out.csv"
    _refused(*run_cli("simulate", p, "--print-output", out, "-o", out), "is also the output of -o")
    assert not out.exists()  # a new name counts by its real path
    link = tmp_path / "link.csv"
    link.symlink_to(out)
    _refused(*run_cli("simulate", p, "--print-output", link, "-o", out), "is also the output of -o")
    status, _, err = run_cli("simulate", p, "--print-output", os.devnull, "-o", os.devnull)
    assert status == 0, err  # a device takes both


def test_compare_plot_and_send_log_are_checked(run_cli, tmp_path):
    s = tmp_path / "s.json"
    s.write_bytes(EXAMPLE4.read_bytes())
    _refused(*run_cli("compare", s, "--plot", s), f"--plot {s}: is also an input")
    _refused(*run_cli("compare", s, "--plot", tmp_path / "m.png", "-o", tmp_path / "m.png"), "the output of -o")
    p = tmp_path / "p.nc"
    p.write_text(PROGRAM)
    _refused(*run_cli("send", p, "--port", os.devnull, "--log", p), f"--log {p}: is also an input")
    _refused(*run_cli("receive", "--port", os.devnull, "--log", tmp_path / "r.nc", "-o", tmp_path / "r.nc"),
             "the output of -o")
    assert s.read_bytes() == EXAMPLE4.read_bytes() and p.read_text() == PROGRAM


def test_job_output_naming_the_job_points_is_refused(run_cli, tmp_path):
    pts = tmp_path / "pts.json"
    pts.write_bytes(EXAMPLE4.read_bytes())
    job = tmp_path / "job.toml"
    job.write_text((EXAMPLES / "example-4-job.toml").read_text().replace('"paper-example-4.json"', '"pts.json"'))
    _refused(*run_cli("job", job, "-o", pts), "is also an input")
    assert pts.read_bytes() == EXAMPLE4.read_bytes()


# F2: a full disk under VTK's writers (and meshio's): one line, exit 2, the earlier file untouched.

@pytest.fixture
def full_disk(tmp_path):
    """A 200 KB tmpfs: mounted here when running as root, else the tests skip."""
    if os.geteuid() != 0:
        pytest.skip("mounting a small tmpfs (a disk that fills) needs root")
    where = tmp_path / "full"
    where.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=200k", "tmpfs", str(where)], capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {r.stderr.strip()}")
    try:
        yield where
    finally:
        subprocess.run(["umount", "-l", str(where)], check=False)


@pytest.mark.parametrize("ext", [".vts", ".stl", ".vtk", ".ply", ".obj"])
def test_a_full_disk_keeps_the_earlier_mesh_and_says_one_line(full_disk, ext):
    target = full_disk / f"s{ext}"
    target.write_text("earlier\n")
    r = subprocess.run([sys.executable, "-m", "lagsym", "sample", str(EXAMPLE4), "--nx", "300", "-q", "-o",
                        str(target)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 2 and r.stdout == "", (r.returncode, r.stderr[:2000])
    assert r.stderr == f"lagsym: error: {target}: cannot write ({r.stderr.split('(', 1)[1]}"
    assert r.stderr.count("\n") == 1 and r.stderr.count("cannot write") == 1, r.stderr[:2000]
    assert "vtk" not in r.stderr.replace(str(target), "").lower() and "any earlier file there is untouched" in r.stderr
    if ext in (".vts", ".stl"):
        assert "no space left on the device" in r.stderr
    assert target.read_text() == "earlier\n"
    assert sorted(os.listdir(full_disk)) == [target.name]  # no temporary left behind


@pytest.mark.parametrize("ext", [".vts", ".stl"])
def test_a_vtk_mesh_written_whole_is_checked_and_kept(run_cli, tmp_path, ext):
    target = tmp_path / f"s{ext}"
    status, out, err = run_cli("sample", EXAMPLE4, "--nx", "30", "--ny", "20", "-q", "-o", target)
    assert (status, err) == (0, ""), err
    data = target.read_bytes()
    if ext == ".stl":
        assert len(data) == 84 + 50 * 2 * 29 * 19
    else:
        assert data.endswith(b"</VTKFile>\n")


# F4: a path the system cannot take whole (its absolute form over PATH_MAX, a symbolic-link loop) is one line, exit 2.

@pytest.fixture
def deep(tmp_path, monkeypatch):
    """A relative folder of 4,089 characters (4,095 with ``/x.txt``) whose absolute path is over 4,096."""
    monkeypatch.chdir(tmp_path)
    rel = "/".join(["d" * 200] * 20) + "/" + "e" * 69
    os.makedirs(rel)
    assert len(rel + "/x.txt") == 4095 and len(os.path.abspath(rel + "/x.txt")) > 4096
    return rel


def test_an_output_whose_absolute_path_is_too_long_is_one_line(run_cli, deep):
    _refused(*run_cli("equation", EXAMPLE4, "-o", deep + "/x.txt"), "longer than the system allows")
    p = "p.nc"
    with open(p, "w") as fh:
        fh.write(PROGRAM)
    _refused(*run_cli("simulate", p, "--print-output", deep + "/x.txt"), "longer than the system allows")
    assert os.listdir(deep) == []


def test_an_input_path_too_long_or_looping_is_one_line(run_cli, tmp_path, deep):
    _refused(*run_cli("equation", os.path.abspath(deep) + "/x.json"), "longer than the system allows")
    (tmp_path / "l1").symlink_to(tmp_path / "l2")
    (tmp_path / "l2").symlink_to(tmp_path / "l1")
    _refused(*run_cli("rough", "l1", "--stock-above", "2"), "too many levels of symbolic links")
    (tmp_path / "c.toml").write_text(f'[[port]]\nname = "a"\ndevice = "loop://"\nprograms = "{deep}"\n'
                                     f'received = "."\n')
    _refused(*run_cli("dnc", "serve", "c.toml", "--check"), "longer than the system allows")


# F15: a note, a warning or a summary that names a file shows a newline in the name escaped, as errors do.

SEMICOLON_TABLE = "x;y;z\n1;1;1,5\n1;2;2\n2;1;3\n2;2;4\n"


@pytest.mark.parametrize("command", ["equation", "check", "fit", "piecewise"])
def test_a_note_naming_a_file_with_a_newline_is_one_line(run_cli, tmp_path, command):
    p = tmp_path / "semi\ncolon.csv"
    p.write_text(SEMICOLON_TABLE)
    status, out, err = run_cli(command, p)
    note = [line for line in err.splitlines() if "read as semicolon-separated" in line]
    assert len(note) == 1 and note[0].startswith(str(tmp_path) + "/semi\\ncolon.csv: read as"), err
    assert "colon.csv" not in err.replace("semi\\ncolon.csv", ""), err  # no line starts inside the name


@pytest.mark.slow
def test_summaries_naming_a_file_with_a_newline_are_one_line(run_cli, tmp_path):
    prog = tmp_path / "p\nq.nc"
    prog.write_text(PROGRAM)
    status, out, err = run_cli("simulate", prog, "-o", os.devnull)
    assert status == 0 and err == f"{tmp_path}/p\\nq.nc: fanuc, 8 digits: " + err.split(": fanuc, 8 digits: ")[1]
    assert err.count("\n") == 1, err
    step = tmp_path / "x\ny.step"
    status, out, err = run_cli("export", EXAMPLE4, "-o", step)
    assert status == 0 and out.startswith(f"{tmp_path}/x\\ny.step: ") and out.count("\n") == 1, out
    nc = tmp_path / "t\nu.nc"
    status, out, err = run_cli("toolpath", EXAMPLE4, "--stepover", "1", "--step", "1", "-o", nc)
    assert status == 0 and err.startswith(f"{tmp_path}/t\\nu.nc: ") and err.count("\n") == 1, err
    status, out, err = run_cli("equation", EXAMPLE4, "x\ny")
    assert status == 2 and "x\\ny" in err and err.count("\n") == 1, err


# F19: a header of another width than its rows is refused; no message echoes more than a few hundred characters.

def _write(path, text):
    path.write_text(text)
    return path


def test_a_header_wider_than_its_rows_is_refused_in_one_short_line(run_cli, tmp_path):
    p = _write(tmp_path / "hdr160k.csv", "x,y,z" + ",w" * 80000 + "\n1,1,2\n1,2,3\n2,1,3\n2,2,4\n")
    status, out, err = run_cli("equation", p)
    _refused(status, out, err, "the header (line 1) has 80,003 columns but the data lines have 3 (line 2)")
    assert len(err) < 400 and "'x,y,z,w," in err, err
    narrow = _write(tmp_path / "narrow.csv", "x,y,z\n1,1,2,5\n1,2,3,5\n2,1,3,5\n2,2,4,5\n")
    _refused(*run_cli("equation", narrow), "the header (line 1) has 3 columns but the data lines have 4")


def test_a_trailing_separator_is_not_a_column(run_cli, tmp_path):
    for text in ("x,y,z,\n1,1,2,\n1,2,3,\n2,1,3,\n2,2,4,\n", "x,y,z,\n1,1,2\n1,2,3\n2,1,3\n2,2,4\n",
                 "x,y,z\n1,1,2,\n1,2,3,\n2,1,3,\n2,2,4,\n"):
        status, out, err = run_cli("equation", _write(tmp_path / "t.csv", text))
        assert (status, out) == (0, "z = x + y\n"), (text, err)


def test_the_notes_and_messages_quote_a_short_prefix(run_cli, tmp_path):
    from lagsym.io.table import SHOWN, SHOWN_NAMES

    assert (SHOWN, SHOWN_NAMES) == (60, 5)  # as docs/formats.md says
    ids = [f"identifier{i}" for i in range(1000)]
    rows = "".join(",".join(["0"] * 1000) + f",{a},{b},{a + b}\n" for a in (1, 2) for b in (1, 2))
    p = _write(tmp_path / "ids.csv", ",".join(ids) + ",x,y,z\n" + rows)
    status, out, err = run_cli("equation", p)
    assert status == 0 and err.count("\n") == 1 and len(err) < 400, err
    assert "ignoring column(s) identifier0, identifier1, identifier2, identifier3, identifier4 and 995 more" in err
    assert "'identifier0,identifier1,identifier2,identifier3,identifier4,'... (" in err
    cell = _write(tmp_path / "cell.csv", "x,y,z\n1,1," + "q" * 9000 + "\n1,2,3\n2,1,3\n2,2,4\n")
    _refused(*(r := run_cli("equation", cell)), "'" + "q" * 60 + "'... (8,940 more characters) is not a number")
    assert len(r[2]) < 400
