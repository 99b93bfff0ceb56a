"""Where and how densely to sample a surface, and the sampled data, whole or in streamed blocks.

A :class:`SampleGrid` is a regular ``nx`` x ``ny`` grid over a box, with exact
box corners; :func:`sample_grid` builds one from counts or from a spacing and
checks it against the control box; :func:`axis_lines` builds each axis of
it, exactly (comparisons and pictures take their axes from it too).
:func:`sample` returns the whole grid of heights; :func:`iter_blocks`
yields it a block of x-rows at a time, so a writer can stream any number of
points in bounded memory.

Points are ordered x-major, like the paper's ``p_ik``: row ``i * ny + j`` of a
flattened sample is ``(xs[i], ys[j], F(xs[i], ys[j]))``.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from typing import NamedTuple

import numpy as np

from .errors import InputError
from .evaluate import surface_evaluator
from .evaluate.engine import Engine, current_engine
from .evaluate.product import grid_product
from .values import as_exact

__all__ = [
    "MAX_AXIS_POINTS",
    "MAX_POINTS",
    "BLOCK_POINTS",
    "Box",
    "SampleGrid",
    "Sample",
    "Block",
    "axis_lines",
    "sample_grid",
    "sample",
    "iter_blocks",
]

MAX_AXIS_POINTS = 10_000_000  # grid lines per axis; the coordinates alone then take 80 MB
MAX_POINTS = 100_000_000  # points of one sample by default: minutes of work and gigabytes of CSV
BLOCK_POINTS = 1 << 20  # points per streamed block: about 24 MB of x, y, z


def _show(v: Fraction) -> str:
    return str(v.numerator) if v.denominator == 1 else f"{float(v):.10g}"


@dataclass(frozen=True)
class Box:
    """An axis-parallel box ``[x0, x1] x [y0, y1]`` with exact corners."""

    x0: Fraction
    x1: Fraction
    y0: Fraction
    y1: Fraction

    def contains(self, other: Box) -> bool:
        """Whether ``other`` lies inside this box (edges included)."""
        return self.x0 <= other.x0 and other.x1 <= self.x1 and self.y0 <= other.y0 and other.y1 <= self.y1

    def floats(self) -> tuple[float, float, float, float]:
        """``(x0, x1, y0, y1)`` as floats."""
        return float(self.x0), float(self.x1), float(self.y0), float(self.y1)


def axis_lines(a: Fraction, b: Fraction, n: int) -> np.ndarray:
    """``n`` evenly spaced values from ``a`` to ``b``, ends included, each the float nearest the exact value.

    This is the one builder of sample axes (sample grids, comparisons and
    pictures all use it).  Each line ``a + (b - a) k / (n - 1)`` is computed
    exactly and rounded once, so the end points are ``float(a)`` and
    ``float(b)`` to the last bit, and a line that falls on a control node is
    that node.  The array is read-only.

    Parameters
    ----------
    a, b : Fraction
        The exact ends.
    n : int
        Number of lines, at least 1 (one line is ``a`` alone).

    Examples
    --------
    >>> axis_lines(Fraction(0), Fraction(3, 10), 4).tolist()
    [0.0, 0.1, 0.2, 0.3]
    """
    if n == 1:
        out = np.array([float(a)])
    else:
        # x_i = (a (n-1-i) + b i) / (n-1) = (p + q i) / d over integers
        d = a.denominator * b.denominator * (n - 1)
        p = a.numerator * b.denominator * (n - 1)
        q = b.numerator * a.denominator - a.numerator * b.denominator
        top = max(abs(p), abs(p + q * (n - 1)))
        i = np.arange(n, dtype=np.int64)
        if top < 2**53 and d < 2**53 and abs(q) * n < 2**62:
            # integers below 2**53 are exact floats, and one IEEE division rounds correctly
            out = (p + q * i).astype(float) / float(d)
        else:
            out = np.array([float(Fraction(p + q * k, d)) for k in range(n)])
    out.setflags(write=False)
    return out


@dataclass(frozen=True)
class SampleGrid:
    """A regular grid of ``nx`` x ``ny`` sample points over ``box``, edges included.

    Attributes
    ----------
    box : Box
        The sampled box.
    nx, ny : int
        Number of grid lines in x and in y.
    """

    box: Box
    nx: int
    ny: int

    @property
    def size(self) -> int:
        """Number of points, ``nx * ny``."""
        return self.nx * self.ny

    @property
    def spacing(self) -> tuple[Fraction, Fraction]:
        """Exact distance between neighbouring grid lines in x and in y."""
        b = self.box
        return (b.x1 - b.x0) / max(self.nx - 1, 1), (b.y1 - b.y0) / max(self.ny - 1, 1)

    @cached_property
    def xs(self) -> np.ndarray:
        """The x grid lines, read-only, each correctly rounded."""
        return axis_lines(self.box.x0, self.box.x1, self.nx)

    @cached_property
    def ys(self) -> np.ndarray:
        """The y grid lines, read-only, each correctly rounded."""
        return axis_lines(self.box.y0, self.box.y1, self.ny)


class Sample(NamedTuple):
    """A sampled surface: ``z[i, j] = F(x[i, j], y[i, j])`` with ``x[i, j] = xs[i]``, ``y[i, j] = ys[j]``.

    All three arrays are read-only with shape ``(nx, ny)`` (NumPy's
    ``meshgrid(..., indexing="ij")``); ``x`` and ``y`` are broadcast views that
    take no memory of their own.
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray


class Block(NamedTuple):
    """Rows ``start .. start + len(xs) - 1`` of a sample: ``z[r, j] = F(xs[r], ys[j])``."""

    start: int
    xs: np.ndarray
    ys: np.ndarray
    z: np.ndarray


def _count(v, name: str) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
        raise InputError(f"{name} = {v!r} is not a whole number of grid lines")
    if v < 2:
        raise InputError(f"{name} = {v} is too few: a sample needs at least 2 grid lines in each direction")
    if v > MAX_AXIS_POINTS:
        raise InputError(f"{name} = {v} is more than {MAX_AXIS_POINTS} grid lines in one direction")
    return int(v)


def _count_for(step: Fraction, length: Fraction, name: str) -> int:
    if step <= 0:
        raise InputError(f"{name} = {_show(step)} should be positive")
    n = math.ceil(length / step) + 1
    if n > MAX_AXIS_POINTS:
        raise InputError(
            f"{name} = {_show(step)} gives {n:.3g} grid lines over a length of {_show(length)}, "
            f"more than {MAX_AXIS_POINTS}; use a larger step"
        )
    return max(n, 2)


def sample_grid(
    control,
    nx: int | None = None,
    ny: int | None = None,
    *,
    step=None,
    dx=None,
    dy=None,
    box=None,
    extrapolate: bool = False,
    max_points: int | None = MAX_POINTS,
) -> SampleGrid:
    """The regular sample grid asked for, checked against the control points.

    Parameters
    ----------
    control : ControlGrid, LagrangeSurface or PiecewiseSurface
        Whose control box is the default domain and the interpolation range.
    nx, ny : int, optional
        Number of grid lines in x and y (edges included), at least 2; one
        alone stands for both, as ``--nx`` alone does on the command line.
    step, dx, dy : number, optional
        Largest spacing instead of counts: ``step`` for both directions or
        ``dx`` and ``dy``.  The count is the smallest that keeps the spacing
        at or below the step, so the spacing equals the step exactly when it
        divides the box.  Exact decimals: pass ``"0.05"`` (a string) or a
        ``Fraction`` to avoid binary rounding of the step.
    box : tuple, optional
        ``(x0, x1, y0, y1)``; any item may be None for the control box's edge.
    extrapolate : bool
        Allow a box reaching outside the control box.
    max_points : int or None
        Refuse more points than this (``--max-points``); None: no limit.

    Raises
    ------
    InputError
        For a missing, conflicting or out-of-range density or box, naming it.

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> g = grid_from_table([0, 1, 2], [0, 2], [[0, 0], [1, 1], [4, 4]])
    >>> s = sample_grid(g, step="0.5")
    >>> s.nx, s.ny, s.xs.tolist()
    (5, 5, [0.0, 0.5, 1.0, 1.5, 2.0])
    """
    region = _region(getattr(control, "grid", control), box, extrapolate)
    counts = nx is not None or ny is not None
    spacing = step is not None or dx is not None or dy is not None
    if counts and spacing:
        raise InputError("give the density either as counts (nx, ny) or as a spacing (step or dx, dy), not both")
    if step is not None and (dx is not None or dy is not None):
        raise InputError("give either step (both directions) or dx and dy, not both")
    if spacing:
        if step is None and (dx is None or dy is None):
            raise InputError("give both dx and dy, or step for both directions")
        nxname, nyname = ("step", "step") if step is not None else ("dx", "dy")
        sx = as_exact(step if step is not None else dx, nxname)
        sy = as_exact(step if step is not None else dy, nyname)
        counts = _count_for(sx, region.x1 - region.x0, nxname), _count_for(sy, region.y1 - region.y0, nyname)
        return _within(SampleGrid(region, *counts), max_points)
    if nx is None and ny is None:
        raise InputError("give nx (and ny, if it differs) or a spacing")
    nx, ny = (nx, ny) if nx is not None and ny is not None else (nx or ny, nx or ny)
    return _within(SampleGrid(region, _count(nx, "nx"), _count(ny, "ny")), max_points)


def _region(grid, box, extrapolate: bool) -> Box:
    """The box to sample: ``box`` with the control box's edges for its Nones, checked against the control points."""
    cx0, cx1, cy0, cy1 = grid.bounds
    given = [None] * 4 if box is None else list(box)
    if len(given) != 4:
        raise InputError(f"box = {box!r} should be (x0, x1, y0, y1)")
    names = ("x0", "x1", "y0", "y1")
    x0, x1, y0, y1 = (c if v is None else as_exact(v, name) for v, c, name in zip(given, (cx0, cx1, cy0, cy1), names))
    if not x0 < x1:
        raise InputError(f"x0 = {_show(x0)} should be less than x1 = {_show(x1)}")
    if not y0 < y1:
        raise InputError(f"y0 = {_show(y0)} should be less than y1 = {_show(y1)}")
    region = Box(x0, x1, y0, y1)
    if not extrapolate and not Box(cx0, cx1, cy0, cy1).contains(region):
        raise InputError(
            f"the box x {_show(x0)}..{_show(x1)}, y {_show(y0)}..{_show(y1)} reaches outside the control points "
            f"(x {_show(cx0)}..{_show(cx1)}, y {_show(cy0)}..{_show(cy1)}); that is extrapolation: "
            f"allow it explicitly (extrapolate=True, --extrapolate)"
        )
    return region


def _within(g: SampleGrid, max_points: int | None) -> SampleGrid:
    if max_points is not None and g.size > max_points:
        raise InputError(f"a {g.nx} x {g.ny} sample is {g.size:.3g} points, more than the limit of {max_points:.3g}; "
                         f"use a coarser grid or raise the limit (--max-points)")
    return g


def sample(surface, nx: int | None = None, ny: int | None = None, *, grid: SampleGrid | None = None,
           engine: Engine | None = None, **kwargs) -> Sample:
    """Sample ``surface`` on a regular grid and return ``(X, Y, Z)``.

    Takes the arguments of :func:`sample_grid` (see there), or a ready
    ``grid``.  The heights come from the stable evaluator, never from the
    expanded power basis, run as ``engine`` rules (a
    :class:`lagsym.evaluate.Engine`; the current one by default): the same
    bits whichever engine runs.
    A piecewise surface (:mod:`lagsym.surfaces.piecewise`) is sampled with
    its own evaluator, each point from the piece whose cell holds it.

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> from lagsym.lagrange import lagrange_surface
    >>> s = lagrange_surface(grid_from_table([0, 1, 2], [0, 2], [[0, 0], [1, 1], [4, 4]]))
    >>> X, Y, Z = sample(s, 3, 2)
    >>> Z.tolist()
    [[0.0, 0.0], [1.0, 1.0], [4.0, 4.0]]
    """
    g = grid if grid is not None else sample_grid(surface, nx, ny, **kwargs)
    z = _evaluator(surface).grid(g.xs, g.ys, engine=engine)
    z.setflags(write=False)
    return Sample(_lines(g.xs, g.ny, 0), _lines(g.ys, g.nx, 1), z)


def _evaluator(surface):
    """The numeric evaluator a sample uses: the one a surface of pieces brings along
    (:attr:`lagsym.surfaces.piecewise.PiecewiseSurface.evaluator`), else the polynomial's stable one."""
    own = getattr(surface, "evaluator", None)
    return own if own is not None else surface_evaluator(surface)


def _lines(values: np.ndarray, count: int, axis: int) -> np.ndarray:
    """``values`` repeated ``count`` times along the other axis: a read-only view taking no memory (stride 0).

    What ``np.broadcast_to`` gives, built directly on the array's buffer:
    the shape is always two axes with one stride 0, so none of
    ``broadcast_to``'s general checks and iterator set-up is needed
    (``benchmarks/bench_sampling.py`` times a whole sample).
    """
    v = np.ascontiguousarray(values, dtype=float)
    shape, strides = ((v.size, count), (8, 0)) if axis == 0 else ((count, v.size), (0, 8))
    out = np.ndarray(shape, float, v, 0, strides)
    out.flags.writeable = False
    return out


def iter_blocks(surface, grid: SampleGrid, block_points: int = BLOCK_POINTS, *,
                engine: Engine | None = None) -> Iterator[Block]:
    """Yield the sample of ``surface`` on ``grid`` a block of x-rows at a time.

    Each block holds about ``block_points`` points (at least one row), so the
    memory in use does not grow with the grid.  ``engine`` as in :func:`sample`.
    """
    engine = current_engine() if engine is None else engine
    rows = max(1, block_points // grid.ny)
    own = getattr(surface, "evaluator", None)
    if own is not None:
        for start in range(0, grid.nx, rows):
            xs = grid.xs[start:start + rows]
            yield Block(start, xs, grid.ys, own.grid(xs, grid.ys))
        return
    ev = surface_evaluator(surface)
    compiled = engine.use_compiled(min(rows, grid.nx) * grid.ny)  # the blocks may run compiled: then the factors too
    w = ev.x_factor(grid.xs, compiled)  # (nx, m): small
    ty = ev.y_basis(grid.ys, compiled)  # (m, ny): small
    for start in range(0, grid.nx, rows):
        stop = min(start + rows, grid.nx)
        xs = grid.xs[start:stop]
        yield Block(start, xs, grid.ys, ev.snap_grid(grid_product(w[start:stop], ty, engine=engine), xs, grid.ys))
