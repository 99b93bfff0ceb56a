"""The look shared by every figure: colours, colour bars, axis labels, text sizes and the camera."""

from __future__ import annotations

import math

from ..values import positive

__all__ = [
    "SURFACE_CMAP",
    "DEVIATION_CMAP",
    "BASIS_CMAP",
    "POINT_COLOR",
    "NET_COLOR",
    "FEED_COLOR",
    "RAPID_COLOR",
    "CYCLE",
    "BAR_COLUMN",
    "bar_args",
    "bar_column",
    "axis_labels",
    "ticks",
    "true_ranges",
    "view",
    "plan_view",
    "fit",
    "z_scale",
    "z_factor",
    "z_note",
    "plan_axes",
    "text_size",
    "chart_text",
    "padded",
    "title_for",
]

SURFACE_CMAP = "viridis"
DEVIATION_CMAP = "coolwarm"
BASIS_CMAP = "RdBu_r"
POINT_COLOR = "crimson"
NET_COLOR = "black"
FEED_COLOR = "orangered"
RAPID_COLOR = "royalblue"
CYCLE = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:gray",
         "tab:olive", "tab:cyan")

BAR_COLUMN = 0.55  # width of the colour-bar column of a multi-panel figure, in panels


def bar_args(title: str, height_px: int, **extra) -> dict:
    """Arguments of ``add_scalar_bar`` for a bar beside a single panel ``height_px`` high."""
    font = text_size(height_px, 1 / 40)
    args = dict(title=title, vertical=True, position_x=0.84, position_y=0.2, width=0.07, height=0.6,
                title_font_size=font + 2, label_font_size=font, fmt="%.3g", color="black")
    args.update(extra)
    return args


def bar_column(p, row: int, col: int, mapper, title: str, height_px: int) -> None:
    """A colour bar alone in the narrow last column, so it covers no panel."""
    p.subplot(row, col)
    p.add_scalar_bar(mapper=mapper, **bar_args(title, height_px, position_x=0.3, width=0.3, height=0.8,
                                               position_y=0.08))


def units_of(surface, units: str | None) -> str:
    """The label unit: ``units`` if given, else the units the surface's points file names, else mm."""
    source = getattr(surface, "grid", None) or getattr(surface, "points", None)
    return units or getattr(source, "units", None) or "mm"


def ticks(lo: float, hi: float, drawn_per_unit: float, least_gap: float, most: int = 6) -> tuple[float, float, int]:
    """Labels for an axis from ``lo`` to ``hi``: ``(first, last, count)`` on round values, or the two ends.

    The step is the smallest of 1, 2, 2.5 and 5 times a power of ten whose
    labels lie at least ``least_gap`` apart as drawn (``drawn_per_unit``
    drawn units per axis unit) and number at most ``most``; the axis then
    runs from a multiple of the step below ``lo`` to one above ``hi``.  Where
    that would stretch the axis by more than 40 % of its span (a short,
    stretched z axis), the labels are the two ends alone: fewer labels, never
    overlapping ones.

    Examples
    --------
    >>> ticks(0.0, 100.0, 1.0, 12.5)
    (0.0, 100.0, 6)
    >>> ticks(3.14, 6.93, 4.43, 12.5)
    (3.14, 6.93, 2)
    >>> ticks(-0.37, 2.61, 10.0, 5.0)
    (-1.0, 3.0, 5)
    """
    span = hi - lo
    if not (span > 0 and drawn_per_unit > 0 and math.isfinite(span)):
        return lo, hi, 2
    power = 10.0 ** math.floor(math.log10(span / 10))
    for step in (m * power * 10 ** e for e in range(4) for m in (1, 2, 2.5, 5)):
        first, last = math.floor(lo / step + 1e-9) * step, math.ceil(hi / step - 1e-9) * step
        count = round((last - first) / step) + 1
        if step * drawn_per_unit >= least_gap and count <= most:
            if last - first <= 1.4 * span:
                return round(first, 12), round(last, 12), count
            break
    return lo, hi, 2


def axis_labels(plotter, units: str, font_size: int = 10) -> None:
    """A grid with x, y and z titled in ``units``, its labels on round values reading true heights.

    A stretched or squeezed z (``plotter.scale``) is labelled with the heights
    of the part, not the drawing's; labels lie at least an eighth of the
    larger plan side apart as drawn, so a short z axis gets fewer of them.
    """
    x0, x1, y0, y1, z0, z1 = true_ranges(plotter)
    k = plotter.scale[2]
    gap = max(x1 - x0, y1 - y0, (z1 - z0) * k) / 8
    (ax, bx, nx), (ay, by, ny), (az, bz, nz) = (ticks(x0, x1, 1.0, gap), ticks(y0, y1, 1.0, gap),
                                                 ticks(z0, z1, k, gap))
    plotter.show_grid(xtitle=f"x ({units})", ytitle=f"y ({units})", ztitle=f"z ({units})", color="black",
                      font_size=font_size, fmt="%.4g", bounds=[ax, bx, ay, by, az * k, bz * k],
                      axes_ranges=[ax, bx, ay, by, az, bz], n_xlabels=nx, n_ylabels=ny, n_zlabels=nz)


def true_ranges(plotter) -> list[float]:
    """The plotter's bounds with z divided by its z scale: the ticks of a stretched picture read true heights."""
    x0, x1, y0, y1, z0, z1 = plotter.bounds
    k = plotter.scale[2]
    return [x0, x1, y0, y1, z0 / k, z1 / k]


def view(plotter, zoom: float = 1.0) -> None:
    """The 3-D camera every figure uses."""
    # A fixed camera, MATLAB's default 3-D view (azimuth -37.5, elevation 30): the
    # same picture every time, and one a reference image can pin.
    plotter.view_vector((-0.53, -0.69, 0.5), viewup=(0.0, 0.0, 1.0))
    plotter.reset_camera()
    plotter.camera.zoom(zoom)


def plan_view(plotter, zoom: float = 0.8) -> None:
    """Seen from above, x to the right."""
    plotter.view_xy()
    plotter.reset_camera()
    plotter.camera.zoom(zoom)


def fit(text: str, width_px: float, largest: int = 14, smallest: int = 5) -> int:
    """A font size at which the longest line of ``text`` fits in ``width_px`` pixels.

    A character of VTK's Arial is at most about 1.2 font sizes wide; the rest is margin.

    Examples
    --------
    >>> fit("short", 1000), fit("a much longer title line", 120)
    (14, 5)
    """
    longest = max((len(line) for line in text.splitlines()), default=1) or 1
    return int(max(smallest, min(largest, width_px / (1.5 * longest))))


def z_scale(x_span: float, y_span: float, z_span: float) -> float:
    """The automatic z exaggeration: the drawn height lies between a fifth of the larger plan side and that side.

    A flat part is stretched so it still shows its shape; a tall, narrow one
    (Example 1 rises 30 mm over a 4 x 2 mm box) is squeezed so it is not a
    sliver with its ticks piled on one another.

    Examples
    --------
    >>> z_scale(10.0, 5.0, 0.5), z_scale(10.0, 5.0, 4.0), z_scale(4.0, 2.0, 30.0)
    (4.0, 1.0, 0.13333333333333333)
    """
    plan = max(x_span, y_span)
    if z_span <= 0 or plan <= 0:
        return 1.0
    if z_span < plan / 5:
        return plan / 5 / z_span
    if z_span > plan:
        return plan / z_span
    return 1.0


def z_factor(z_exaggeration, x_span: float, y_span: float, z_span: float) -> float:
    """``z_exaggeration`` checked (a finite number > 0), or :func:`z_scale`'s choice when it is None."""
    if z_exaggeration is None:
        return z_scale(x_span, y_span, z_span)
    return float(positive(z_exaggeration, "z exaggeration"))


def z_note(factor: float) -> str:
    """The line a figure carries when z is drawn stretched or squeezed ("" when it is not).

    Examples
    --------
    >>> z_note(1.0), z_note(0.1333), z_note(4.0)
    ('', 'z drawn x0.133', 'z drawn x4')
    """
    return "" if factor == 1.0 else f"z drawn x{factor:.3g}"


def text_size(height_px: int, share: float = 1 / 32, smallest: int = 8) -> int:
    """A font size readable at ``height_px``: text stays the same share of the picture at any size."""
    return max(smallest, int(height_px * share))


def plan_axes(plotter, units: str, font_size: int) -> None:
    """x and y axes with ticks on a panel seen from above (no z axis: the panel is flat)."""
    plotter.show_bounds(xtitle=f"x ({units})", ytitle=f"y ({units})", show_zaxis=False, show_zlabels=False,
                        color="black", font_size=font_size, fmt="%.3g", n_xlabels=3, n_ylabels=3,
                        location="front", bold=False)


def padded(lo: float, hi: float, share: float = 0.06) -> list[float]:
    """The range ``[lo, hi]`` widened by ``share`` of its length each side (by 1 when it is empty)."""
    pad = (hi - lo) * share or 1.0
    return [float(lo - pad), float(hi + pad)]


def title_for(surface_or_curve) -> str:
    """The default title: what is drawn and its degree."""
    deg = surface_or_curve.degree
    if isinstance(deg, tuple):
        n, m = deg
        d = f"degree {n}" if n == m else f"degree {n} in x, {m} in y"
        return f"Lagrange surface z = F(x, y), {d} ({n + 1}x{m + 1} points)"
    return f"Lagrange curve y = F(x), degree {deg} ({deg + 1} points)"


def chart_text(chart, height_px: int) -> None:
    """Axis titles, ticks and legend of a 2-D chart at sizes legible at ``height_px``."""
    for axis in (chart.x_axis, chart.y_axis):
        axis.label_size = text_size(height_px, 1 / 40)
        axis.tick_label_size = text_size(height_px, 1 / 44)
    chart.legend.GetLabelProperties().SetFontSize(text_size(height_px, 1 / 44))
    chart.GetTitleProperties().SetFontSize(text_size(height_px, 1 / 36))
