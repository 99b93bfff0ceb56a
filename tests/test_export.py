"""Every format reads back with an independent reader; streamed tables stay small in memory."""

from __future__ import annotations

import csv
import json
import os
import stat
import tracemalloc

import numpy as np
import pytest

from conftest import EXAMPLES
from lagsym.errors import InputError
from lagsym.evaluate import surface_evaluator
from lagsym.export import FORMATS, format_of, write_sample
from lagsym.io import read_points
from lagsym.lagrange import lagrange_surface
from lagsym.sampling import sample, sample_grid

pv = pytest.importorskip("pyvista")

EXAMPLE4 = EXAMPLES / "paper-example-4.json"


@pytest.fixture(scope="module")
def surface():
    return lagrange_surface(read_points(EXAMPLE4))


@pytest.fixture(scope="module")
def grid(surface):
    return sample_grid(surface, 9, 7)


def _expected(surface, grid):
    X, Y, Z = sample(surface, grid=grid)
    return np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])


def test_csv_reads_back_with_the_csv_module(tmp_path, surface, grid):
    path = tmp_path / "s.csv"
    write_sample(path, surface, grid)
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["x", "y", "z"]
    table = np.array([[float(v) for v in r] for r in rows[1:]])
    assert table.shape == (63, 3)
    assert np.array_equal(table, _expected(surface, grid))  # shortest round-trip text loses nothing


def test_a_sampled_csv_is_itself_a_points_file(tmp_path, surface, grid):
    path = tmp_path / "s.csv"
    write_sample(path, surface, sample_grid(surface, 5, 5))
    again = lagrange_surface(read_points(path))
    assert again.grid.shape == (5, 5)
    assert again.grid.z == surface.grid.z  # the control heights come back exactly


def test_npy_reads_back_with_numpy(tmp_path, surface, grid):
    path = tmp_path / "s.npy"
    write_sample(path, surface, grid, block_points=10)
    a = np.load(path)
    assert a.shape == (63, 3) and a.dtype == np.float64
    assert np.abs(a - _expected(surface, grid)).max() <= surface_evaluator(surface).error_bound()


@pytest.mark.parametrize("ext", [".vtk", ".vts", ".stl", ".ply", ".obj"])
def test_meshes_read_back_with_vtk(tmp_path, surface, grid, ext):
    path = tmp_path / f"s{ext}"
    write_sample(path, surface, grid)
    mesh = pv.read(path)
    want = _expected(surface, grid)
    got = np.asarray(mesh.points, dtype=float)
    tol = 1e-6 if ext in (".stl", ".ply") else 1e-12  # STL stores float32; VTK reads PLY as float32
    if ext == ".vts":
        assert tuple(mesh.dimensions) == (9, 7, 1)
        assert mesh.n_cells == 8 * 6
    else:
        assert mesh.n_cells == 2 * 8 * 6
        assert np.allclose(mesh.compute_cell_sizes(length=False, volume=False)["Area"].sum(),
                           _area(want, 9, 7), rtol=1e-5)
    # same points as a set (STL readers may merge and reorder them)
    key = lambda a: a[np.lexsort((a[:, 1], a[:, 0]))]  # noqa: E731
    assert got.shape == want.shape
    assert np.allclose(key(got), key(want), rtol=0, atol=tol * 10)
    if ext in (".vtk", ".vts"):
        assert np.allclose(np.sort(np.asarray(mesh["z"])), np.sort(want[:, 2]), rtol=0, atol=1e-12)


def _area(points, nx, ny):
    p = points.reshape(nx, ny, 3)
    a, b, c, d = p[:-1, :-1], p[1:, :-1], p[1:, 1:], p[:-1, 1:]
    tri = lambda u, v, w: 0.5 * np.linalg.norm(np.cross(v - u, w - u), axis=-1).sum()  # noqa: E731
    return tri(a, b, c) + tri(a, c, d)


def test_mesh_normals_point_up(tmp_path, surface, grid):
    path = tmp_path / "s.stl"
    write_sample(path, surface, grid)
    mesh = pv.read(path).compute_normals(cell_normals=True, point_normals=False, auto_orient_normals=False,
                                         consistent_normals=False)
    assert (np.asarray(mesh.cell_data["Normals"])[:, 2] > 0).all()


def test_unknown_extension_names_the_choices(tmp_path):
    with pytest.raises(InputError, match=r"'\.xyz'.*\.csv, \.npy"):
        format_of(tmp_path / "a.xyz")
    assert set(FORMATS) == {".csv", ".npy", ".vtk", ".vts", ".stl", ".ply", ".obj"}


def test_a_failure_mid_stream_leaves_no_file(tmp_path, surface):
    path = tmp_path / "big.npy"
    path.write_bytes(b"earlier")

    def stop(done):
        if done > 100:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_sample(path, surface, sample_grid(surface, 100, 100), progress=stop, block_points=50)
    assert path.read_bytes() == b"earlier"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.npy"]


def test_too_large_a_mesh_is_refused_before_any_work(tmp_path, surface, monkeypatch):
    import lagsym.export

    monkeypatch.setattr(lagsym.export, "MESH_MAX_POINTS", 100)
    with pytest.raises(InputError, match="use a coarser grid"):
        write_sample(tmp_path / "a.stl", surface, sample_grid(surface, 11, 11))
    assert list(tmp_path.iterdir()) == []


def test_output_files_get_the_usual_permissions(tmp_path, surface, grid):
    mask = os.umask(0o022)
    try:
        for ext in (".csv", ".stl"):
            write_sample(tmp_path / f"p{ext}", surface, grid)
            assert stat.S_IMODE((tmp_path / f"p{ext}").stat().st_mode) == 0o644
    finally:
        os.umask(mask)


def _peak(fn) -> int:
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_streamed_npy_memory_stays_bounded(tmp_path, surface):
    grid = sample_grid(surface, 2000, 2000)  # 4M points: 96 MB as one array
    path = tmp_path / "big.npy"
    peak = _peak(lambda: write_sample(path, surface, grid, block_points=1 << 16))
    assert peak < 12 * 2**20, f"peak {peak / 2**20:.1f} MB"
    a = np.load(path, mmap_mode="r")
    assert a.shape == (4_000_000, 3)
    assert a[-1].tolist() == [5.0, 5.0, 1.06]
    assert a[2000 * 1000 + 7, 0] == grid.xs[1000] and a[2000 * 1000 + 7, 1] == grid.ys[7]


def test_streamed_csv_memory_stays_bounded(tmp_path, surface):
    grid = sample_grid(surface, 300, 300)  # 90000 lines, about 5 MB of text
    path = tmp_path / "big.csv"
    peak = _peak(lambda: write_sample(path, surface, grid, block_points=1 << 12))
    assert peak < 2**20, f"peak {peak / 2**20:.1f} MB"
    assert path.stat().st_size > 4 * 2**20
    with open(path) as fh:
        assert sum(1 for _ in fh) == 90001


# --- the command line -------------------------------------------------------


def test_cli_writes_csv_to_stdout(run_cli):
    status, out, err = run_cli("sample", EXAMPLE4, "--nx", "3", "--ny", "2")
    assert status == 0 and err == ""
    assert out.splitlines() == ["x,y,z", "1.0,1.0,1.0", "1.0,5.0,1.06", "3.0,1.0,1.05", "3.0,5.0,3.39",
                                "5.0,1.0,1.0", "5.0,5.0,1.06"]


@pytest.mark.parametrize("ext", FORMATS)
def test_cli_writes_every_format(run_cli, tmp_path, ext):
    path = tmp_path / f"out{ext}"
    status, out, err = run_cli("sample", EXAMPLE4, "--step", "0.5", "-o", path)
    assert (status, out, err) == (0, "", "")
    if ext == ".npy":
        assert np.load(path).shape == (81, 3)
    elif ext == ".csv":
        assert len(path.read_text().splitlines()) == 82
    else:
        assert pv.read(path).n_points == 81


def test_cli_one_count_sets_both(run_cli):
    status, out, _ = run_cli("sample", EXAMPLE4, "--nx", "4")
    assert status == 0 and len(out.splitlines()) == 17


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--nx", "1"], "argument --nx: '1' is out of range"),
        (["--step", "0"], "argument --step: '0' is out of range"),
        (["--x0", "0"], "extrapolation"),
        (["--x0", "x"], "'x' is not a number"),
        (["--nx", "5", "--step", "1"], "not both"),
        (["-o", "{tmp}/a.xyz"], "unknown output format '.xyz'"),
        (["-o", "{tmp}/missing/a.csv"], "does not exist"),
    ],
)
def test_cli_bad_requests_exit_2_with_one_line_and_no_file(run_cli, tmp_path, args, words):
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    status, out, err = run_cli("sample", EXAMPLE4, *args)
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("lagsym: error:") and words in err
    assert list(tmp_path.iterdir()) == []


def test_cli_bad_points_file_exits_2(run_cli, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("[[1, 2, 3], [1, 3, 4]]")
    status, _, err = run_cli("sample", bad, "-o", tmp_path / "o.csv")
    assert status == 2 and str(bad) in err
    assert not (tmp_path / "o.csv").exists()


def test_cli_extrapolation_is_warned(run_cli, tmp_path):
    path = tmp_path / "wide.npy"
    status, _, err = run_cli("sample", EXAMPLE4, "--x0", "0", "--x1", "6", "--nx", "7", "--ny", "5",
                             "--extrapolate", "-o", path)
    assert status == 0
    assert "warning" in err and "extrapolated" in err
    a = np.load(path)
    assert a[0, 0] == 0.0 and a[-1, 0] == 6.0


def test_cli_warns_when_rounding_cannot_be_trusted(run_cli, tmp_path):
    rng = np.random.default_rng(5)
    n = 20
    pts = [[k, j, int(v) / 100] for k in range(n) for j, v in zip(range(n), rng.integers(100, 340, n))]
    src = tmp_path / "rough.json"
    src.write_text(json.dumps(pts))
    # 20 x 20 even nodes amplify errors in the points beyond any use: accepted here to see the rounding warning.
    status, _, err = run_cli("sample", src, "--nx", "5", "-o", tmp_path / "o.csv", "--accept-conditioning")
    assert status == 0
    assert "rounding error of the samples may reach" in err and "lagsym check" in err
    status, out, _ = run_cli("check", src, "--format", "json")
    assert any(f["name"] == "float_error" and f["warning"] for f in json.loads(out)["findings"])


@pytest.mark.slow
def test_cli_paper_example_samples_without_warnings(run_cli, tmp_path):
    status, _, err = run_cli("sample", EXAMPLE4, "--nx", "400", "--ny", "400", "-o", tmp_path / "i.csv")
    assert (status, err) == (0, "")
    assert read_points(tmp_path / "i.csv").shape == (400, 400)


class _Terminal:
    """A text stream that says it is a terminal, to see the progress bar."""

    def __init__(self):
        import io

        self.buf = io.StringIO()

    def write(self, s):
        return self.buf.write(s)

    def flush(self):
        pass

    def isatty(self):
        return True


@pytest.mark.parametrize("quiet", [False, True])
def test_cli_progress_bar_only_on_a_terminal_and_not_quiet(tmp_path, quiet):
    import io

    from lagsym.cli import main

    err = _Terminal()
    argv = ["sample", str(EXAMPLE4), "--nx", "600", "--ny", "600", "-o", str(tmp_path / "p.npy")]
    status = main(argv + (["--quiet"] if quiet else []), io.StringIO(), err)
    assert status == 0
    shown = err.buf.getvalue()
    assert ("sampling" in shown) != quiet
    assert np.load(tmp_path / "p.npy").shape == (360000, 3)


def test_ply_header_names_each_property_once(tmp_path, surface, grid):
    path = tmp_path / "s.ply"
    write_sample(path, surface, grid)
    header = path.read_bytes().split(b"end_header")[0].decode("ascii").splitlines()
    props = [line.split()[-1] for line in header if line.startswith("property double")]
    assert props == ["x", "y", "z"]
