"""Deviation measures between surfaces built from one control net, and the paper's table.

The paper (section 3, Table 1) compares an approximation ``z_a`` with a
function ``z_f`` at every sample of a fine grid:

* deviation ``d = z_f - z_a`` at each sample;
* deviation rate ``z_a / z_f``;
* maximum and minimum deviation and their ``(I, J)`` sample location;
* number of coincided points;
* deviation percentage ``(deviation / number of points) * 100 %``.

Where the paper leaves a measure open this module reads it as follows
(``docs/comparison.md`` gives the reasons):

``deviation``
    The table shows one number per method: the mean of ``d`` over the samples.
``deviation rate``
    ``sum(z_a) / sum(z_f)`` over the samples (the ratio of the volumes over
    ``z = 0``), so that a single ``z_f = 0`` does not make it infinite; ``nan``
    when ``sum(z_f) == 0``.
``maximum / minimum deviation``
    The largest and smallest *signed* ``d``.  ``(I, J)`` are 1-based sample
    indices along x and y; on a tie the first in order of ``I`` then ``J``.
``coincided points``
    Samples with ``|d| <= tolerance`` (an absolute tolerance in mm, stated with
    the table; default :data:`DEFAULT_TOLERANCE_MM`).
``deviation percentage``
    The formula as printed, with the sum of ``|d|`` for "deviation":
    ``100 * sum(|d|) / N``.  It is numerically 100 x the mean absolute
    deviation and carries the unit of ``z``; it is not relative.  The relative
    figure, ``100 * sum(|d|) / sum(|z_f|)``, is reported beside it.

An engineer also gets the maximum ``|d|`` with its location, the mean ``|d|``
and the root mean square of ``d``.
"""

from __future__ import annotations

import csv
import functools
import io
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ._arrays import power_of_two_scale
from ._arrays import readonly as _readonly
from .errors import InputError
from .exactsize import MAX_EXACT_MB
from .grid import ControlGrid, _fmt
from .sampling import axis_lines
from .surfaces import HERMITE_KINDS, METHODS, make_surface
from .values import choice

__all__ = ["DEFAULT_SAMPLES", "DEFAULT_TOLERANCE_MM", "MAX_SAMPLES", "MEASURES", "TABLE_FORMATS", "Comparison",
           "DeviationMeasures", "MethodComparison", "compare_surfaces", "deviation_measures", "render_table",
           "sample_axes"]

DEFAULT_SAMPLES = (61, 61)  # 60 steps: every node of an evenly spaced 3- to 7-node net is a sample
DEFAULT_TOLERANCE_MM = 1e-6
MAX_SAMPLES = 4_000_000  # a 2000 x 2000 grid; each method holds a few arrays of this size
TABLE_FORMATS = ("text", "markdown", "csv", "json")

#: Rows of the table, in the paper's order first: (attribute, label).
MEASURES = (
    ("deviation_mean", "Deviation, mean of z_f - z_a (mm)"),
    ("deviation_rate", "Deviation rate, sum z_a / sum z_f"),
    ("max_deviation", "Maximum deviation (mm)"),
    ("max_location", "Location in (I,J) direction"),
    ("min_deviation", "Minimum deviation (mm)"),
    ("min_location", "Location in (I,J) direction"),
    ("coincided", "Number of coincided points"),
    ("deviation_percentage", "Deviation percentage, 100 sum|d| / N"),
    ("relative_percentage", "Relative deviation (%), 100 sum|d| / sum|z_f|"),
    ("max_abs_deviation", "Maximum |deviation| (mm)"),
    ("max_abs_location", "Location in (I,J) direction"),
    ("mean_abs_deviation", "Mean |deviation| (mm)"),
    ("rms_deviation", "RMS deviation (mm)"),
)


@dataclass(frozen=True)
class DeviationMeasures:
    """The deviation measures of one approximation against the reference.

    Locations are 1-based ``(I, J)`` sample indices along x and along y.
    """

    samples: int
    deviation_mean: float
    deviation_rate: float
    max_deviation: float
    max_location: tuple[int, int]
    min_deviation: float
    min_location: tuple[int, int]
    coincided: int
    tolerance: float
    deviation_percentage: float
    relative_percentage: float
    max_abs_deviation: float
    max_abs_location: tuple[int, int]
    mean_abs_deviation: float
    rms_deviation: float


def _location(index: int, shape: tuple[int, ...]) -> tuple[int, int]:
    if len(shape) == 1:
        return index + 1, 1
    i, j = np.unravel_index(index, shape)
    return int(i) + 1, int(j) + 1


def _ratio(num: float, den: float) -> float:
    return num / den if den != 0 else math.nan


def deviation_measures(z_f, z_a, tolerance: float = DEFAULT_TOLERANCE_MM) -> DeviationMeasures:
    """The paper's measures and the usual ones for ``d = z_f - z_a`` on a sample grid.

    Parameters
    ----------
    z_f : array_like
        Reference heights (the paper's "function"), 1-D or a ``(I, J)`` grid.
    z_a : array_like
        Heights of the approximation at the same samples.
    tolerance : float, optional
        Samples with ``|d| <= tolerance`` count as coincided.

    Returns
    -------
    DeviationMeasures

    Examples
    --------
    >>> m = deviation_measures([[1.0, 2.0], [3.0, 4.0]], [[1.0, 1.0], [3.0, 5.0]])
    >>> m.max_deviation, m.max_location, m.min_deviation, m.min_location, m.coincided
    (1.0, (1, 2), -1.0, (2, 2), 2)
    >>> m.deviation_rate, m.deviation_percentage, m.rms_deviation
    (1.0, 50.0, 0.7071067811865476)
    """
    z_f = np.asarray(z_f, dtype=float)
    z_a = np.asarray(z_a, dtype=float)
    if z_f.shape != z_a.shape or z_f.size == 0:
        raise ValueError(f"reference shape {z_f.shape} and approximation shape {z_a.shape} should match, non-empty")
    if not (tolerance >= 0 and math.isfinite(tolerance)):
        raise InputError(f"tolerance {tolerance!r} should be a finite number >= 0")
    coincided = int(np.count_nonzero(np.abs(z_f - z_a) <= tolerance)) if np.isfinite(z_f - z_a).all() else None
    # Heights near the float range (1e300) would overflow the sums and squares: measure in units of a
    # power of two (an exact scaling) and scale back; a result beyond the float range is refused.
    k = power_of_two_scale(z_f, z_a)
    z_f, z_a = z_f / k, z_a / k
    d = z_f - z_a
    a = np.abs(d)
    n = d.size
    imax, imin, iabs = int(np.argmax(d)), int(np.argmin(d)), int(np.argmax(a))
    m = DeviationMeasures(
        samples=n,
        deviation_mean=float(d.mean()) * k,
        deviation_rate=_ratio(float(z_a.sum()), float(z_f.sum())),
        max_deviation=float(d.flat[imax]) * k,
        max_location=_location(imax, d.shape),
        min_deviation=float(d.flat[imin]) * k,
        min_location=_location(imin, d.shape),
        coincided=coincided if coincided is not None else int(np.count_nonzero(a <= tolerance / k)),
        tolerance=float(tolerance),
        deviation_percentage=float(100.0 * a.mean()) * k,
        relative_percentage=100.0 * _ratio(float(a.sum()), float(np.abs(z_f).sum())),
        max_abs_deviation=float(a.flat[iabs]) * k,
        max_abs_location=_location(iabs, d.shape),
        mean_abs_deviation=float(a.mean()) * k,
        rms_deviation=float(np.sqrt(np.mean(d * d))) * k,
    )
    if not all(math.isfinite(v) for v in (m.max_deviation, m.min_deviation, m.deviation_percentage, m.rms_deviation)):
        raise InputError(f"deviations of {float(a.flat[iabs]):.3g} x {k:.3g} are beyond the range of a float; "
                         f"check the reference and the heights")
    return m


@dataclass(frozen=True)
class MethodComparison:
    """One column of the table: a method's heights, its deviations and their measures."""

    name: str
    z: np.ndarray = field(repr=False)
    deviation: np.ndarray = field(repr=False)
    measures: DeviationMeasures


@dataclass(frozen=True)
class Comparison:
    """Every compared method against one reference, at the same samples.

    Attributes
    ----------
    reference : str
        What ``z_f`` is: ``"Lagrange surface"``, the formula, or the measured points' file.
    xs, ys : numpy.ndarray
        The sample positions; sample ``(I, J)`` is ``(xs[I-1], ys[J-1])``.
    z_reference : numpy.ndarray
        ``z_f`` at the samples, shape ``(len(xs), len(ys))``.
    methods : tuple of MethodComparison
        One per method, in the order asked for.
    tolerance : float
        Coincidence tolerance in mm.
    bspline_degree : tuple of int
        The B-spline degree used in x and in y (after capping).
    hermite : str
        The Hermite kind.
    """

    reference: str
    xs: np.ndarray = field(repr=False)
    ys: np.ndarray = field(repr=False)
    z_reference: np.ndarray = field(repr=False)
    methods: tuple[MethodComparison, ...]
    tolerance: float
    bspline_degree: tuple[int, int]
    hermite: str

    @property
    def deviations(self) -> dict[str, np.ndarray]:
        """``{method name: d = z_f - z_a}``, the arrays a deviation map shows."""
        return {m.name: m.deviation for m in self.methods}


def sample_axes(grid: ControlGrid, samples: tuple[int, int] = DEFAULT_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """Evenly spaced sample positions over the control box, ends included.

    Positions come from :func:`lagsym.sampling.axis_lines`: computed exactly
    and rounded once, so a sample that falls on a control node is that node,
    to the last bit.

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> xs, ys = sample_axes(grid_from_table([0, 3], [1, 2], [[0, 0], [0, 0]]), (4, 3))
    >>> xs.tolist(), ys.tolist()
    ([0.0, 1.0, 2.0, 3.0], [1.0, 1.5, 2.0])
    """
    if len(samples) != 2:
        raise InputError(f"samples {samples!r} should be two counts, in x and in y")
    for name, count in (("x", samples[0]), ("y", samples[1])):
        if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 2:
            raise InputError(f"{count!r} samples in {name}: need an integer >= 2")
    if samples[0] * samples[1] > MAX_SAMPLES:
        raise InputError(f"{samples[0]} x {samples[1]} samples is more than the limit of {MAX_SAMPLES}")
    x0, x1, y0, y1 = grid.bounds
    return axis_lines(x0, x1, int(samples[0])), axis_lines(y0, y1, int(samples[1]))


def _reference_heights(reference, grid: ControlGrid, samples, surface_of):
    """``(label, xs, ys, z_f)`` for the three kinds of reference; ``surface_of(method)`` builds a method's surface."""
    if isinstance(reference, str):
        if reference != "lagrange":
            raise InputError(f"reference {reference!r}: give 'lagrange', a Formula or a ControlGrid of measured points")
        xs, ys = sample_axes(grid, samples or DEFAULT_SAMPLES)
        return "Lagrange surface", xs, ys, surface_of("lagrange").evaluate_grid(xs, ys)
    if isinstance(reference, ControlGrid):
        if samples is not None:
            raise InputError(f"{reference.source}: measured points fix the samples; leave out the sample count")
        x0, x1, y0, y1 = grid.bounds
        for axis, nodes, lo, hi in (("x", reference.x, x0, x1), ("y", reference.y, y0, y1)):
            for v in nodes:
                if not lo <= v <= hi:
                    raise InputError(
                        f"{reference.source}: measured {axis} = {_fmt(v)} lies outside the control points' "
                        f"{axis} range [{_fmt(lo)}, {_fmt(hi)}]"
                    )
        return f"measured points {reference.source}", reference.x_array, reference.y_array, reference.z_array
    if hasattr(reference, "evaluate_grid") and hasattr(reference, "name"):
        xs, ys = sample_axes(grid, samples or DEFAULT_SAMPLES)
        return reference.name, xs, ys, reference.evaluate_grid(xs, ys)
    raise InputError(f"reference {reference!r}: give 'lagrange', a Formula or a ControlGrid of measured points")


def compare_surfaces(
    grid: ControlGrid,
    reference="lagrange",
    *,
    samples: tuple[int, int] | None = None,
    methods: Sequence[str] = METHODS,
    degree: int = 3,
    hermite: str = "corner",
    tolerance: float = DEFAULT_TOLERANCE_MM,
    max_mb: float | None = MAX_EXACT_MB,
) -> Comparison:
    """Build every method's surface from ``grid`` and measure it against ``reference``.

    Parameters
    ----------
    grid : ControlGrid
        The control net every method is built from.
    reference : "lagrange", Formula, Surface or ControlGrid, optional
        ``z_f``: the Lagrange surface (default), a parsed formula
        (:func:`lagsym.formula.parse_formula`) or any value with ``name`` and
        ``evaluate_grid``, or measured points, compared at the measured
        positions themselves (no interpolation of the measurements).
    samples : (int, int), optional
        Samples in x and in y over the control box (default
        :data:`DEFAULT_SAMPLES`); not allowed with measured points.
    methods : sequence of str, optional
        Any of :data:`~lagsym.surfaces.METHODS`, in the table's column order.
    degree : int, optional
        B-spline degree, capped at ``n - 1`` per direction.
    hermite : {"corner", "piecewise"}, optional
        The Hermite surface to build.
    tolerance : float, optional
        Coincidence tolerance in mm.
    max_mb : float or None, optional
        The Lagrange surface's limit on its exact rationals (:func:`lagsym.lagrange.lagrange_surface`).

    Returns
    -------
    Comparison

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> from lagsym.formula import parse_formula
    >>> g = grid_from_table([0, 1, 2], [0, 1, 2], [[x * x + y for y in range(3)] for x in range(3)])
    >>> c = compare_surfaces(g, parse_formula("x**2 + y"), samples=(5, 5))
    >>> [(m.name, m.measures.coincided) for m in c.methods]
    [('Lagrange', 25), ('Hermite', 10), ('Bezier', 10), ('B-spline', 10)]
    """
    methods = [methods] if isinstance(methods, str) else methods
    if not methods:
        raise InputError(f"no methods to compare; choose from {', '.join(METHODS)}")
    for m in methods:
        choice(m, METHODS, "method")
    choice(hermite, HERMITE_KINDS, "Hermite kind")
    # the Lagrange surface is built once, as the reference and as a column
    surface_of = functools.cache(lambda m: make_surface(m, grid, degree=degree, hermite=hermite, max_mb=max_mb))
    label, xs, ys, z_f = _reference_heights(reference, grid, samples, surface_of)
    z_f = _readonly(z_f)
    bad = np.argwhere(~np.isfinite(z_f))
    if len(bad):
        i, j = bad[0]
        raise InputError(
            f"reference {label!r} is not finite at (x, y) = ({xs[i]:g}, {ys[j]:g}), sample ({i + 1},{j + 1})"
        )
    columns = []
    for m in dict.fromkeys(methods):
        surface = surface_of(m)
        z_a = _readonly(surface.evaluate_grid(xs, ys))
        measures = deviation_measures(z_f, z_a, tolerance)
        columns.append(MethodComparison(surface.name, z_a, _readonly(z_f - z_a), measures))
    n, mm = grid.shape
    return Comparison(reference=label, xs=_readonly(xs), ys=_readonly(ys), z_reference=z_f, methods=tuple(columns),
                      tolerance=float(tolerance), bspline_degree=(min(degree, n - 1), min(degree, mm - 1)),
                      hermite=hermite)


def _cell(value, kind: str) -> str:
    if isinstance(value, tuple):
        return f"({value[0]},{value[1]})"
    if isinstance(value, int):
        return str(value)
    if math.isnan(value):
        return "n/a"
    text = f"{value:.4f}"
    return "0.0000" if text == "-0.0000" else text


def _notes(c: Comparison) -> list[str]:
    names = [m.name for m in c.methods]
    notes = [
        f"z_f: {c.reference}; d = z_f - z_a; {len(c.xs)} x {len(c.ys)} samples "
        f"over x [{c.xs[0]:g}, {c.xs[-1]:g}], y [{c.ys[0]:g}, {c.ys[-1]:g}]",
        f"coincided: |d| <= {c.tolerance:g} mm; (I,J): 1-based sample indices along x and y",
    ]
    if "B-spline" in names:
        notes.append(f"B-spline: clamped uniform knots, degree {c.bspline_degree[0]} x {c.bspline_degree[1]}")
    if "Hermite" in names:
        kind = "one corner patch" if c.hermite == "corner" else "piecewise C1 patches through every point"
        notes.append(f"Hermite: bicubic, {kind}, tangents by finite differences")
    return notes


def _rows(c: Comparison) -> list[list[str]]:
    return [[label] + [_cell(getattr(m.measures, key), key) for m in c.methods] for key, label in MEASURES]


def _json_value(value):
    if isinstance(value, tuple):
        return list(value)
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def render_table(c: Comparison, fmt: str = "text") -> str:
    """The comparison as a table shaped like the paper's Table 1: one column per method.

    Parameters
    ----------
    c : Comparison
    fmt : {"text", "markdown", "csv", "json"}
        ``text`` and ``markdown`` round to 4 decimals as the paper does;
        ``csv`` and ``json`` carry full precision.
    """
    choice(fmt, TABLE_FORMATS, "table format")
    names = [m.name for m in c.methods]
    if fmt == "json":
        doc = {
            "reference": c.reference,
            "samples": [len(c.xs), len(c.ys)],
            "tolerance_mm": c.tolerance,
            "bspline_degree": list(c.bspline_degree),
            "hermite": c.hermite,
            "methods": {
                m.name: {key: _json_value(getattr(m.measures, key)) for key, _ in MEASURES} for m in c.methods
            },
        }
        return json.dumps(doc, indent=2, allow_nan=False) + "\n"
    if fmt == "csv":
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["measure"] + names)
        for key, _ in MEASURES:
            values = [getattr(m.measures, key) for m in c.methods]
            w.writerow([key] + [f"{v[0]} {v[1]}" if isinstance(v, tuple) else repr(v) for v in values])
        return buf.getvalue()
    header = ["Parameters"] + names
    rows = _rows(c)
    if fmt == "markdown":
        lines = ["| " + " | ".join(header) + " |", "|" + "---|" + "---:|" * len(names)]
        lines += ["| " + " | ".join(v.replace("|", "\\|") for v in r) + " |" for r in rows]
        return "\n".join(lines) + "\n\n" + "\n".join(f"- {n}" for n in _notes(c)) + "\n"
    widths = [max(len(r[k]) for r in [header] + rows) for k in range(len(header))]
    def line(r):
        return "  ".join([r[0].ljust(widths[0])] + [v.rjust(w) for v, w in zip(r[1:], widths[1:])])

    title = f"Comparison with {c.reference}"
    lines = [title, line(header), "  ".join("-" * w for w in widths)] + [line(r) for r in rows]
    return "\n".join(lines) + "\n\n" + "\n".join(_notes(c)) + "\n"
