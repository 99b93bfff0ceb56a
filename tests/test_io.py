"""Reading point files: exact numbers, every accepted layout, and every refusal."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lagsym import GridError, InputError, read_any_points, read_curve_points, read_points
from lagsym.grid import ControlGrid, CurvePoints
from lagsym.io import atomic_write, exact_number, write_text

TRIPLES = "[[1, 2, 7], [1, 3, 10], [3, 2, 15], [3, 3, 18]]"


def write(tmp_path: Path, name: str, text: str | bytes) -> Path:
    p = tmp_path / name
    (p.write_bytes if isinstance(text, bytes) else p.write_text)(text)
    return p


def test_json_number_text_is_an_exact_decimal(tmp_path):
    g = read_points(write(tmp_path, "p.json", "[[1, 2, 1.06], [1, 3, 0.1], [3, 2, 1e-3], [3, 3, 2.5E2]]"))
    assert g.z == ((Fraction(53, 50), Fraction(1, 10)), (Fraction(1, 1000), Fraction(250)))


def test_strings_hold_exact_decimals_and_rationals(tmp_path):
    g = read_points(write(tmp_path, "p.json", '[["1/3", 2, "1.06"], ["1/3", 3, "-2/7"], [3, 2, 0], [3, 3, " 4 "]]'))
    assert g.x[0] == Fraction(1, 3) and g.z[0] == (Fraction(53, 50), Fraction(-2, 7))


@pytest.mark.parametrize(
    "text",
    [
        TRIPLES,
        '{"units": "mm", "points": ' + TRIPLES + "}",
        '{"x": [1, 3], "y": [2, 3], "z": [[7, 10], [15, 18]]}',
        '{"x": [3, 1], "y": [3, 2], "z": [[18, 15], [10, 7]]}',
        "[[3, 3, 18], [1, 2, 7], [3, 2, 15], [1, 3, 10]]",
    ],
)
def test_every_json_layout_gives_the_same_grid(tmp_path, text):
    g = read_points(write(tmp_path, "p.json", text))
    assert g.x == (1, 3) and g.y == (2, 3) and g.z == ((7, 10), (15, 18))


@pytest.mark.parametrize("text", ["x,y,z\n1,2,7\n1,3,10\n3,2,15\n3,3,18\n", "1,2,7\n3,3,18\n1,3,10\n3,2,15\n",
                                  "z,x,y\n7,1,2\n10,1,3\n15,3,2\n18,3,3\n", "# comment\n\n1, 2, 7\n1,3,10\n3,2,15\n3,3,18\n"])
def test_csv_with_or_without_header(tmp_path, text):
    g = read_points(write(tmp_path, "p.csv", text))
    assert g.z == ((7, 10), (15, 18))


def test_uneven_spacing_and_decreasing_axes(tmp_path):
    g = read_points(write(tmp_path, "p.json", '{"x": [5, 1, 2], "y": [0.5, 0], "z": [[1, 2], [3, 4], [5, 6]]}'))
    assert g.x == (1, 2, 5) and g.y == (0, Fraction(1, 2))
    assert g.z == ((4, 3), (6, 5), (2, 1))


def test_curve_files(tmp_path):
    assert read_curve_points(write(tmp_path, "c.json", "[[3, 1], [1, 1], [2, 3]]")).x == (1, 2, 3)
    assert read_curve_points(write(tmp_path, "c.json", '{"points": [[1, 1], [2, 3]]}')).y == (1, 3)
    assert read_curve_points(write(tmp_path, "c.csv", "x,y\n1,1\n2,3\n")).y == (1, 3)
    assert isinstance(read_any_points(write(tmp_path, "c.json", "[[1, 1], [2, 3]]")), CurvePoints)
    assert isinstance(read_any_points(write(tmp_path, "s.json", TRIPLES)), ControlGrid)


BAD = [
    ("empty", "p.json", "", "empty"),
    ("blank", "p.json", "  \n ", "empty"),
    ("not json", "p.json", "[[1, 2, 3", "not valid JSON"),
    ("nan", "p.json", "[[1, 2, NaN], [1, 3, 1], [3, 2, 1], [3, 3, 1]]", "NaN"),
    ("infinity", "p.json", "[[1, 2, Infinity], [1, 3, 1], [3, 2, 1], [3, 3, 1]]", "Infinity"),
    ("overflow", "p.json", "[[1, 2, 1e999], [1, 3, 1], [3, 2, 1], [3, 3, 1]]", "1e999"),
    ("huge int", "p.json", "[[1, 2, " + "9" * 400 + "], [1, 3, 1], [3, 2, 1], [3, 3, 1]]", "overflow"),
    ("boolean", "p.json", "[[1, 2, true], [1, 3, 1], [3, 2, 1], [3, 3, 1]]", "true is a boolean"),
    ("word", "p.json", '[[1, 2, "seven"], [1, 3, 1], [3, 2, 1], [3, 3, 1]]', "'seven' is not a number"),
    ("null", "p.json", "[[1, 2, null], [1, 3, 1], [3, 2, 1], [3, 3, 1]]", "null is not a number"),
    ("short triple", "p.json", "[[1, 2], [1, 3, 1], [3, 2, 1], [3, 3, 1]]", "point 1 [1, 2] has 2 values"),
    ("missing point", "p.json", "[[1, 2, 7], [1, 3, 10], [3, 2, 15]]", "no point at (x, y) = (3, 3)"),
    ("duplicated point", "p.json", "[[1, 2, 7], [1, 3, 10], [3, 2, 15], [3, 3, 18], [1, 3, 11]]",
     "duplicated grid point (1, 3) at points 2 and 5"),
    ("repeated node", "p.json", '{"x": [1, 2, 1], "y": [0, 1], "z": [[1, 2], [3, 4], [5, 6]]}', "repeated node x = 1"),
    ("single row", "p.json", "[[1, 2, 7], [1, 3, 10], [1, 4, 13]]", "all 3 points have x = 1"),
    ("scattered", "p.json", "[[0, 0, 1], [1, 2, 1], [2, 1, 1], [3, 3, 1]]", "do not form a rectangular grid"),
    ("ragged table", "p.json", '{"x": [1, 2], "y": [0, 1], "z": [[1, 2], [3]]}', "z[1] has 1 heights"),
    ("garbage bytes", "p.json", b"\xff\xfe\x00garbage\x9c", "not a text file"),
    ("nul byte", "p.csv", "1,2,3\x00\n", "not a text file"),
    ("deep nesting", "p.json", "[" * 100000 + "]" * 100000, "nested too deeply"),
    ("object", "p.json", '{"a": 1}', "expected a \"points\" list"),
    ("csv word", "p.csv", "1,2,7\n1,3,abc\n", "line 2: 'abc' is not a number"),
    ("csv columns", "p.csv", "1,2,7\n1,3\n", "line 2 has 2 columns"),
    ("zero denominator", "p.json", '[[1, 2, "1/0"], [1, 3, 1], [3, 2, 1], [3, 3, 1]]', "divides by zero"),
]


@pytest.mark.parametrize("case,name,text,message", BAD, ids=[b[0] for b in BAD])
def test_bad_input_names_the_file_and_value(tmp_path, case, name, text, message):
    path = write(tmp_path, name, text)
    with pytest.raises(InputError) as info:
        read_points(path)
    text = str(info.value)
    assert text.startswith(str(path)), text
    assert message in text, text
    assert "\n" not in text


def test_missing_file_and_directory(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        read_points(tmp_path / "nope.json")
    with pytest.raises(InputError, match="is a directory"):
        read_points(tmp_path)


def test_curve_with_repeated_x_cites_limitation_1(tmp_path):
    with pytest.raises(GridError, match="x = 2 repeats.*limitation 1"):
        read_curve_points(write(tmp_path, "c.json", "[[1, 1], [2, 3], [2, 4]]"))


@pytest.mark.parametrize("text,value", [("1.06", Fraction(53, 50)), ("-1/3", Fraction(-1, 3)), (".5", Fraction(1, 2)),
                                        ("2e3", Fraction(2000)), ("+7", Fraction(7))])
def test_exact_number(text, value):
    assert exact_number(text) == value


def test_atomic_write_leaves_the_old_file_on_failure(tmp_path):
    target = tmp_path / "out.txt"
    write_text(target, "old\n")
    with pytest.raises(RuntimeError):
        with atomic_write(target) as fh:
            fh.write("half")
            raise RuntimeError("disk died")
    assert target.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_written_files_get_the_usual_permissions(tmp_path):
    import os

    mask = os.umask(0o022)
    try:
        write_text(tmp_path / "o.txt", "x\n")
    finally:
        os.umask(mask)
    assert (tmp_path / "o.txt").stat().st_mode & 0o777 == 0o644


@settings(max_examples=300, deadline=None)
@given(st.from_regex(r"[ \t]?[+-]?[0-9]{0,30}(\.[0-9]{0,30})?[ \t]?", fullmatch=True))
def test_a_plain_decimal_reads_as_the_decimal_module_reads_it(text):
    """The short path for decimals without exponent gives the value Decimal gives, and refuses what it refuses."""
    from decimal import Decimal, InvalidOperation

    from lagsym.values import NotANumber, exact_number

    try:
        expected = Fraction(Decimal(text.strip()))
    except InvalidOperation:
        with pytest.raises(NotANumber):
            exact_number(text)
        return
    assert exact_number(text) == expected
