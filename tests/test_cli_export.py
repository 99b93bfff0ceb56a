"""``lagsym export``: bad options get one line and exit 2, and nothing is written."""

from __future__ import annotations

import json

import pytest

from lagsym.export.patchjson import parse_patch_json

from conftest import EXAMPLES

EX4 = str(EXAMPLES / "paper-example-4.json")


@pytest.mark.parametrize("argv, message", [
    ([EX4, "-o", "out.stl"], "out.stl: unknown CAD format '.stl'; choose one of .step, .stp, .igs, .iges, .json"),
    ([EX4, "-o", "out"], "out: unknown CAD format '(no extension)'"),
    ([EX4, "--solid", "-o", "out.step"], "--solid needs --base-z Z"),
    ([EX4, "--base-z", "0", "-o", "out.step"], "--base-z 0 is for a solid: add --solid"),
    ([EX4, "--solid", "--base-z", "nan", "-o", "out.step"], "--base-z: 'nan' is not a number"),
    ([EX4, "--solid", "--base-z", "1", "-o", "out.igs"],
     "--base-z 1 is not below the surface, whose lowest height is 0.1507663366"),
    ([EX4, "--solid", "--base-z", "0.1507663366", "-o", "out.json"], "is not below the surface"),
    ([EX4, "--units", "inch", "-o", "out.step"], "the file states \"units\": \"mm\", not --units inch"),
    ([EX4, "--method", "bspline", "--degree", "0", "-o", "out.step"], "argument --degree: '0' is out of range: give a whole number from 1 to 30"),
    (["missing.json", "-o", "out.step"], "missing.json: no such file"),
    ([EX4, "-o", "no/such/folder/out.step"], "no/such/folder does not exist"),
])
def test_bad_input_one_line_exit_2_nothing_written(run_cli, tmp_path, monkeypatch, argv, message):
    monkeypatch.chdir(tmp_path)
    status, out, err = run_cli("export", *argv)
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("lagsym: error: ") and message in err, err
    assert list(tmp_path.iterdir()) == []


def test_an_earlier_file_survives_a_refused_base(run_cli, tmp_path):
    target = tmp_path / "part.step"
    target.write_text("earlier")
    status, _, _ = run_cli("export", EX4, "--solid", "--base-z", "2", "-o", target)
    assert status == 2 and target.read_text() == "earlier"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["part.step"]


def test_traceback_only_on_request(run_cli, tmp_path):
    _, _, err = run_cli("export", EX4, "--solid", "--base-z", "2", "-o", tmp_path / "p.step", "--traceback")
    assert "Traceback" in err and "InputError" in err


def test_units_from_the_file_and_for_csv(run_cli, tmp_path):
    (tmp_path / "inch.json").write_text(json.dumps({"units": "inch", "points": [[0, 0, 1], [0, 1, 2], [1, 0, 3],
                                                                               [1, 1, 5]]}))
    assert run_cli("export", tmp_path / "inch.json", "-o", tmp_path / "a.step")[0] == 0
    assert "CONVERSION_BASED_UNIT('INCH'" in (tmp_path / "a.step").read_text()
    (tmp_path / "p.csv").write_text("x,y,z\n0,0,1\n0,1,2\n1,0,3\n1,1,5\n")
    status, out, _ = run_cli("export", tmp_path / "p.csv", "--units", "inch", "-o", tmp_path / "b.json")
    assert status == 0 and out.rstrip().endswith("exact control points, inch")
    assert json.loads((tmp_path / "b.json").read_text())["units"] == "inch"
    (tmp_path / "bad.json").write_text(json.dumps({"units": "furlong", "points": [[0, 0, 1], [0, 1, 2], [1, 0, 3],
                                                                                 [1, 1, 5]]}))
    status, _, err = run_cli("export", tmp_path / "bad.json", "-o", tmp_path / "c.step")
    assert status == 2 and "\"units\": \"furlong\" is not one lagsym knows" in err


def test_comparison_methods(run_cli, tmp_path):
    for method in ("bezier", "bspline"):
        status, out, _ = run_cli("export", EX4, "--method", method, "-o", tmp_path / f"{method}.json")
        assert status == 0
        patch = parse_patch_json((tmp_path / f"{method}.json").read_text())
        assert patch.name == ("Bezier" if method == "bezier" else "B-spline")
        assert patch.degree_u == (4 if method == "bezier" else 3)


def _smooth_grid(tmp_path, n):
    import math

    xs = [i * 60 / (n - 1) for i in range(n)]
    pts = [[round(x, 6), round(y, 6), round(20 + 10 * math.sin(x / 15) * math.cos(y / 20), 3)] for x in xs for y in xs]
    path = tmp_path / f"smooth{n}.json"
    path.write_text(json.dumps({"units": "mm", "points": pts}))
    return path


def test_warns_when_doubles_cannot_hold_the_surface(run_cli, tmp_path):
    status, _, err = run_cli("export", _smooth_grid(tmp_path, 8), "-o", tmp_path / "a.step")
    assert status == 0 and err == ""
    status, _, err = run_cli("export", _smooth_grid(tmp_path, 16), "-o", tmp_path / "b.step", "--accept-conditioning")
    assert status == 0 and "lagsym: warning: rounding the control points to doubles may move" in err
    assert "at degree (15, 15)" in err and (tmp_path / "b.step").exists()


def test_warns_above_the_kernel_degree(run_cli, tmp_path):
    path = tmp_path / "long.json"
    path.write_text(json.dumps([[x, y, 0] for x in range(27) for y in range(2)]))
    status, _, err = run_cli("export", path, "-o", tmp_path / "long.json.step", "--accept-conditioning")
    assert status == 0 and "degree (26, 1) is above 25" in err


@pytest.mark.parametrize("args, message", [
    (["--degree", "3"], "--degree 3 is the degree of --method bspline"),
    (["--method", "bspline", "--degree", "999999999"], "--degree"),
    (["--method", "bspline", "--degree", "0"], "--degree"),
])
def test_degree_is_refused_where_it_would_not_be_used(run_cli, tmp_path, args, message):
    status, _, err = run_cli("export", EXAMPLES / "paper-example-4.json", "-o", tmp_path / "x.step", *args)
    assert status == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.step").exists()
