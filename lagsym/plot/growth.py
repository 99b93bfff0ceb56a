"""The growth of the deviation with the degree (the paper's Figure 11).

A function ``f(x, y)`` is sampled at ``n x n`` evenly spaced control points
over a box for each degree ``n - 1``; each method's surface through those
points is compared with ``f`` itself at a fine sample grid, and the largest
``|z_f - z_a|`` is drawn against the degree.  The Lagrange surface improves
up to a point, then its deviation grows rapidly (Runge's phenomenon, the
paper's limitation 4: "more than 6th order").
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from ..compare import compare_surfaces
from ..errors import FormulaError, InputError
from ..grid import grid_from_table
from .backend import DEFAULT_WINDOW_SIZE, new_plotter
from .checks import check_samples
from .style import CYCLE, chart_text, fit, text_size

__all__ = ["DegreeGrowth", "degree_growth", "growth_figure", "MAX_GROWTH_DEGREE"]

# A 21 x 21 Lagrange surface in exact rationals takes a few seconds to build and sample; higher degrees
# say nothing new (the deviation has long since left the part) and grow as the fourth power of n.
MAX_GROWTH_DEGREE = 20


@dataclass(frozen=True)
class DegreeGrowth:
    """The largest deviation of each method at each degree.

    Attributes
    ----------
    function : str
        What ``z_f`` is, for the title.
    degrees : tuple of int
        The degrees ``n - 1`` of the ``n x n`` nets.
    largest : mapping of str to tuple of float
        Method name to ``max |z_f - z_a|`` at each degree, in the order of ``degrees``.
    samples : int
        Samples along each axis at which the surfaces were compared.
    """

    function: str
    degrees: tuple[int, ...]
    largest: Mapping[str, tuple[float, ...]]
    samples: int


def _net(formula, bounds, n: int):
    x0, x1, y0, y1 = (Fraction(v) for v in bounds)
    xs = [x0 + (x1 - x0) * i / (n - 1) for i in range(n)]
    ys = [y0 + (y1 - y0) * k / (n - 1) for k in range(n)]
    try:
        z = [[formula.exact_value(a, b) for b in ys] for a in xs]
    except FormulaError as exact_error:  # sin, pi, ...: the float value, read exactly
        z = [[_finite(formula, a, b, exact_error) for b in ys] for a in xs]
    return grid_from_table(xs, ys, z)


def _finite(formula, a: Fraction, b: Fraction, exact_error: FormulaError) -> Fraction:
    """The formula's float value at a node, exactly; where it is not finite (1/(x-x)), the exact reading's error."""
    with np.errstate(all="ignore"):
        v = float(formula(float(a), float(b)))
    if not math.isfinite(v):
        raise FormulaError(f"{exact_error}; its value at (x, y) = ({float(a):g}, {float(b):g}) is {v}") from None
    return Fraction(v)


def degree_growth(formula, bounds: Sequence[float], degrees: Sequence[int] = range(2, 13, 2), *, samples: int = 81,
                  methods: Sequence[str] = ("lagrange", "bspline")) -> DegreeGrowth:
    """Measure each method against ``formula`` on ``n x n`` evenly spaced nets, ``n - 1`` in ``degrees``.

    Parameters
    ----------
    formula : Formula
        ``z_f`` (:func:`lagsym.formula.parse_formula`); values at the nodes are exact where it can be.
    bounds : (x0, x1, y0, y1)
        The box the nets span.
    degrees : sequence of int
        Degrees from 1 to :data:`MAX_GROWTH_DEGREE`; default the even ones 2 to 12, whose odd nets
        have a node in the middle (odd and even nets zigzag against each other).
    samples : int
        Samples along each axis of the comparison.
    methods : sequence of str
        Methods of :func:`lagsym.compare.compare_surfaces` (the B-spline is cubic, capped at ``n - 1``).

    Returns
    -------
    DegreeGrowth

    Examples
    --------
    >>> from lagsym.formula import parse_formula
    >>> g = degree_growth(parse_formula("x**3 + y"), (0, 1, 0, 1), degrees=[2, 3], samples=5, methods=["lagrange"])
    >>> g.degrees, g.largest["Lagrange"][1] < 1e-12 < g.largest["Lagrange"][0]
    ((2, 3), True)
    """
    degs = tuple(int(d) for d in degrees)
    if not degs:
        raise InputError("no degrees to measure")
    for d in degs:
        if not 1 <= d <= MAX_GROWTH_DEGREE:
            raise InputError(f"degree {d} is out of range: give degrees from 1 to {MAX_GROWTH_DEGREE} "
                             f"(a {d + 1}x{d + 1} net)")
    n = check_samples(samples)
    x0, x1, y0, y1 = bounds
    if not (x0 < x1 and y0 < y1):
        raise InputError(f"box {tuple(bounds)!r} should be (x0, x1, y0, y1) with x0 < x1 and y0 < y1")
    largest: dict[str, list[float]] = {}
    for d in degs:
        c = compare_surfaces(_net(formula, bounds, d + 1), formula, samples=(n, n), methods=methods)
        for m in c.methods:
            largest.setdefault(m.name, []).append(m.measures.max_abs_deviation)
    return DegreeGrowth(getattr(formula, "name", str(formula)), degs, {k: tuple(v) for k, v in largest.items()}, n)


def growth_figure(growth: DegreeGrowth, *, units: str = "mm", title: str | None = None,
                  window_size: Sequence[int] = DEFAULT_WINDOW_SIZE, off_screen: bool | None = None):
    """The largest ``|z_f - z_a|`` against the degree, one line per method (the paper's Figure 11).

    The deviation axis is logarithmic when every value is above 0, so the
    early gains and the late growth both show.

    Parameters
    ----------
    growth : DegreeGrowth
        From :func:`degree_growth`.
    units : str
        Length unit of the deviations.
    title : str, optional
        Defaults to one naming the function.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    import pyvista as pv

    p = new_plotter(window_size=window_size, off_screen=off_screen)
    h = p.window_size[1]
    # The chart's own title has a fixed small font: the title is the plotter's text, above the chart.
    chart = pv.Chart2D(size=(1.0, 0.86), x_label="degree (n x n points, n - 1)",
                       y_label=f"largest abs(z_f - z_a) ({units})")
    text = title if title is not None else f"Deviation against degree\n{growth.function}"
    degs = np.array(growth.degrees, dtype=float)
    values = np.array([v for series in growth.largest.values() for v in series])
    log = bool(values.size and values.min() > 0)
    for k, (name, series) in enumerate(growth.largest.items()):
        color = CYCLE[k % len(CYCLE)]
        chart.line(degs, series, color=color, width=3.0, label=name)
        chart.scatter(degs, series, color=color, size=10, style="o")
    chart.y_axis.log_scale = log
    chart.x_range = [float(degs.min()) - 0.5, float(degs.max()) + 0.5]
    chart.x_axis.tick_locations = degs
    chart.x_axis.tick_labels = [str(d) for d in growth.degrees]
    lo, hi = float(values.min()), float(values.max())
    chart.y_range = [lo / 2, hi * 2] if log else [min(0.0, lo), hi * 1.1 or 1.0]
    chart_text(chart, h)
    p.add_chart(chart)
    p.add_text(text, position="upper_edge", font_size=fit(text, p.window_size[0], largest=text_size(h, 1 / 60)),
               color="black")
    return p
