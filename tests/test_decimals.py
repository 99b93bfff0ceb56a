"""Tables of plain decimals read in whole columns: the same exact points, layout and messages as cell by cell.

The oracle for every value is Python's own ``Fraction(text)`` on the cell
(which reads a decimal string exactly); the layout is compared with what the
cell-by-cell reader finds for the same text.
"""

from __future__ import annotations

import math
import random
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from lagsym.errors import InputError
from lagsym.fit import fit_surface
from lagsym.fit.hull import convex_hull, convex_hull_integers
from lagsym.io import read_scattered_points
from lagsym.io import table
from lagsym.io.decimals import DecimalPoints, first_repeat
from lagsym.io.table import read_table


def cell_by_cell(name, text, arity, columns=None, monkeypatch=None):
    """What the table reader gives without the whole-column path."""
    monkeypatch.setattr(table, "_plain_table", lambda *a: None)
    try:
        return read_table(name, text, arity, columns)
    finally:
        monkeypatch.undo()


def oracle(text: str, sep: str, chosen, skip_header: bool):
    lines = text.replace("\r\n", "\n").split("\n")
    lines = [ln for ln in lines[1 if skip_header else 0:] if ln]
    return [tuple(Fraction(ln.split(sep)[j]) for j in chosen) for ln in lines]


TABLES = [
    # text, arity, columns, separator, chosen columns, header
    ("x,y,z\n51.182,44.300,8.370\n-0.5,+.25,7.\n", 3, None, ",", (0, 1, 2), True),
    ("X (mm);Y (mm);Z (mm)\r\n1;2;3.125\r\n-4;5.5;-0\r\n", 3, None, ";", (0, 1, 2), True),
    ("id\tx\ty\tz\n1\t0.1\t0.2\t0.3\n2\t0.25\t-0.75\t100\n", 3, None, "\t", (1, 2, 3), True),
    ("1 2 3\n4 5.5 6.25\n7 8 9", 3, None, " ", (0, 1, 2), False),
    ("0.00000000000000001,123456789012345678,1\n2,3,4\n", 3, None, ",", (0, 1, 2), False),
    ("5,1,2,3\n6,4,5,6\n", 3, "2,3,4", ",", (1, 2, 3), False),
    ("x,y\n0,1\n0.5,2.25\n", 2, None, ",", (0, 1), True),
]


@pytest.mark.parametrize("text, arity, columns, sep, chosen, header", TABLES, ids=range(len(TABLES)))
def test_whole_columns_read_the_exact_points_and_layout_the_cells_give(text, arity, columns, sep, chosen, header,
                                                                        monkeypatch):
    cols = table.parse_columns(columns, arity) if columns else None
    assert table._plain_table("t.csv", text, arity, cols) is not None  # the whole-column path read it
    points, layout = read_table("t.csv", text, arity, cols)
    assert isinstance(points, DecimalPoints)
    expected = oracle(text, sep, chosen, header)
    assert list(points) == expected and [points[k] for k in range(len(points))] == expected
    slow, slow_layout = cell_by_cell("t.csv", text, arity, cols, monkeypatch)
    assert slow == expected and layout == slow_layout and layout.describe() == slow_layout.describe()
    for j in range(arity):
        assert points.floats(j).tolist() == [float(p[j]) for p in expected]
        ints, d = points.integers(j)
        assert [Fraction(n, d) for n in ints] == [p[j] for p in expected]
        assert d == math.lcm(*(p[j].denominator for p in expected))  # the least that serves


# Tables the whole-column path leaves to the cell-by-cell reader, which reads them (or refuses them) as before.
ELSEWHERE = [
    "1,2,3e5\n4,5,6\n",            # an exponent
    "1,2,1/3\n4,5,6\n",            # a rational
    "1;2,5;3\n4;5;6\n",            # a decimal comma
    '"1","2","3"\n4,5,6\n',        # quotes
    "1,2,3\n\n4,5,6\n",            # a blank line
    "# scan 3\n1,2,3\n4,5,6\n",    # a comment
    "1, 2, 3\n4, 5, 6\n",          # spaces beside the commas
    "1,2,3,\n4,5,6,\n",            # a trailing separator
    "1,2,1234567890123456789\n4,5,6\n",  # 19 digits
    "1,2,0.00000000000000001\n4,5,123\n",  # 3 + 17 digits once the column is scaled
    "1  2  3\n4  5  6\n",          # runs of spaces
    "1,2,3\n4,5,6\r7,8,9\n",       # a carriage return alone
    "x,y,z\n1,2,3\n4,5\n",         # a short line
    "x,y,z\n1,2,3\n4,5,x\n",       # a word
    "x,y,z\n1,2,3\n4,5,-\n",       # a sign alone
    "x,y,z\n1,2,3\n4,5,1.2.3\n",   # two points
    "x,y,z\n1,2,3\n4,5,3-\n",      # a sign at the end
    "x,y,z\n1,2,3\n4,5,\u0663\n",  # an Arabic-Indic digit
]


@pytest.mark.parametrize("text", ELSEWHERE, ids=range(len(ELSEWHERE)))
def test_other_tables_are_read_cell_by_cell_with_the_same_result(text, monkeypatch):
    assert table._plain_table("t.csv", text, 3, None) is None
    try:
        got = read_table("t.csv", text, 3)
    except InputError as e:
        got = str(e)
    try:
        want = cell_by_cell("t.csv", text, 3, None, monkeypatch)
    except InputError as e:
        want = str(e)
    assert got == want


def test_a_header_that_names_too_few_columns_is_refused_as_before(monkeypatch):
    text = "x\ty\tz\n1,2,3\n4,5,6\n"  # tabs in the header, commas below
    with pytest.raises(InputError) as fast:
        read_table("t.csv", text, 3)
    with pytest.raises(InputError) as slow:
        cell_by_cell("t.csv", text, 3, None, monkeypatch)
    assert str(fast.value) == str(slow.value) and "header" in str(fast.value)


decimal = st.builds(lambda sign, whole, frac, dot: f"{sign}{whole}{'.' if dot else ''}{frac if dot else ''}",
                    st.sampled_from(["", "-", "+"]), st.text("0123456789", min_size=1, max_size=6),
                    st.text("0123456789", max_size=6), st.booleans())


@given(st.lists(st.tuples(decimal, decimal, decimal), min_size=1, max_size=40), st.sampled_from([",", ";", "\t"]),
       st.booleans(), st.booleans())
def test_any_table_of_plain_decimals_is_read_exactly(rows, sep, header, crlf):
    end = "\r\n" if crlf else "\n"
    text = (f"x{sep}y{sep}z{end}" if header else "") + end.join(sep.join(r) for r in rows) + end
    points, _ = read_table("t.csv", text, 3)
    assert isinstance(points, DecimalPoints)
    assert list(points) == [tuple(Fraction(v) for v in r) for r in rows]


def test_a_repeated_place_is_found_as_the_point_by_point_search_finds_it():
    rng = random.Random(5)
    for _ in range(200):
        n = rng.randint(1, 30)
        cols = [[rng.randint(-3, 3) for _ in range(n)] for _ in range(3)]
        dp = DecimalPoints(cols, [1, 2, 0])
        brute = next(((min(i for i in range(j) if dp[i][:2] == dp[j][:2]), j) for j in range(n)
                      if any(dp[i][:2] == dp[j][:2] for i in range(j))), None)
        assert dp.first_repeat() == brute == first_repeat(tuple(dp))


def test_floats_are_the_nearest_even_beyond_two_to_the_53(tmp_path):
    big = [2 ** 53 + 1, 10 ** 18 - 1, -(10 ** 17 + 3), 7]
    dp = DecimalPoints([big, big, big], [0, 3, 18])
    for j, e in enumerate((0, 3, 18)):
        assert dp.floats(j).tolist() == [float(Fraction(v, 10 ** e)) for v in big]


def test_the_hull_of_many_integer_points_is_the_hull_of_all():
    rng = random.Random(3)
    for t in range(60):
        n = rng.choice([70, 500, 3000])
        span = rng.choice([3, 50, 10 ** 6, 2 ** 31, 2 ** 40])
        xs = [rng.randint(-span, span) for _ in range(n)]
        ys = [2 * x + 1 for x in xs] if t % 3 == 0 else [rng.randint(-span, span) for _ in range(n)]
        assert convex_hull_integers(xs, ys) == convex_hull(list(zip(xs, ys)))


def test_a_fit_from_a_table_is_the_fit_from_the_same_points_as_fractions(tmp_path):
    rng = np.random.default_rng(7)
    keys = rng.choice(200 * 150, 2500, replace=False)
    x, y = keys // 150 * Fraction(1, 2), keys % 150 * Fraction(2, 5)
    pts = [(Fraction(int(a.numerator), int(a.denominator)), Fraction(int(b.numerator), int(b.denominator)),
            Fraction(int(rng.integers(-5000, 5000)), 1000)) for a, b in zip(x, y)]
    path = tmp_path / "scan.csv"
    path.write_text("x,y,z\n" + "".join(f"{float(a):.1f},{float(b):.1f},{float(c):.3f}\n" for a, b, c in pts))
    read = read_scattered_points(path)
    assert isinstance(read.points, DecimalPoints) and list(read.points) == pts
    fast, slow = fit_surface(read.points, (3, 2)), fit_surface(pts, (3, 2))
    assert fast.coefficients == slow.coefficients and fast.hull == slow.hull
    assert fast.residual_denominator == slow.residual_denominator
    assert fast.float_residuals.tolist() == slow.float_residuals.tolist()
    assert fast.amplification == pytest.approx(slow.amplification, rel=1e-12)
    with pytest.raises(InputError, match=r"points 3 and 2501 are both at \(x, y\)"):
        path.write_text(path.read_text() + f"{float(pts[2][0]):.1f},{float(pts[2][1]):.1f},1.5\n")
        read_scattered_points(path)


def test_a_grid_read_in_whole_columns_is_the_grid_of_its_points(tmp_path, monkeypatch):
    from lagsym.grid import grid_from_points
    from lagsym.io import read_points
    from lagsym.io.decimals import grid_of_columns

    rng = random.Random(2)
    rows = [(f"{x * 0.25:.2f}", f"{-y * 1.5:.1f}", f"{rng.uniform(-9, 9):.4f}") for x in range(7) for y in range(5)]
    rng.shuffle(rows)
    path = tmp_path / "grid.csv"
    path.write_text("x,y,z\n" + "".join(",".join(r) + "\n" for r in rows))
    grid = read_points(path)
    want = grid_from_points([tuple(Fraction(v) for v in r) for r in rows], source=str(path))
    assert (grid.x, grid.y, grid.z, grid.shape) == (want.x, want.y, want.z, (7, 5))
    # A place missing and a place twice: the grid of points says which, as it does for any points.
    for broken in (rows[:-1] + [rows[0][:2] + ("1",)], rows[:-1]):
        path.write_text("x,y,z\n" + "".join(",".join(r) + "\n" for r in broken))
        points, _ = read_table(str(path), path.read_text(), 3)
        assert grid_of_columns(points, str(path), None) is None
        with pytest.raises(InputError) as fast:
            read_points(path)
        with pytest.raises(InputError) as slow:
            grid_from_points([tuple(Fraction(v) for v in r) for r in broken], source=str(path))
        assert str(fast.value) == str(slow.value)
