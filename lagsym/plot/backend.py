"""How VTK renders in this process, and the one factory of plotters.

Rendering needs no display.  Where there is none (no ``DISPLAY`` on Linux),
:func:`rendering_backend` picks a way to render offscreen once per process:
VTK's EGL window on Mesa, else OSMesa, else a private Xvfb server that lives
as long as the process.  :func:`new_plotter` asks for that choice before it
makes a plotter, so every figure renders wherever lagsym runs.

VTK learns the choice from two environment variables,
``VTK_DEFAULT_OPENGL_WINDOW`` (the window class, read when a render window
is made) and, for the private server, ``DISPLAY`` (read when the window
opens its X connection).  Neither is written for the whole process: they
are set only inside :func:`rendering_environment`, around the making of a
plotter's window, and restored as they were on leaving it, so the
process's environment, and every program it starts, stay as the user left
them.
"""

from __future__ import annotations

import importlib.util

import functools
import os
import shutil
import subprocess
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from ..errors import RenderError
from .checks import check_window_size

__all__ = ["DEFAULT_WINDOW_SIZE", "rendering_backend", "rendering_environment", "new_plotter"]

DEFAULT_WINDOW_SIZE = (1280, 960)  # sharp in the docs, and text still legible scaled to a notebook's width

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

_OFFSCREEN_WINDOWS = (("egl", "vtkEGLRenderWindow"), ("osmesa", "vtkOSOpenGLRenderWindow"))


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
    handler, which would run while VTK still holds its X connection).  It
    runs with ``-noreset``: an X server resets when its last client leaves,
    and a window opened during the reset finds no server ("bad X server
    connection"), which VTK, opening and closing connections, ran into.
    """
    read_fd, write_fd = os.pipe()
    try:
        server = subprocess.Popen(
            ["Xvfb", "-displayfd", str(write_fd), "-screen", "0", "1920x1080x24", "-nolisten", "tcp", "-noreset"],
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
def _chosen() -> tuple[str, tuple[tuple[str, str], ...]]:
    """The backend's name, and the environment variables VTK must see to make a window on it (name, value)."""
    if _has_display():
        return "display", ()
    if os.environ.get("VTK_DEFAULT_OPENGL_WINDOW"):
        return os.environ["VTK_DEFAULT_OPENGL_WINDOW"], ()
    for name, window_class in _OFFSCREEN_WINDOWS:
        if _probe(window_class):
            # Name the window outright: otherwise VTK tries X first and warns on stderr.
            return name, (("VTK_DEFAULT_OPENGL_WINDOW", window_class),)
    if shutil.which("Xvfb"):
        return "xvfb", (("DISPLAY", _start_xvfb()),)
    raise RenderError(
        "no display, and VTK cannot render offscreen here: install Mesa's EGL "
        "(Debian: libegl1 libgl1-mesa-dri) or Xvfb (Debian: xvfb)"
    )


def rendering_backend() -> str:
    """Make sure VTK can render in this process, and say how.

    Called by every figure function; the choice is made once per process,
    and changes nothing in the process's environment
    (:func:`rendering_environment` hands it to VTK).

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
    return _chosen()[0]


_ENVIRONMENT = threading.Lock()  # one block at a time changes the process's variables


@contextmanager
def rendering_environment() -> Iterator[dict[str, str]]:
    """Inside the block, the environment variables VTK reads to make a render window on the chosen backend.

    ``VTK_DEFAULT_OPENGL_WINDOW`` for EGL or OSMesa, ``DISPLAY`` for the
    private Xvfb server (nothing where there is a display, or the variable
    was set already) are set in :data:`os.environ` on entering and restored
    to what they were (or removed) on leaving, also after an error.  Make the
    render window, and open its display, inside the block: VTK reads the
    variables then and not later.  Blocks in several threads take turns;
    another thread reading the environment meanwhile sees the variables.

    Yields
    ------
    dict
        The variables set, by name.

    Raises
    ------
    RenderError
        When nothing here can render (:func:`rendering_backend`).
    """
    variables = dict(_chosen()[1])
    with _ENVIRONMENT:
        before = {name: os.environ.get(name) for name in variables}
        try:
            os.environ.update(variables)
            yield variables
        finally:
            for name, value in before.items():
                if value is None:
                    os.environ.pop(name, None)
                else:
                    os.environ[name] = value


def _has_ipython() -> bool:
    try:
        return importlib.util.find_spec("IPython") is not None
    except (ImportError, ValueError):
        return False


def new_plotter(shape=(1, 1), window_size=DEFAULT_WINDOW_SIZE, off_screen: bool | None = None, col_weights=None):
    """A new :class:`pyvista.Plotter` with its own white theme, on the backend chosen here.

    Parameters
    ----------
    shape : (int, int)
        Rows and columns of panels.
    window_size : (int, int)
        Image size in pixels, 16 to 8192 each.
    off_screen : bool, optional
        Render without a window; forced where there is no display, since a
        window on no screen, or on a private Xvfb, would show nobody anything.
    col_weights : sequence of float, optional
        Relative widths of the columns.

    Returns
    -------
    pyvista.Plotter
        Shown in Jupyter as a static image, which also works headless; the
        global theme is left alone.
    """
    import pyvista as pv

    size = check_window_size(window_size)
    if rendering_backend() != "display":
        off_screen = True
    theme = pv.themes.DocumentTheme()
    if _has_ipython():
        # Notebooks show a static image by default (the same picture -o writes); pyvista refuses to
        # set a notebook backend at all where IPython is not installed, as after a plain install.
        theme.jupyter_backend = "static"
    theme.font.color = "black"
    theme.font.family = "arial"
    with rendering_environment() as variables:
        plotter = pv.Plotter(shape=shape, window_size=list(size), off_screen=off_screen, theme=theme,
                             lighting="three lights", border=False, col_weights=col_weights)
        if "DISPLAY" in variables and hasattr(plotter.ren_win, "EnsureDisplay"):
            plotter.ren_win.EnsureDisplay()  # its X connection opened now, while DISPLAY names the private server
    return plotter
