"""Tables of plain decimals read in whole columns: the points as integers over a power of ten, still exact.

A scanner or a CMM writes a million lines of ``51.182,44.300,8.370``.  Made
one ``Fraction`` at a time those take most of a fit's time; here the text of
the data lines is read as bytes, all at once, into the integers ``n`` of
``n / 10**e`` for each column, and :class:`DecimalPoints` hands them on:

- as a sequence of ``(x, y, z)`` tuples of Fractions, as every other reader
  gives its points, made only when asked for;
- as those integers and their denominator (:meth:`DecimalPoints.integers`),
  for the exact fit;
- as floats, each the nearest to its exact value (:meth:`DecimalPoints.floats`).

Only lines of plain decimals (``-12.5``, ``+.5``, ``7.``; no exponent, no
rational, at most 18 digits) with one separator between cells and nothing
else are read here; :func:`parse_plain` says None to anything else, and the
table reader then reads the file cell by cell as before, with its messages.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from fractions import Fraction

__all__ = ["DecimalPoints", "parse_plain", "first_repeat", "grid_of_columns", "column_floats", "MAX_DIGITS"]

MAX_DIGITS = 18  # digits of a cell read here: 10**18 fits a signed 64-bit integer
_CHUNK = 1 << 22  # bytes of text read at a time: the index arrays stay a few times this, not the file's size
_DIGIT0, _DOT, _MINUS, _PLUS, _NEWLINE = 48, 46, 45, 43, 10


class DecimalPoints(Sequence):
    """Points read from decimals: column ``j`` holds the integers ``n`` of ``n / 10**exponents[j]``.

    A sequence of tuples of Fractions, equal to what the cell-by-cell reader gives.

    Examples
    --------
    >>> p = DecimalPoints([[15, -20], [3, 40], [100, 7]], [1, 0, 2])
    >>> len(p), p[1]
    (2, (Fraction(-2, 1), Fraction(40, 1), Fraction(7, 100)))
    >>> p.integers(0), p.floats(2).tolist()
    (([3, -4], 2), [1.0, 0.07])
    """

    __slots__ = ("_columns", "_exponents")

    def __init__(self, columns, exponents):
        import numpy as np

        cols = tuple(np.array(c, dtype=np.int64) for c in columns)
        for c in cols:
            c.setflags(write=False)
        if len({len(c) for c in cols}) > 1 or len(cols) != len(exponents):
            raise ValueError("DecimalPoints: columns of different lengths, or not one exponent a column")
        self._columns, self._exponents = cols, tuple(int(e) for e in exponents)

    @property
    def columns(self) -> tuple:
        """The columns' integers (read-only int64 arrays)."""
        return self._columns

    @property
    def exponents(self) -> tuple[int, ...]:
        """Each column's power of ten: its values are its integers divided by ``10**e``."""
        return self._exponents

    def __len__(self) -> int:
        return len(self._columns[0]) if self._columns else 0

    def __getitem__(self, index):
        if isinstance(index, slice):
            return tuple(self[k] for k in range(*index.indices(len(self))))
        return tuple(Fraction(int(c[index]), 10 ** e) for c, e in zip(self._columns, self._exponents))

    def __iter__(self):
        tens = [10 ** e for e in self._exponents]
        for row in zip(*(c.tolist() for c in self._columns)):
            yield tuple(Fraction(v, t) for v, t in zip(row, tens))

    def __eq__(self, other):
        if isinstance(other, DecimalPoints):
            return len(self) == len(other) and all(a == b for a, b in zip(self, other))
        if isinstance(other, (tuple, list)):
            return len(self) == len(other) and all(a == tuple(b) for a, b in zip(self, other))
        return NotImplemented

    __hash__ = None

    def __repr__(self) -> str:
        return f"DecimalPoints({len(self)} points, exponents {self._exponents})"

    def integers(self, j: int) -> tuple[list[int], int]:
        """Column ``j`` as Python integers over their least common denominator ``d``: value ``n / d``."""
        import math

        import numpy as np

        c, d = self._columns[j], 10 ** self._exponents[j]
        g = math.gcd(int(np.gcd.reduce(c)) if len(c) else 0, d) or 1
        return (c // g).tolist(), d // g

    def floats(self, j: int):
        """Column ``j`` in floats, each the float nearest its exact value (as ``float(Fraction)``)."""
        import numpy as np

        c, e = self._columns[j], self._exponents[j]
        if e <= 22 and (len(c) == 0 or int(np.abs(c).max()) <= 2 ** 53):
            return c.astype(float) / 10.0 ** e  # both exact, so the one division is correctly rounded
        d = 10 ** e
        return np.array([v / d for v in c.tolist()], dtype=float)  # Python's int division rounds correctly

    def first_repeat(self) -> tuple[int, int] | None:
        """:func:`first_repeat` in whole columns."""
        import numpy as np

        x, y = self._columns[0], self._columns[1]
        order = np.lexsort((np.arange(len(x)), y, x))
        same = (x[order[1:]] == x[order[:-1]]) & (y[order[1:]] == y[order[:-1]])
        if not same.any():
            return None
        j = int(order[1:][same].min())
        i = int(np.flatnonzero((x == x[j]) & (y == y[j]))[0])
        return i, j


def first_repeat(points) -> tuple[int, int] | None:
    """``(i, j)``, 0-based: the first point ``j`` at the ``(x, y)`` of an earlier one, ``i`` the earliest of those;
    None when no two points share an ``(x, y)``.

    Examples
    --------
    >>> from fractions import Fraction as F
    >>> first_repeat([(F(0), F(1), F(5)), (F(2), F(1), F(5)), (F(0), F(1), F(6))])
    (0, 2)
    >>> first_repeat(DecimalPoints([[0, 2, 0], [1, 1, 1], [5, 5, 6]], [0, 0, 0]))
    (0, 2)
    """
    if isinstance(points, DecimalPoints):
        return points.first_repeat()
    seen: dict[tuple[int, int, int, int], int] = {}
    for idx, pt in enumerate(points):
        # the lowest-terms integers: a Fraction's own hash takes a modular inverse, most of this loop's time
        key = (pt[0].numerator, pt[0].denominator, pt[1].numerator, pt[1].denominator)
        if key in seen:
            return seen[key], idx
        seen[key] = idx
    return None


def grid_of_columns(points: DecimalPoints, source: str, units: str | None):
    """The control grid of points read in whole columns, arranged from their integers; None where they do not make
    one (repeated or missing places): :func:`lagsym.grid.grid_from_points` then says which, as for any points.

    Examples
    --------
    >>> g = grid_of_columns(DecimalPoints([[3, 1, 3, 1], [2, 2, 3, 3], [15, 7, 18, 10]], [0, 0, 0]), "p.csv", None)
    >>> g.x, g.z
    ((Fraction(1, 1), Fraction(3, 1)), ((Fraction(7, 1), Fraction(10, 1)), (Fraction(15, 1), Fraction(18, 1))))
    """
    import numpy as np

    from ..grid import ControlGrid

    x, y, z = points.columns
    ux, ix = np.unique(x, return_inverse=True)
    uy, iy = np.unique(y, return_inverse=True)
    nx, ny = len(ux), len(uy)
    if nx < 2 or ny < 2 or nx * ny != len(z):
        return None
    at = ix * ny + iy
    filled = np.zeros(nx * ny, dtype=bool)
    filled[at] = True
    if not filled.all():  # as many points as places, so a place missed is a place repeated
        return None
    heights = np.empty(nx * ny, dtype=np.int64)
    heights[at] = z
    (tx, ty, tz), flat = (10 ** e for e in points.exponents), heights.tolist()
    return ControlGrid(x=tuple(Fraction(v, tx) for v in ux.tolist()), y=tuple(Fraction(v, ty) for v in uy.tolist()),
                       z=tuple(tuple(Fraction(v, tz) for v in flat[i * ny:(i + 1) * ny]) for i in range(nx)),
                       source=source, units=units)


def column_floats(points, j: int):
    """Coordinate ``j`` of ``points`` as a float array: whole columns for :class:`DecimalPoints`, else one at a time."""
    import numpy as np

    if isinstance(points, DecimalPoints):
        return points.floats(j)
    return np.array([float(p[j]) for p in points], dtype=float)


def parse_plain(body: str, separator: str, width: int) -> tuple[list, list[int]] | None:
    """The cells of ``body`` (data lines only, each ``width`` plain decimals split by ``separator``) as columns of
    integers and their powers of ten; None unless every line is exactly that."""
    import numpy as np

    if not body.isascii():
        return None
    raw = body.encode("ascii")
    if not raw.endswith(b"\n"):
        raw += b"\n"
    parts, start = [], 0
    while start < len(raw):
        stop = raw.rfind(b"\n", start, start + _CHUNK) + 1 if start + _CHUNK < len(raw) else len(raw)
        if stop <= start:
            return None  # a line longer than a chunk is no line of numbers
        found = _cells(np.frombuffer(raw, np.uint8, stop - start, start), ord(separator), width)
        if found is None:
            return None
        parts.append(found)
        start = stop
    mantissas = np.concatenate([m for m, _, _ in parts])
    decimals = np.concatenate([d for _, d, _ in parts])
    digits = np.concatenate([n for _, _, n in parts])
    columns, exponents = [], []
    for j in range(width):
        m, d, n = mantissas[j::width], decimals[j::width], digits[j::width]
        e = int(d.max())
        if int((n + (e - d)).max()) > MAX_DIGITS:
            return None  # scaled to the column's decimals, a cell would not fit 64 bits
        columns.append(m * _pow10()[e - d])
        exponents.append(e)
    return columns, exponents


def _cells(b, sep: int, width: int):
    """Each cell's integer (sign included), its decimals and its digits, in order; None unless every line is
    ``width`` plain decimals."""
    import numpy as np

    end = b == _NEWLINE
    bound = end | (b == sep)
    digit = (b >= _DIGIT0) & (b <= _DIGIT0 + 9)
    dot, minus, plus = b == _DOT, b == _MINUS, b == _PLUS
    if not (digit | dot | minus | plus | bound).all():
        return None
    ends = np.flatnonzero(bound)
    if len(ends) % width or not (end[ends].reshape(-1, width) == (np.arange(width) == width - 1)).all():
        return None  # a line with more or fewer cells
    cell = np.cumsum(bound) - bound  # each byte's cell: the bounds before it
    starts = np.concatenate(([0], ends[:-1] + 1))
    signs = np.flatnonzero(minus | plus)
    if (signs != starts[cell[signs]]).any():
        return None  # a sign inside a cell
    dots = np.flatnonzero(dot)
    if (np.diff(cell[dots]) == 0).any():
        return None  # two decimal points in a cell
    at = np.flatnonzero(digit)
    of = cell[at]
    count = np.bincount(of, minlength=len(ends))
    if count.min() == 0 or count.max() > MAX_DIGITS:
        return None  # an empty cell, a sign or point alone, or too many digits
    first = np.cumsum(count) - count
    place = count[of] - 1 - (np.arange(len(at)) - first[of])
    mantissa = np.add.reduceat((b[at] - _DIGIT0).astype(np.int64) * _pow10()[place], first)
    point = np.full(len(ends), len(b))
    point[cell[dots]] = dots
    decimals = np.bincount(of[at > point[of]], minlength=len(ends))
    negative = np.zeros(len(ends), bool)
    negative[cell[np.flatnonzero(minus)]] = True
    return np.where(negative, -mantissa, mantissa), decimals, count


@functools.cache
def _pow10():
    """``10**k`` as int64 for ``k`` from 0 to 18, to index with an array of ``k``."""
    import numpy as np

    return np.array([10 ** k for k in range(MAX_DIGITS + 1)], dtype=np.int64)
