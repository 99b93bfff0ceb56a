"""Point files as spreadsheets and measuring software write them, each accepted with its layout said, or refused."""

from __future__ import annotations

import csv
import io
import json
from fractions import Fraction

import pytest

from lagsym import lagrange_surface, read_points
from lagsym.errors import GridError, InputError
from lagsym.io import read_point_file
from lagsym.io.table import parse_columns

POINTS = [(1, 2, 7), (1, 3, 10), (1, 4, 13), (3, 2, 15), (3, 3, 18), (3, 4, 21),
          (5, 2, 31), (5, 3, 34), (5, 4, 37.5)]
EXPECTED_Z = ((7, 10, 13), (15, 18, 21), (31, 34, Fraction(75, 2)))


class Semicolon(csv.excel):
    """LibreOffice and Excel in a locale with decimal commas: semicolons, CRLF."""

    delimiter = ";"


def table(rows, dialect="excel", decimal=".", encoding="utf-8") -> bytes:
    buf = io.StringIO(newline="")
    w = csv.writer(buf, dialect=dialect)
    for row in rows:
        w.writerow([str(c).replace(".", decimal) if isinstance(c, float) else c for c in row])
    return buf.getvalue().encode(encoding)


def write(tmp_path, name, data):
    p = tmp_path / name
    p.write_bytes(data)
    return p


def check(path, *, layout=None, units=None, columns=None, snap=None):
    f = read_point_file(path, "surface", columns, snap)
    assert f.points.z == EXPECTED_Z
    assert f.points.units == units
    if layout is not None:
        assert f.layout == layout
    return f


def test_excel_csv_with_units_bom_and_crlf(tmp_path):
    data = table([("X (mm)", "Y (mm)", "Z (mm)")] + POINTS, encoding="utf-8-sig")
    assert data.startswith(b"\xef\xbb\xbf") and b"\r\n" in data
    f = check(write(tmp_path, "p.csv", data), units="mm",
              layout="comma-separated; decimal point; header 'X (mm),Y (mm),Z (mm)'; "
                     "x from column 1, y from column 2, z from column 3; units mm")
    assert not f.plain


def test_libreoffice_semicolons_and_decimal_commas(tmp_path):
    data = table([("X [mm]", "Y [mm]", "Z [mm]")] + POINTS, dialect=Semicolon, decimal=",")
    assert b"37,5" in data
    check(write(tmp_path, "p.csv", data), units="mm",
          layout="semicolon-separated; decimal comma; header 'X [mm];Y [mm];Z [mm]'; "
                 "x from column 1, y from column 2, z from column 3; units mm")


def test_comma_separated_with_quoted_decimal_commas(tmp_path):
    check(write(tmp_path, "p.csv", table(POINTS, decimal=",")))


def test_tab_separated_from_excel(tmp_path):
    data = table([("x_in", "y_in", "z_in")] + POINTS, dialect="excel-tab")
    check(write(tmp_path, "p.tsv", data), units="inch")


@pytest.mark.parametrize("name", ["scan.xyz", "scan.txt"])
def test_whitespace_separated_xyz(tmp_path, name):
    text = "X (mm)   Y (mm)   Z (mm)\n" + "".join(f"  {a:<6} {b:<6}  {c}\n" for a, b, c in POINTS)
    check(write(tmp_path, name, text.encode()), units="mm")


def test_a_trailing_empty_column_is_dropped_and_said(tmp_path):
    f = check(write(tmp_path, "p.csv", table([p + ("",) for p in POINTS])))
    assert f.layout.endswith("x from column 1, y from column 2, z from column 3")


def test_a_point_id_column_by_header_or_by_columns(tmp_path):
    rows = [(f"P{i + 1}",) + p for i, p in enumerate(POINTS)]
    f = check(write(tmp_path, "h.csv", table([("Point", "X", "Y", "Z")] + rows)))
    assert "x from column 2" in f.layout and "ignoring column(s) Point" in f.layout
    bare = write(tmp_path, "b.csv", table([(i + 1,) + p for i, p in enumerate(POINTS)]))
    with pytest.raises(InputError, match=r"4 columns and lagsym cannot tell which are x,y,z.*--columns id,x,y,z"):
        read_points(bare)
    check(bare, columns="id,x,y,z")
    check(bare, columns="2,3,4")
    with pytest.raises(InputError, match="--columns names 3 columns but the lines have 4"):
        read_points(bare, columns="x,y,z")


def test_columns_values():
    assert parse_columns("ID, X, Y, Z") == ("id", "x", "y", "z")
    assert parse_columns("4,2,3", 3) == (3, 1, 2)
    for bad in ("x,x,z", "0,1,2", "a,b,c", "1,2"):
        with pytest.raises(InputError, match="--columns"):
            parse_columns(bad, 3)


def test_json_list_of_objects_and_units(tmp_path):
    doc = {"units": "mm", "points": [{"id": i, "x": a, "y": b, "z": str(c)} for i, (a, b, c) in enumerate(POINTS)]}
    f = check(write(tmp_path, "p.json", json.dumps(doc).encode()), units="mm")
    assert f.layout == "JSON list of {x, y, z} objects"
    bare = [{"X": a, "Y": b, "Z": str(c)} for a, b, c in POINTS]
    check(write(tmp_path, "q.json", json.dumps(bare).encode()))
    with pytest.raises(InputError, match="point 1 .* should have keys x, y, z"):
        read_points(write(tmp_path, "r.json", b'[{"x": 1, "y": 2}]'))
    with pytest.raises(InputError, match=r"\"units\": \"furlong\" is not one lagsym knows"):
        read_points(write(tmp_path, "s.json", b'{"units": "furlong", "points": [[1, 2, 3]]}'))


def test_every_example_file_carries_its_units():
    from conftest import EXAMPLES

    assert read_points(EXAMPLES / "paper-example-4.json").units == "mm"


def cmm_points():
    jitter = {3: "2.9999999999999996", 5: "5.000000000000001"}
    return [(jitter.get(a, a) if i % 2 else a, b, c) for i, (a, b, c) in enumerate(POINTS)]


def test_cmm_jitter_is_refused_with_a_hint_then_snapped_and_reported(tmp_path, run_cli):
    path = write(tmp_path, "cmm.csv", table([("x", "y", "z")] + cmm_points()))
    with pytest.raises(GridError, match=r"x = 2.9999999999999996 and x = 3 differ by only 4e-16.*--snap 1e-13"):
        read_points(path)
    f = check(path, snap="1e-9")
    assert f.snapped.moved == 3 and f.snapped.largest == Fraction("1e-15") and f.snapped.nodes == (3, 3)
    status, out, err = run_cli("equation", path, "--snap", "1e-9")
    assert status == 0 and out.startswith("z = ")
    assert err == f"{path}: --snap 1e-09: moved 3 point(s) onto 3 x 3 nodes, the largest move 1e-15\n"
    assert lagrange_surface(f.points).exact_value(3, 3) == 18


def test_snap_refuses_a_tolerance_that_merges_real_nodes(tmp_path):
    path = write(tmp_path, "p.csv", table(POINTS))
    with pytest.raises(GridError, match="span more than"):
        read_points(path, snap="1.5")
    with pytest.raises(InputError, match="positive"):
        read_points(path, snap="0")


REFUSED = [
    ("mixed marks", [("1.5", "2,5", "3")], "mix decimal commas and decimal points"),
    ("unknown unit", [("X (m)", "Y (m)", "Z (m)"), (1, 2, 3)], "unit 'm' is not one lagsym knows (mm or inch)"),
    ("mixed units", [("X (mm)", "Y (mm)", "Z (in)"), (1, 2, 3)], "the header mixes units (inch, mm)"),
    ("only a header", [("x", "y", "z")], "only the header"),
    ("no names", [("East", "North", "Height"), (1, 2, 3)], "cannot tell which are x,y,z"),
    ("ragged", [(1, 2, 3), (1, 2)], "line 2 has 2 columns, expected 3"),
]


@pytest.mark.parametrize("case,rows,message", REFUSED, ids=[r[0] for r in REFUSED])
def test_refusals_say_what_to_change(tmp_path, case, rows, message):
    path = write(tmp_path, "p.csv", table(rows, dialect=Semicolon))
    with pytest.raises(InputError) as info:
        read_points(path)
    text = str(info.value)
    assert text.startswith(str(path)) and message in text and "\n" not in text, text


def test_the_cli_says_how_a_table_was_read_and_stays_quiet_for_plain_ones(tmp_path, run_cli):
    fancy = write(tmp_path, "p.csv", table([("X (mm)", "Y (mm)", "Z (mm)")] + POINTS, dialect=Semicolon, decimal=","))
    status, out, err = run_cli("check", fancy)
    assert status == 0 and err.startswith(f"{fancy}: read as semicolon-separated; decimal comma;")
    plain = write(tmp_path, "q.csv", table([("x", "y", "z")] + POINTS))
    assert run_cli("equation", plain)[2] == ""
    curve = write(tmp_path, "c.csv", table([("id", "x", "y"), (1, 1, 1), (2, 2, 3), (3, 3, 1)]))
    assert run_cli("curve", curve)[1] == "y = -2*x**2 + 8*x - 5\n"
    assert run_cli("curve", curve, "--columns", "2,3")[1] == "y = -2*x**2 + 8*x - 5\n"
    status, _, err = run_cli("equation", plain, "--columns", "1,2")
    assert status == 2 and "give 3 column numbers" in err


def test_quoted_and_plain_cells_read_alike(tmp_path):
    # A file with no quote anywhere is split without the csv module; one with quotes goes through it.
    plain = "x,y,z\n" + "".join(f"{a},{b},{c}\n" for a, b, c in POINTS)
    quoted = '"x","y","z"\n' + "".join(f'"{a}","{b}",{c}\n' for a, b, c in POINTS)
    a, b = (read_point_file(write(tmp_path, n, t.encode())) for n, t in (("a.csv", plain), ("b.csv", quoted)))
    assert a.points == b.points


def test_two_heights_at_one_place_are_refused_however_the_place_is_written(tmp_path):
    from lagsym.io import read_scattered_points

    text = "x,y,z\n0,0,1\n1.50,2,3\n4,5,6\n3/2,2.000,7\n"
    with pytest.raises(InputError, match=r"points 2 and 4 are both at \(x, y\) = \(1\.5, 2\)"):
        read_scattered_points(write(tmp_path, "s.csv", text.encode()))
    assert len(read_scattered_points(write(tmp_path, "t.csv", b"x,y,z\n0,0,1\n1.5,2,3\n1.5,2.0001,3\n")).points) == 3
