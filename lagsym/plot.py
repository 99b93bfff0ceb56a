"""Pictures of curves, surfaces, basis functions, comparisons and toolpaths (pyvista).

This is the only module that imports pyvista, and it does so inside the
functions that draw, so importing :mod:`lagsym` never loads VTK.  Each
``*_figure`` function takes values (a surface, a curve, plain arrays) and
returns a new :class:`pyvista.Plotter`; nothing here touches pyvista's global
theme.  :func:`save_figure` renders a plotter to an image file atomically, and
:func:`deviation_map` draws and saves in one call.

Rendering needs no display.  Where there is none (no ``DISPLAY`` on Linux),
:func:`rendering_backend` picks a way to render offscreen once per process:
VTK's EGL window on Mesa, else OSMesa, else a private Xvfb server that lives
as long as the process.

Every figure is offscreen when there is no display, and shows in Jupyter as a
static image (the ``static`` backend), which also works when a notebook is run
headless.

Array conventions follow :func:`lagsym.evaluate.evaluate_grid`: a height array
``Z`` sampled on the axes ``x`` and ``y`` has ``Z[i, j] = F(x[i], y[j])``.
"""

from __future__ import annotations

import functools
import os
import shutil
import subprocess
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from .errors import InputError, RenderError

__all__ = [
    "surface_figure",
    "curve_figure",
    "basis_figure",
    "compare_figure",
    "toolpath_figure",
    "deviation_figure",
    "deviation_map",
    "curve_basis_figure",
    "save_figure",
    "image_format",
    "rendering_backend",
    "IMAGE_FORMATS",
    "DEFAULT_WINDOW_SIZE",
]

IMAGE_FORMATS = ("png", "jpg", "jpeg", "tif", "tiff", "bmp")
DEFAULT_WINDOW_SIZE = (1024, 768)

SURFACE_CMAP = "viridis"
DEVIATION_CMAP = "coolwarm"
BASIS_CMAP = "RdBu_r"
POINT_COLOR = "crimson"
NET_COLOR = "black"
FEED_COLOR = "orangered"
RAPID_COLOR = "royalblue"
_CYCLE = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:gray",
          "tab:olive", "tab:cyan")

# A tiny scene rendered in a child process: a render window that cannot get an
# OpenGL context may crash the process that asks, so never ask in this one.
_PROBE = """
import vtkmodules.vtkRenderingOpenGL2, vtkmodules.vtkRenderingCore as rc
from vtkmodules.vtkCommonCore import vtkUnsignedCharArray
w = rc.vtkRenderWindow(); w.SetOffScreenRendering(1); w.SetSize(8, 8)
r = rc.vtkRenderer(); r.SetBackground(1.0, 0.0, 0.0); w.AddRenderer(r); w.Render()
a = vtkUnsignedCharArray(); w.GetPixelData(0, 0, 7, 7, 1, a, 0)
print("ok" if a.GetValue(0) == 255 and a.GetValue(1) == 0 else "wrong pixels")
w.Finalize()
"""

_BAR_COLUMN = 0.55  # width of the colour-bar column of a multi-panel figure, in panels

_OFFSCREEN_WINDOWS = (("egl", "vtkEGLRenderWindow"), ("osmesa", "vtkOSOpenGLRenderWindow"))


# ----------------------------------------------------------------------------- rendering backend


def _has_display() -> bool:
    if sys.platform != "linux":
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def _probe(window_class: str) -> bool:
    env = dict(os.environ, VTK_DEFAULT_OPENGL_WINDOW=window_class)
    env.pop("DISPLAY", None)
    try:
        done = subprocess.run([sys.executable, "-c", _PROBE], env=env, capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.SubprocessError):
        return False
    return done.returncode == 0 and done.stdout.strip() == "ok"


def _die_with_parent() -> None:
    """In the child before exec: ask Linux to end it with SIGTERM when its parent exits."""
    import ctypes
    import signal

    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # 1 = PR_SET_PDEATHSIG


def _start_xvfb() -> str:
    """Start a private Xvfb server that ends with this process; return its display name.

    The kernel ends the server when this process exits (not an ``atexit``
    handler, which would run while VTK still holds its X connection).
    """
    read_fd, write_fd = os.pipe()
    try:
        server = subprocess.Popen(
            ["Xvfb", "-displayfd", str(write_fd), "-screen", "0", "1920x1080x24", "-nolisten", "tcp"],
            pass_fds=(write_fd,),
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            preexec_fn=_die_with_parent,
        )
    finally:
        os.close(write_fd)
    with os.fdopen(read_fd) as f:
        number = f.readline().strip()
    if not number.isdigit():
        server.terminate()
        raise RenderError("Xvfb started but did not report a display number")
    return f":{number}"


@functools.cache
def rendering_backend() -> str:
    """Make sure VTK can render in this process, and say how.

    Called by every figure function; the choice is made once per process.

    Returns
    -------
    str
        ``"display"`` when there is a display (or the platform is not Linux),
        ``"egl"`` or ``"osmesa"`` for VTK's offscreen windows, ``"xvfb"`` for a
        private X server started here, or the window class named by the
        ``VTK_DEFAULT_OPENGL_WINDOW`` variable when that is already set.

    Raises
    ------
    RenderError
        When nothing here can render.
    """
    if _has_display():
        return "display"
    if os.environ.get("VTK_DEFAULT_OPENGL_WINDOW"):
        return os.environ["VTK_DEFAULT_OPENGL_WINDOW"]
    for name, window_class in _OFFSCREEN_WINDOWS:
        if _probe(window_class):
            # Name the window outright: otherwise VTK tries X first and warns on stderr.
            os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = window_class
            return name
    if shutil.which("Xvfb"):
        os.environ["DISPLAY"] = _start_xvfb()
        return "xvfb"
    raise RenderError(
        "no display, and VTK cannot render offscreen here: install Mesa's EGL "
        "(Debian: libegl1 libgl1-mesa-dri) or Xvfb (Debian: xvfb)"
    )


# ----------------------------------------------------------------------------- checks at the edge


def _window_size(size) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in size)
    except (TypeError, ValueError):
        raise InputError(f"window size {size!r} should be two integers (width, height)") from None
    if not (16 <= w <= 8192 and 16 <= h <= 8192):
        raise InputError(f"window size {w}x{h} is out of range: width and height must be 16 to 8192 pixels")
    return w, h


def _samples(n, name: str = "samples") -> int:
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2:
        raise InputError(f"{name} = {n!r} should be an integer of at least 2")
    return int(n)


def _axis(values, name: str) -> np.ndarray:
    a = np.asarray(values, dtype=float)
    if a.ndim != 1 or a.size < 2:
        raise InputError(f"{name} should be a 1-D array of at least 2 values, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name} holds a value that is not finite")
    if not np.all(np.diff(a) > 0):
        k = int(np.argmin(np.diff(a) > 0))
        raise InputError(f"{name} must increase strictly, but {name}[{k}] = {a[k]} and {name}[{k + 1}] = {a[k + 1]}")
    return a


def _heights(z, shape: tuple[int, int], name: str) -> np.ndarray:
    a = np.asarray(z, dtype=float)
    if a.shape != shape:
        raise InputError(f"{name} has shape {a.shape}, but the axes x and y give {shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name} holds a value that is not finite")
    return a


# ----------------------------------------------------------------------------- building blocks


def _plotter(shape=(1, 1), window_size=DEFAULT_WINDOW_SIZE, off_screen: bool | None = None, col_weights=None):
    import pyvista as pv

    size = _window_size(window_size)
    if rendering_backend() != "display":
        off_screen = True  # a window on no screen, or on a private Xvfb, would show nobody anything
    theme = pv.themes.DocumentTheme()
    theme.jupyter_backend = "static"
    theme.font.color = "black"
    theme.font.family = "arial"
    return pv.Plotter(shape=shape, window_size=list(size), off_screen=off_screen, theme=theme,
                      lighting="three lights", border=False, col_weights=col_weights)


def _structured(x: np.ndarray, y: np.ndarray, z: np.ndarray):
    import pyvista as pv

    xx, yy = np.meshgrid(x, y, indexing="ij")
    return pv.StructuredGrid(xx, yy, np.asarray(z, dtype=float))


def _scalar_mesh(x: np.ndarray, y: np.ndarray, z: np.ndarray, name: str, values: np.ndarray | None = None):
    """The surface ``z`` over ``x`` x ``y`` carrying the point array ``name`` (``z`` itself unless ``values``)."""
    mesh = _structured(x, y, z)
    mesh.point_data[name] = np.asarray(z if values is None else values, dtype=float).ravel(order="F")
    return mesh


def _outline(x: np.ndarray, y: np.ndarray):
    return _structured(np.array([x[0], x[-1]]), np.array([y[0], y[-1]]), np.zeros((2, 2))).extract_all_edges()


def _bar(title: str, height_px: int, **extra) -> dict:
    font = max(8, min(16, height_px // 40))
    args = dict(title=title, vertical=True, position_x=0.84, position_y=0.2, width=0.07, height=0.6,
                title_font_size=font + 2, label_font_size=font, fmt="%.3g", color="black")
    args.update(extra)
    return args


def _bar_column(p, row: int, col: int, mapper, title: str, height_px: int) -> None:
    """A colour bar alone in the narrow last column, so it covers no panel."""
    p.subplot(row, col)
    p.add_scalar_bar(mapper=mapper, **_bar(title, height_px, position_x=0.3, width=0.3, height=0.8, position_y=0.08))


def _labels(plotter, units: str, font_size: int = 10) -> None:
    plotter.show_grid(xtitle=f"x ({units})", ytitle=f"y ({units})", ztitle=f"z ({units})", color="black",
                      font_size=font_size, fmt="%.3g")


def _view(plotter, zoom: float = 1.0) -> None:
    # A fixed camera, MATLAB's default 3-D view (azimuth -37.5, elevation 30): the
    # same picture every time, and one a reference image can pin.
    plotter.view_vector((-0.53, -0.69, 0.5), viewup=(0.0, 0.0, 1.0))
    plotter.reset_camera()
    plotter.camera.zoom(zoom)


def _plan_view(plotter, zoom: float = 0.8) -> None:
    plotter.view_xy()
    plotter.reset_camera()
    plotter.camera.zoom(zoom)


def _fit(text: str, width_px: float, largest: int = 14, smallest: int = 5) -> int:
    """A font size at which the longest line of ``text`` fits in ``width_px`` pixels.

    A character of VTK's Arial is at most about 1.2 font sizes wide; the rest is margin.
    """
    longest = max((len(line) for line in text.splitlines()), default=1) or 1
    return int(max(smallest, min(largest, width_px / (1.5 * longest))))


def _z_scale(x_span: float, y_span: float, z_span: float) -> float:
    """Stretch z so a flat part still shows its shape: at least a fifth of the larger plan side."""
    plan = max(x_span, y_span)
    if z_span <= 0 or z_span >= plan / 5:
        return 1.0
    return plan / 5 / z_span


def _title(surface_or_curve) -> str:
    deg = surface_or_curve.degree
    if isinstance(deg, tuple):
        n, m = deg
        d = f"degree {n}" if n == m else f"degree {n} in x, {m} in y"
        return f"Lagrange surface z = F(x, y), {d} ({n + 1}x{m + 1} points)"
    return f"Lagrange curve y = F(x), degree {deg} ({deg + 1} points)"


def _sampled(surface, samples: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    from .evaluate import evaluate_grid

    n = _samples(samples)
    g = surface.grid
    xs = np.linspace(g.x_array[0], g.x_array[-1], n)
    ys = np.linspace(g.y_array[0], g.y_array[-1], n)
    return xs, ys, evaluate_grid(surface, xs, ys)


# ----------------------------------------------------------------------------- figures


def surface_figure(surface, *, samples: int = 61, units: str = "mm", title: str | None = None,
                   cmap: str = SURFACE_CMAP, control_net: bool = True, scalar_bar: bool = True,
                   window_size: Sequence[int] = DEFAULT_WINDOW_SIZE, off_screen: bool | None = None):
    """The shaded surface with its control points and control net (the paper's Figures 6-9).

    Parameters
    ----------
    surface : LagrangeSurface
        The surface to draw, over the box of its control points.
    samples : int
        Samples along each axis.
    units : str
        Length unit shown on the axes and the colour bar.
    title : str, optional
        Defaults to one naming the degree.
    cmap : str
        Colour map for z.
    control_net : bool
        Draw the control points and the net joining them.
    scalar_bar : bool
        Draw the colour bar for z.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    xs, ys, zz = _sampled(surface, samples)
    w, h = _window_size(window_size)
    p = _plotter(window_size=(w, h), off_screen=off_screen)
    name = f"z ({units})"
    p.add_mesh(_scalar_mesh(xs, ys, zz, name), scalars=name, cmap=cmap, smooth_shading=True,
               show_scalar_bar=scalar_bar, scalar_bar_args=_bar(name, h))
    if control_net:
        g = surface.grid
        _add_control(p, g.x_array, g.y_array, g.z_array)
    p.set_scale(zscale=_z_scale(np.ptp(xs), np.ptp(ys), float(np.ptp(zz))))
    _labels(p, units, font_size=max(8, h // 60))
    text = title if title is not None else _title(surface)
    p.add_text(text, position="upper_edge", font_size=_fit(text, w, largest=12), color="black")
    _view(p, zoom=0.9)
    return p


def _add_control(p, x, y, z, size: float = 12.0) -> None:
    import pyvista as pv

    net = _structured(x, y, z)
    p.add_mesh(net.extract_all_edges(), color=NET_COLOR, line_width=2, lighting=False)
    p.add_mesh(pv.PolyData(np.asarray(net.points)), color=POINT_COLOR, point_size=size,
               render_points_as_spheres=True)


def curve_figure(curve, *, samples: int = 401, units: str = "mm", title: str | None = None,
                 window_size: Sequence[int] = DEFAULT_WINDOW_SIZE, off_screen: bool | None = None):
    """The 1-D interpolant with the points it passes through (the paper's Figures 2-3).

    Parameters
    ----------
    curve : LagrangeCurve
        The curve, drawn over the span of its points.
    samples : int
        Samples along x.
    units : str
        Length unit shown on the axes.
    title : str, optional
        Defaults to one naming the degree.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    import pyvista as pv

    n = _samples(samples)
    px, py = curve.points.x_array, curve.points.y_array
    xs = np.linspace(px[0], px[-1], n)
    ys = curve.evaluate(xs)
    p = _plotter(window_size=window_size, off_screen=off_screen)
    chart = pv.Chart2D(x_label=f"x ({units})", y_label=f"y ({units})")
    chart.title = title if title is not None else _title(curve)
    chart.line(xs, ys, color="tab:blue", width=3.0, label="F(x)")
    chart.scatter(px, py, color=POINT_COLOR, size=12, style="o", label="points")
    chart.x_range = _padded(xs.min(), xs.max())
    chart.y_range = _padded(min(ys.min(), py.min()), max(ys.max(), py.max()))
    chart.legend.visible = False
    p.add_chart(chart)
    return p


def curve_basis_figure(curve, *, samples: int = 401, units: str = "mm", window_size: Sequence[int] = DEFAULT_WINDOW_SIZE,
                       off_screen: bool | None = None):
    """The basis polynomials ``L_i(x)`` of a curve's nodes, each 1 at its own node and 0 at the others.

    Parameters
    ----------
    curve : LagrangeCurve
        Supplies the nodes.
    samples : int
        Samples along x.
    units : str
        Length unit of x.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    import pyvista as pv

    from .evaluate import basis_matrix

    n = _samples(samples)
    nodes = curve.points.x_array
    xs = np.linspace(nodes[0], nodes[-1], n)
    lx = basis_matrix(nodes, xs)
    p = _plotter(window_size=window_size, off_screen=off_screen)
    chart = pv.Chart2D(x_label=f"x ({units})", y_label="L_i(x)")
    chart.title = f"Lagrange basis polynomials of degree {curve.degree} on {len(nodes)} nodes"
    for i in range(len(nodes)):
        color = _CYCLE[i % len(_CYCLE)]
        chart.line(xs, lx[:, i], color=color, width=2.5, label=f"L{i + 1}(x)")
        chart.scatter(nodes[i:i + 1], [1.0], color=color, size=10, style="o")
    chart.scatter(nodes, np.zeros_like(nodes), color="black", size=6, style="o")
    chart.x_range = _padded(xs.min(), xs.max())
    chart.y_range = _padded(float(lx.min()), float(lx.max()))
    p.add_chart(chart)
    return p


def _padded(lo: float, hi: float, share: float = 0.06) -> list[float]:
    pad = (hi - lo) * share or 1.0
    return [float(lo - pad), float(hi + pad)]


def basis_figure(surface, *, samples: int = 25, units: str = "mm", window_size: Sequence[int] = DEFAULT_WINDOW_SIZE,
                 off_screen: bool | None = None):
    """The tensor-product basis functions ``L_i(x) L_k(y)`` as small multiples (the paper's Figure 4).

    The panel in column ``i`` and row ``k`` counted from the bottom holds
    ``L_i(x) L_k(y)``, so the panels lie like the nodes in the plane seen from
    above.  All panels share one colour scale, centred on 0; a black dot marks
    the node where the function is 1 (it is 0 at every other node).

    Parameters
    ----------
    surface : LagrangeSurface
        Supplies the nodes.
    samples : int
        Samples along each axis of each panel.
    units : str
        Length unit of x and y, noted in the figure.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    import pyvista as pv

    from .evaluate import basis_matrix

    n_s = _samples(samples)
    g = surface.grid
    nx, ny = g.shape
    xs = np.linspace(g.x_array[0], g.x_array[-1], n_s)
    ys = np.linspace(g.y_array[0], g.y_array[-1], n_s)
    lx = basis_matrix(g.x_array, xs)
    ly = basis_matrix(g.y_array, ys)
    values = np.einsum("ai,bk->ikab", lx, ly)  # values[i, k] = L_i(xs) L_k(ys) on the sample grid
    bound = float(np.abs(values).max())
    scale = max(np.ptp(xs), np.ptp(ys)) / 3 / bound
    w, h = _window_size(window_size)
    p = _plotter(shape=(ny, nx + 1), window_size=(w, h), off_screen=off_screen, col_weights=[1.0] * nx + [_BAR_COLUMN])
    font = _fit("L5(x) L5(y)", w / (nx + _BAR_COLUMN), largest=12)
    actor = None
    for k in range(ny):
        for i in range(nx):
            p.subplot(ny - 1 - k, i)
            actor = p.add_mesh(_scalar_mesh(xs, ys, values[i, k], "L"), scalars="L", cmap=BASIS_CMAP,
                               clim=(-bound, bound), smooth_shading=True, show_scalar_bar=False)
            node = np.array([[g.x_array[i], g.y_array[k], 1.0]])
            p.add_mesh(pv.PolyData(node), color="black", point_size=6, render_points_as_spheres=True)
            p.add_text(f"L{i + 1}(x) L{k + 1}(y)", position="upper_left", font_size=font, color="black")
            p.set_scale(zscale=scale)
            _view(p, zoom=1.0)
    p.subplot(ny - 1, 0)
    p.add_text(f"x, y in {units}", position="lower_left", font_size=max(6, font - 2), color="gray")
    _bar_column(p, ny // 2, nx, actor.mapper, "L_i L_k", h)
    return p


def compare_figure(x, y, surfaces: Mapping[str, np.ndarray], *, reference: str = "Lagrange", units: str = "mm",
                   control_points=None, window_size: Sequence[int] = DEFAULT_WINDOW_SIZE,
                   off_screen: bool | None = None):
    """Surfaces side by side, with the deviation of each from a reference below it (the paper's Figure 10).

    Top row: every surface, on one colour scale for z.  Bottom row: for each
    surface but the reference, ``Z - Z_reference`` seen from above, on one
    colour scale symmetric about 0; under the reference, the plan of the
    control points.

    Parameters
    ----------
    x, y : 1-D array
        Strictly increasing sample axes, shared by every surface.
    surfaces : mapping of str to 2-D array
        Method name to heights ``Z[i, j]`` at ``(x[i], y[j])``, in drawing order.
    reference : str
        The key the others are measured against.
    units : str
        Length unit of x, y and z.
    control_points : (K, 3) array, optional
        Points marked on every surface.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    x, y = _axis(x, "x"), _axis(y, "y")
    if not surfaces:
        raise InputError("no surfaces to compare")
    if reference not in surfaces:
        raise InputError(f"reference {reference!r} is not among the surfaces: {', '.join(map(repr, surfaces))}")
    zs = {name: _heights(z, (x.size, y.size), f"surface {name!r}") for name, z in surfaces.items()}
    pts = _points(control_points, "control_points") if control_points is not None else None
    ref = zs[reference]
    zlo = min(float(z.min()) for z in zs.values())
    zhi = max(float(z.max()) for z in zs.values())
    dmax = max((float(np.abs(z - ref).max()) for z in zs.values()), default=0.0) or 1.0
    scale = _z_scale(np.ptp(x), np.ptp(y), zhi - zlo)
    names = list(zs)
    n = len(names)
    w, h = _window_size(window_size)
    p = _plotter(shape=(2, n + 1), window_size=(w, h), off_screen=off_screen, col_weights=[1.0] * n + [_BAR_COLUMN])
    panel = w / (n + _BAR_COLUMN)
    zname, dname = f"z ({units})", f"dev. ({units})"
    top = _fit("\n".join(names), panel, largest=14)
    bottom = _fit("\n".join(f"{name} - {reference}" for name in names), panel, largest=12)
    z_actor = d_actor = None
    for col, name in enumerate(names):
        p.subplot(0, col)
        z_actor = p.add_mesh(_scalar_mesh(x, y, zs[name], zname), scalars=zname, cmap=SURFACE_CMAP,
                             clim=(zlo, zhi), smooth_shading=True, show_scalar_bar=False)
        if pts is not None:
            p.add_mesh(_pointcloud(pts), color=POINT_COLOR, point_size=8, render_points_as_spheres=True)
        p.add_text(name, position="upper_edge", font_size=top, color="black")
        p.set_scale(zscale=scale)
        _view(p, zoom=1.0)
        p.subplot(1, col)
        if name == reference:
            _add_plan(p, x, y, pts, f"{name}\n(reference)", bottom)
            continue
        d = zs[name] - ref
        d_actor = p.add_mesh(_scalar_mesh(x, y, np.zeros_like(d), dname, d), scalars=dname, cmap=DEVIATION_CMAP,
                             clim=(-dmax, dmax), lighting=False, show_scalar_bar=False)
        p.add_mesh(_outline(x, y), color="black", line_width=1, lighting=False)
        text = f"{name} - {reference}\nlargest {np.abs(d).max():.3g} {units}"
        p.add_text(text, position="upper_edge", font_size=bottom, color="black")
        _plan_view(p)
    _bar_column(p, 0, n, z_actor.mapper, zname, h // 2)
    if d_actor is not None:
        _bar_column(p, 1, n, d_actor.mapper, dname, h // 2)
    return p


def _add_plan(p, x, y, pts, text: str, font: int) -> None:
    import pyvista as pv

    p.add_mesh(_outline(x, y), color="gray", line_width=1, lighting=False)
    if pts is not None:
        p.add_mesh(pv.PolyData(np.c_[pts[:, :2], np.zeros(len(pts))]), color=POINT_COLOR, point_size=8,
                   render_points_as_spheres=True)
    p.add_text(text, position="upper_edge", font_size=font, color="black")
    _plan_view(p)


def _points(a, name: str) -> np.ndarray:
    pts = np.asarray(a, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) == 0:
        raise InputError(f"{name} should be an (N, 3) array of x, y, z, got shape {pts.shape}")
    if not np.all(np.isfinite(pts)):
        k = int(np.argmin(np.all(np.isfinite(pts), axis=1)))
        raise InputError(f"{name}[{k}] = {pts[k].tolist()} is not finite")
    return pts


def _pointcloud(pts: np.ndarray):
    import pyvista as pv

    return pv.PolyData(pts)


def _polyline(points: np.ndarray, segments: np.ndarray):
    """Line segments ``points[s] -> points[s + 1]`` for each index ``s`` in ``segments``."""
    import pyvista as pv

    lines = np.column_stack([np.full(len(segments), 2), segments, segments + 1]).ravel()
    return pv.PolyData(points, lines=lines)


def toolpath_figure(surface, moves, *, rapid=None, samples: int = 61, units: str = "mm", title: str | None = None,
                    window_size: Sequence[int] = DEFAULT_WINDOW_SIZE, off_screen: bool | None = None):
    """The cutter path drawn over the surface (the paper's Figures 12 and 14).

    Parameters
    ----------
    surface : LagrangeSurface
        The surface, drawn half transparent over the box of its control points.
    moves : (N, 3) array
        Tool-tip points in the surface's units, in the order the tool visits
        them; consecutive points are joined by straight moves.
    rapid : (N,) array of bool, optional
        ``rapid[k]`` is true when the move that ends at point ``k`` is a rapid
        (``rapid[0]`` is ignored).  Feed moves are drawn in orange-red, rapids
        in blue.  Default: every move is a feed move.
    samples : int
        Samples along each axis of the surface.
    units : str
        Length unit shown on the axes.
    title : str, optional
        Defaults to one giving the degree and the number of moves.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    pts = _points(moves, "moves")
    if rapid is None:
        fast = np.zeros(len(pts), dtype=bool)
    else:
        fast = np.asarray(rapid)
        if fast.shape != (len(pts),) or fast.dtype != bool:
            raise InputError(f"rapid should be a boolean array of shape ({len(pts)},), got {fast.dtype} {fast.shape}")
    xs, ys, zz = _sampled(surface, samples)
    w, h = _window_size(window_size)
    p = _plotter(window_size=(w, h), off_screen=off_screen)
    name = f"z ({units})"
    p.add_mesh(_scalar_mesh(xs, ys, zz, name), scalars=name, cmap=SURFACE_CMAP, smooth_shading=True, opacity=0.55,
               scalar_bar_args=_bar(name, h))
    seg = np.arange(len(pts) - 1)
    feed, quick = seg[~fast[1:]], seg[fast[1:]]
    if feed.size:
        p.add_mesh(_polyline(pts, feed), color=FEED_COLOR, line_width=2, lighting=False)
    if quick.size:
        p.add_mesh(_polyline(pts, quick), color=RAPID_COLOR, line_width=1, lighting=False)
    span_z = float(max(zz.max(), pts[:, 2].max()) - min(zz.min(), pts[:, 2].min()))
    p.set_scale(zscale=_z_scale(max(np.ptp(xs), np.ptp(pts[:, 0])), max(np.ptp(ys), np.ptp(pts[:, 1])), span_z))
    _labels(p, units, font_size=max(8, h // 60))
    deg = surface.degree
    text = title if title is not None else (
        f"Toolpath over the Lagrange surface, degree {deg[0]} x {deg[1]}\n"
        f"{feed.size} feed moves (red), {quick.size} rapids (blue)")
    p.add_text(text, position="upper_edge", font_size=_fit(text, w, largest=12), color="black")
    _view(p, zoom=0.9)
    return p


def deviation_figure(x, y, deviations: Mapping[str, np.ndarray], *, units: str = "mm",
                     window_size: Sequence[int] = DEFAULT_WINDOW_SIZE, off_screen: bool | None = None):
    """One deviation colour map per method, seen from above, on one colour scale symmetric about 0.

    Parameters
    ----------
    x, y : 1-D array
        Strictly increasing sample axes.
    deviations : mapping of str to 2-D array
        Method name to deviations ``D[i, j]`` at ``(x[i], y[j])``.
    units : str
        Length unit of x, y and the deviations.
    window_size : (int, int)
        Image size in pixels.
    off_screen : bool, optional
        Render without a window; forced where there is no display.

    Returns
    -------
    pyvista.Plotter
    """
    x, y = _axis(x, "x"), _axis(y, "y")
    if not deviations:
        raise InputError("no deviations to draw")
    ds = {name: _heights(d, (x.size, y.size), f"deviations {name!r}") for name, d in deviations.items()}
    dmax = max(float(np.abs(d).max()) for d in ds.values()) or 1.0
    n = len(ds)
    w, h = _window_size(window_size)
    p = _plotter(shape=(1, n + 1), window_size=(w, h), off_screen=off_screen, col_weights=[1.0] * n + [_BAR_COLUMN])
    panel = w / (n + _BAR_COLUMN)
    dname = f"dev. ({units})"
    font = _fit("\n".join([*ds, f"largest 0.000 {units}"]), panel, largest=12)
    actor = None
    for col, (name, d) in enumerate(ds.items()):
        p.subplot(0, col)
        actor = p.add_mesh(_scalar_mesh(x, y, np.zeros_like(d), dname, d), scalars=dname, cmap=DEVIATION_CMAP,
                           clim=(-dmax, dmax), lighting=False, show_scalar_bar=False)
        p.add_mesh(_outline(x, y), color="black", line_width=1, lighting=False)
        p.add_text(f"{name}\nlargest {np.abs(d).max():.3g} {units}", position="upper_edge", font_size=font,
                   color="black")
        _plan_view(p)
    _bar_column(p, 0, n, actor.mapper, dname, h)
    return p


# ----------------------------------------------------------------------------- writing images


def image_format(path: str | os.PathLike) -> str:
    """The image format for ``path``, from its suffix (one of :data:`IMAGE_FORMATS`).

    Examples
    --------
    >>> image_format("surface.PNG"), image_format("a/b.jpg")
    ('png', 'jpeg')
    """
    path = Path(path)
    suffix = path.suffix.lower().lstrip(".")
    if suffix not in IMAGE_FORMATS:
        raise InputError(f"{path}: cannot tell the image format from {path.suffix or 'no suffix'!r}; "
                         f"use one of: {', '.join('.' + f for f in IMAGE_FORMATS)}")
    return {"jpg": "jpeg", "tif": "tiff"}.get(suffix, suffix)


def save_figure(plotter, path: str | os.PathLike, *, close: bool = True) -> Path:
    """Render ``plotter`` and write the image to ``path`` atomically.

    The format follows the file's suffix, one of :data:`IMAGE_FORMATS`.

    Parameters
    ----------
    plotter : pyvista.Plotter
        A plotter from one of the ``*_figure`` functions.
    path : str or path-like
        Where to write.
    close : bool
        Close the plotter afterwards (it cannot render again).

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    import io

    from PIL import Image

    from .io import atomic_write

    path = Path(path)
    fmt = image_format(path)
    img = plotter.screenshot(return_img=True)
    if close:
        plotter.close()
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(img)).save(buf, format=fmt)
    with atomic_write(path, "wb") as f:
        f.write(buf.getvalue())
    return path


def deviation_map(x, y, deviations: Mapping[str, np.ndarray], path: str | os.PathLike, *, units: str = "mm",
                  window_size: Sequence[int] = DEFAULT_WINDOW_SIZE) -> Path:
    """Draw :func:`deviation_figure` offscreen and write it to ``path``; returns ``path``."""
    return save_figure(deviation_figure(x, y, deviations, units=units, window_size=window_size, off_screen=True), path)
