"""Control points arranged the way the paper arranges them.

A :class:`ControlGrid` holds the nodes ``x[0] < ... < x[n-1]`` and
``y[0] < ... < y[m-1]`` and the heights ``z[i][k]`` at ``(x[i], y[k])``, the
paper's ``p_ik``.  A :class:`CurvePoints` holds the nodes and values of a 1-D
curve.  All values are exact :class:`fractions.Fraction`; every check on the
points happens here, once.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property
from typing import TYPE_CHECKING

from .errors import GridError, InputError
from .values import choice

if TYPE_CHECKING:
    import numpy as np


def _readonly(values):
    # NumPy is imported with the first array asked for: the exact equation needs none of it.
    from ._arrays import readonly

    return readonly(values)

__all__ = ["ControlGrid", "CurvePoints", "grid_from_points", "grid_from_table", "curve_from_points",
           "SnapReport", "snap_points"]


def _fmt(v: Fraction) -> str:
    """Show an exact number the way a user typed it where possible."""
    if v.denominator == 1:
        return str(v.numerator)
    d = v.denominator
    while d % 2 == 0:
        d //= 2
    while d % 5 == 0:
        d //= 5
    if d == 1:  # a terminating decimal
        from decimal import Decimal, localcontext

        with localcontext() as ctx:
            ctx.prec = 200
            return format(Decimal(v.numerator) / Decimal(v.denominator), "f")
    return f"{v.numerator}/{v.denominator}"


@dataclass(frozen=True)
class ControlGrid:
    """A rectangular grid of control points with exact coordinates.

    Attributes
    ----------
    x, y : tuple of Fraction
        Strictly increasing nodes in each direction.
    z : tuple of tuple of Fraction
        ``z[i][k]`` is the height at ``(x[i], y[k])``.
    source : str
        Where the points came from (a file name), for messages.
    units : str or None
        The units of the coordinates where the file says them (``"mm"`` or
        ``"inch"``: a JSON ``"units"`` key or a header such as ``X (mm)``).
    amplification : float or None
        For heights computed from other, measured points (a least-squares
        fit's values at its nodes): how much the surface can amplify errors
        in those points.  None for measured heights, whose amplification is
        the nodes' own (:func:`lagsym.conditioning.amplification`).
    """

    x: tuple[Fraction, ...]
    y: tuple[Fraction, ...]
    z: tuple[tuple[Fraction, ...], ...]
    source: str = field(default="<points>", compare=False)
    units: str | None = field(default=None, compare=False)
    amplification: float | None = field(default=None, compare=False)

    def __post_init__(self):
        _check_units(self.units)

    @property
    def shape(self) -> tuple[int, int]:
        """``(n, m)``: the number of nodes in x and in y."""
        return len(self.x), len(self.y)

    @property
    def degree(self) -> tuple[int, int]:
        """Degree of the interpolating polynomial in x and in y."""
        return len(self.x) - 1, len(self.y) - 1

    @property
    def bounds(self) -> tuple[Fraction, Fraction, Fraction, Fraction]:
        """``(x0, x1, y0, y1)``: the box spanned by the control points."""
        return self.x[0], self.x[-1], self.y[0], self.y[-1]

    def points(self) -> list[tuple[Fraction, Fraction, Fraction]]:
        """The control points as ``(x, y, z)`` triples, x-major like the paper's p_ik."""
        return [(xi, yk, self.z[i][k]) for i, xi in enumerate(self.x) for k, yk in enumerate(self.y)]

    @cached_property
    def x_array(self) -> np.ndarray:
        """The x nodes as a read-only float array."""
        return _readonly(self.x)

    @cached_property
    def y_array(self) -> np.ndarray:
        """The y nodes as a read-only float array."""
        return _readonly(self.y)

    @cached_property
    def z_array(self) -> np.ndarray:
        """The heights as a read-only ``(n, m)`` float array."""
        return _readonly(self.z)

    def z_range(self) -> tuple[Fraction, Fraction]:
        """Smallest and largest control height."""
        flat = [v for row in self.z for v in row]
        return min(flat), max(flat)

    def with_z(self, z: Sequence[Sequence[Fraction]]) -> ControlGrid:
        """The same nodes with other heights."""
        return grid_from_table(self.x, self.y, z, source=self.source, units=self.units)


POINT_UNITS = ("mm", "inch")  # the units a points file may name (None: it names none)


def _check_units(units) -> None:
    if units is not None:
        choice(units, POINT_UNITS, "units")


@dataclass(frozen=True)
class CurvePoints:
    """Nodes ``x[0] < ... < x[n-1]`` and values ``y[i]`` of a 1-D curve, exact (``units`` as for a grid)."""

    x: tuple[Fraction, ...]
    y: tuple[Fraction, ...]
    source: str = field(default="<points>", compare=False)
    units: str | None = field(default=None, compare=False)

    def __post_init__(self):
        _check_units(self.units)

    @property
    def degree(self) -> int:
        """Degree of the interpolating polynomial."""
        return len(self.x) - 1

    @cached_property
    def x_array(self) -> np.ndarray:
        """The nodes as a read-only float array."""
        return _readonly(self.x)

    @cached_property
    def y_array(self) -> np.ndarray:
        """The values as a read-only float array."""
        return _readonly(self.y)


def _exact(v, where: str) -> Fraction:
    if isinstance(v, bool) or not isinstance(v, (int, Fraction)):
        raise InputError(f"{where}: {v!r} is not an exact number")
    return Fraction(v)


def _check_axis(nodes: Sequence[Fraction], name: str, source: str) -> None:
    seen: dict[Fraction, int] = {}
    for idx, v in enumerate(nodes):
        if v in seen:
            raise GridError(
                f"{source}: repeated node {name} = {_fmt(v)} (entries {seen[v]} and {idx}); "
                f"the nodes in {name} must all differ"
            )
        seen[v] = idx


def grid_from_table(
    x: Sequence[Fraction], y: Sequence[Fraction], z: Sequence[Sequence[Fraction]], source: str = "<points>",
    units: str | None = None,
) -> ControlGrid:
    """Build a grid from node lists and a height table ``z[i][k]`` at ``(x[i], y[k])``.

    The nodes may come in increasing or decreasing order, unevenly spaced; the
    grid is stored with increasing nodes.

    Examples
    --------
    >>> g = grid_from_table([3, 1], [0, 1], [[30, 31], [10, 11]])
    >>> g.x, g.z[0]
    ((Fraction(1, 1), Fraction(3, 1)), (Fraction(10, 1), Fraction(11, 1)))
    """
    xs = [_exact(v, f"{source}: x[{i}]") for i, v in enumerate(x)]
    ys = [_exact(v, f"{source}: y[{k}]") for k, v in enumerate(y)]
    if len(xs) < 2 or len(ys) < 2:
        raise GridError(
            f"{source}: a surface needs at least 2 nodes in each direction, got {len(xs)} in x and {len(ys)} in y"
        )
    _check_axis(xs, "x", source)
    _check_axis(ys, "y", source)
    if len(z) != len(xs):
        raise GridError(f"{source}: z has {len(z)} rows but x has {len(xs)} nodes")
    rows = []
    for i, row in enumerate(z):
        if isinstance(row, (str, bytes)) or not isinstance(row, Sequence):
            raise GridError(f"{source}: z[{i}] = {row!r} is not a row of heights")
        if len(row) != len(ys):
            raise GridError(f"{source}: z[{i}] has {len(row)} heights but y has {len(ys)} nodes")
        rows.append([_exact(v, f"{source}: z[{i}][{k}]") for k, v in enumerate(row)])
    ix = sorted(range(len(xs)), key=xs.__getitem__)
    iy = sorted(range(len(ys)), key=ys.__getitem__)
    return ControlGrid(
        x=tuple(xs[i] for i in ix),
        y=tuple(ys[k] for k in iy),
        z=tuple(tuple(rows[i][k] for k in iy) for i in ix),
        source=source,
        units=units,
    )


def grid_from_points(points: Sequence[Sequence[Fraction]], source: str = "<points>",
                     units: str | None = None) -> ControlGrid:
    """Arrange ``(x, y, z)`` triples given in any order into the paper's matrix ``p_ik``.

    Examples
    --------
    >>> g = grid_from_points([(1, 2, 7), (3, 3, 18), (1, 3, 10), (3, 2, 15)])
    >>> g.shape, g.z
    ((2, 2), ((Fraction(7, 1), Fraction(10, 1)), (Fraction(15, 1), Fraction(18, 1))))
    """
    if len(points) == 0:
        raise GridError(f"{source}: no control points")
    heights: dict[tuple[Fraction, Fraction], tuple[Fraction, int]] = {}
    for idx, p in enumerate(points):
        if len(p) != 3:
            raise InputError(f"{source}: point {idx + 1} {_show(p)} should be [x, y, z]")
        px, py, pz = (_exact(v, f"{source}: point {idx + 1}") for v in p)
        if (px, py) in heights:
            first = heights[(px, py)][1]
            raise GridError(
                f"{source}: duplicated grid point ({_fmt(px)}, {_fmt(py)}) at points {first + 1} and {idx + 1}"
            )
        heights[(px, py)] = (pz, idx)
    xs = sorted({k[0] for k in heights})
    ys = sorted({k[1] for k in heights})
    if len(xs) < 2 or len(ys) < 2:
        axis, vals = ("x", xs) if len(xs) < 2 else ("y", ys)
        raise GridError(
            f"{source}: all {len(points)} points have {axis} = {_fmt(vals[0])}: a surface needs at least "
            f"2 distinct x and 2 distinct y (a single row is a curve: use 'lagsym curve')"
        )
    z = []
    for xi in xs:
        row = []
        for yk in ys:
            if (xi, yk) not in heights:
                raise GridError(
                    f"{source}: no point at (x, y) = ({_fmt(xi)}, {_fmt(yk)}): the {len(points)} points do not "
                    f"form a rectangular grid over {len(xs)} x-values and {len(ys)} y-values{_jitter_hint(xs, ys)}"
                )
            row.append(heights[(xi, yk)][0])
        z.append(tuple(row))
    return ControlGrid(x=tuple(xs), y=tuple(ys), z=tuple(z), source=source, units=units)


def _jitter_hint(xs: list[Fraction], ys: list[Fraction]) -> str:
    """A hint when two node values are so close that they are one node measured twice (CMM jitter)."""
    for name, vals in (("x", xs), ("y", ys)):
        gap, a, b = min((vals[j + 1] - vals[j], vals[j], vals[j + 1]) for j in range(len(vals) - 1))
        if gap * 10**6 < vals[-1] - vals[0]:
            return (f"; {name} = {_fmt(a)} and {name} = {_fmt(b)} differ by only {float(gap):.3g}: if they are one "
                    f"node measured twice, snap them together with --snap {_tolerance_for(gap)}")
    return ""


def _tolerance_for(gap: Fraction) -> str:
    exponent = 0
    while Fraction(10) ** exponent > gap * 10:
        exponent -= 1
    return f"1e{exponent + 2}"


def curve_from_points(points: Sequence[Sequence[Fraction]], source: str = "<points>",
                      units: str | None = None) -> CurvePoints:
    """Sort ``(x, y)`` pairs by x for a 1-D Lagrange curve.

    Examples
    --------
    >>> curve_from_points([(3, 1), (1, 1), (2, 3)]).x
    (Fraction(1, 1), Fraction(2, 1), Fraction(3, 1))
    """
    if len(points) < 2:
        raise GridError(f"{source}: a curve needs at least 2 points, got {len(points)}")
    seen: dict[Fraction, int] = {}
    pairs = []
    for idx, p in enumerate(points):
        if len(p) != 2:
            raise InputError(f"{source}: point {idx + 1} {_show(p)} should be [x, y]")
        px, py = (_exact(v, f"{source}: point {idx + 1}") for v in p)
        if px in seen:
            raise GridError(
                f"{source}: x = {_fmt(px)} repeats (points {seen[px] + 1} and {idx + 1}); a Lagrange curve "
                f"needs x to increase or decrease strictly (the paper's limitation 1)"
            )
        seen[px] = idx
        pairs.append((px, py))
    pairs.sort()
    return CurvePoints(x=tuple(p[0] for p in pairs), y=tuple(p[1] for p in pairs), source=source, units=units)


def _show(p) -> str:
    try:
        return "[" + ", ".join(_fmt(v) if isinstance(v, (int, Fraction)) else repr(v) for v in p) + "]"
    except TypeError:
        return repr(p)


@dataclass(frozen=True)
class SnapReport:
    """What :func:`snap_points` moved.

    Attributes
    ----------
    tolerance : Fraction
        Node values closer than this were taken as one node.
    moved : int
        How many points had a coordinate moved.
    largest : Fraction
        The largest move of one coordinate.
    nodes : tuple of int
        The number of distinct node values per snapped axis afterwards.
    """

    tolerance: Fraction
    moved: int
    largest: Fraction
    nodes: tuple[int, ...]

    def text(self, source: str) -> str:
        """One line saying it."""
        if not self.moved:
            return f"{source}: --snap {float(self.tolerance):g}: no point needed moving"
        axes = " x ".join(str(n) for n in self.nodes)
        return (f"{source}: --snap {float(self.tolerance):g}: moved {self.moved} point(s) onto {axes} nodes, "
                f"the largest move {float(self.largest):.3g}")


def _simplest(lo: Fraction, hi: Fraction) -> Fraction:
    """The decimal with the fewest digits in ``[lo, hi]``, nearest the middle: 3 for 2.9999999999999996..3.0000000000000004."""
    if lo == hi:
        return lo
    mid = (lo + hi) / 2
    step = Fraction(1)
    while step > (hi - lo) / 10:
        first, last = -((-lo) // step), hi // step
        if first <= last:
            return min(max(round(mid / step), first), last) * step
        step /= 10
    return mid


def _snap_axis(values: list[Fraction], tolerance: Fraction, name: str, source: str) -> dict[Fraction, Fraction]:
    groups: list[list[Fraction]] = []
    for v in sorted(set(values)):
        if groups and v - groups[-1][-1] <= tolerance:
            groups[-1].append(v)
        else:
            groups.append([v])
    target = {}
    for g in groups:
        if g[-1] - g[0] > tolerance:
            raise GridError(f"{source}: --snap {_fmt(tolerance)}: the {name} values from {_fmt(g[0])} to {_fmt(g[-1])} "
                            f"chain together but span more than {_fmt(tolerance)}; give a smaller --snap")
        node = _simplest(g[0], g[-1])
        target.update({v: node for v in g})
    return target


def snap_points(points: Sequence[Sequence[Fraction]], tolerance, axes: int = 2,
                source: str = "<points>") -> tuple[list[tuple[Fraction, ...]], SnapReport]:
    """Move node coordinates that differ by at most ``tolerance`` onto one node (measured grids, CMM jitter).

    The first ``axes`` coordinates of each point are snapped (x and y of a
    surface, x of a curve); heights never move.  The node a group moves to
    is the shortest decimal within the group's range.

    Examples
    --------
    >>> pts = [(Fraction("2.9999999999999996"), 1, 5), (3, 2, 6), (1, 1, 7), (1, 2, 8)]
    >>> snapped, report = snap_points(pts, Fraction(1, 10**9))
    >>> snapped[0][0], report.moved, report.largest
    (Fraction(3, 1), 1, Fraction(1, 2500000000000000))
    """
    from .values import as_exact

    tol = as_exact(tolerance, "--snap")
    if tol <= 0:
        raise InputError(f"--snap {_fmt(tol)} must be a positive tolerance")
    maps = [_snap_axis([Fraction(p[a]) for p in points], tol, "xy"[a], source) for a in range(axes)]
    out, moved, largest = [], 0, Fraction(0)
    for p in points:
        q = tuple(maps[a][Fraction(v)] if a < axes else v for a, v in enumerate(p))
        shifts = [abs(q[a] - Fraction(p[a])) for a in range(axes)]
        if any(shifts):
            moved += 1
            largest = max(largest, *shifts)
        out.append(q)
    _check_not_joined(points, out, axes, tol, source)
    nodes = tuple(len(set(m.values())) for m in maps)
    return out, SnapReport(tolerance=tol, moved=moved, largest=largest, nodes=nodes)


def _check_not_joined(points, snapped, axes: int, tol: Fraction, source: str) -> None:
    """Refuse a snap that takes two points at different places to one place: two heights for one grid point."""
    first: dict[tuple, int] = {}
    for i, q in enumerate(snapped):
        j = first.setdefault(q[:axes], i)
        if j != i and any(Fraction(points[j][a]) != Fraction(points[i][a]) for a in range(axes)):
            where = lambda p: ", ".join(_fmt(Fraction(v)) for v in p[:axes])  # noqa: E731
            raise GridError(f"{source}: --snap {float(tol):g} takes points {j + 1} ({where(points[j])}) and {i + 1} "
                            f"({where(points[i])}) to one place ({where(q)}): a tolerance wider than the nodes' "
                            f"spacing (give a smaller one), or one place measured twice (average the two first)")
