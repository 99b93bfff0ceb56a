"""The look shared by every figure: colours, colour bars, axis labels, text sizes and the camera."""

from __future__ import annotations

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
    "view",
    "plan_view",
    "fit",
    "z_scale",
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
    font = max(8, min(16, height_px // 40))
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


def axis_labels(plotter, units: str, font_size: int = 10) -> None:
    """A grid with x, y and z titled in ``units``."""
    plotter.show_grid(xtitle=f"x ({units})", ytitle=f"y ({units})", ztitle=f"z ({units})", color="black",
                      font_size=font_size, fmt="%.3g")


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
    """Stretch z so a flat part still shows its shape: at least a fifth of the larger plan side.

    Examples
    --------
    >>> z_scale(10.0, 5.0, 0.5), z_scale(10.0, 5.0, 4.0)
    (4.0, 1.0)
    """
    plan = max(x_span, y_span)
    if z_span <= 0 or z_span >= plan / 5:
        return 1.0
    return plan / 5 / z_span


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
