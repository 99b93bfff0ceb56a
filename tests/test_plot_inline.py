"""The rich display in Jupyter: a surface or a curve as its equation and a small figure.

The display is checked in a real IPython shell, through the formatter the
shell itself calls; the PNG is decoded by hand (stdlib zlib, the PNG filters
undone here) and again with PIL, and compared with a reference image the way
tests/test_plot.py compares every figure.
"""

from __future__ import annotations

import base64
import re
import struct
import subprocess
import sys
import zlib
from fractions import Fraction

import numpy as np
import pytest

from conftest import EXAMPLES, ROOT, missing_system_package
from lagsym.errors import RenderError
from lagsym.grid import grid_from_points
from lagsym.io import read_curve_points, read_points
from lagsym.lagrange import LATEX_TERMS, lagrange_curve, lagrange_surface
from test_plot import check_reference

WIDTH, HEIGHT = 320, 240


@pytest.fixture
def opengl():
    from lagsym import plot

    try:
        plot.rendering_backend()
    except RenderError:
        missing_system_package("libegl1 libegl-mesa0 libgl1-mesa-dri", "an offscreen OpenGL (EGL or OSMesa)")


@pytest.fixture
def shell(tmp_path, monkeypatch):
    """A real IPython shell with lagsym's extension loaded as a user loads it, history kept in memory."""
    from IPython.core.interactiveshell import InteractiveShell
    from traitlets.config import Config

    monkeypatch.setenv("IPYTHONDIR", str(tmp_path))
    config = Config()
    config.HistoryManager.hist_file = ":memory:"
    sh = InteractiveShell.instance(config=config)
    sh.run_line_magic("load_ext", "lagsym")
    yield sh
    InteractiveShell.clear_instance()


@pytest.fixture(scope="module")
def surface4():
    return lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))


@pytest.fixture(scope="module")
def curve3():
    return lagrange_curve(read_curve_points(EXAMPLES / "paper-curve-3rd.json"))


def png_of(html: str) -> bytes:
    found = re.findall(r'<img src="data:image/png;base64,([A-Za-z0-9+/=]+)"', html)
    assert len(found) == 1, html[:400]
    return base64.b64decode(found[0])


def decode_png(data: bytes) -> np.ndarray:
    """An 8-bit RGB or RGBA PNG decoded with zlib alone: the chunks read and the row filters undone."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        assert zlib.crc32(kind + body) == struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])[0]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    w, h, depth, colour, _, _, interlace = header
    assert depth == 8 and colour in (2, 6) and interlace == 0, header
    bpp = 3 if colour == 2 else 4
    raw, stride = zlib.decompress(idat), w * bpp
    rows, prev = [], bytearray(stride)
    for r in range(h):
        kind, line = raw[r * (stride + 1)], raw[r * (stride + 1) + 1:(r + 1) * (stride + 1)]
        out = bytearray(stride)
        for i in range(stride):
            a = out[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if kind == 0:
                pred = 0
            elif kind == 1:
                pred = a
            elif kind == 2:
                pred = b
            elif kind == 3:
                pred = (a + b) // 2
            else:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            out[i] = (line[i] + pred) & 255
        rows.append(bytes(out))
        prev = out
    return np.frombuffer(b"".join(rows), dtype=np.uint8).reshape(h, w, bpp)[..., :3]


def drawn_share(img: np.ndarray) -> float:
    """Share of the pixels that differ from the white background."""
    return float((np.abs(img.astype(int) - 255).max(axis=-1) > 30).mean())


# ----------------------------------------------------------------------------- the display in a shell


def test_a_surface_shows_its_equation_and_a_figure(opengl, shell, surface4):
    from PIL import Image
    import io

    data, _ = shell.display_formatter.format(surface4)
    assert {"text/plain", "text/latex", "text/html"} <= set(data)
    html = data["text/html"]
    latex = surface4._repr_latex_()
    assert latex.startswith("$z = ") and f"$${latex[1:-1]}$$" in html
    assert r"\frac{x^{4} y^{4}}{2880}" in html  # the exact x^4 y^4 coefficient, -1/2880, of Example 4
    png = png_of(html)
    img = decode_png(png)
    assert img.shape == (HEIGHT, WIDTH, 3)
    assert drawn_share(img) > 0.2, drawn_share(img)
    assert np.array_equal(img, np.asarray(Image.open(io.BytesIO(png)).convert("RGB")))
    check_reference(img, "surface_thumbnail")
    assert 10_000 < len(html.encode()) < 100_000  # docs/plotting.md: "a few tens of kilobytes"


def test_a_curve_shows_its_equation_and_a_line_plot(opengl, shell, curve3):
    data, _ = shell.display_formatter.format(curve3)
    html = data["text/html"]
    assert f"$${curve3._repr_latex_()[1:-1]}$$" in html and html.count("<img") == 1
    img = decode_png(png_of(html))
    assert img.shape == (HEIGHT, WIDTH, 3) and drawn_share(img) > 0.03
    blue = (np.abs(img.astype(int) - (31, 119, 180)).max(axis=-1) < 40).mean()  # the curve's tab:blue
    assert blue > 0.005
    check_reference(img, "curve_thumbnail")


def test_other_values_keep_their_display(shell):
    data, _ = shell.display_formatter.format([1, 2])
    assert set(data) == {"text/plain"}


def test_a_big_equation_keeps_the_html_small(opengl, shell):
    """A 9 x 9 grid shows its 81 terms in full; 11 x 11 (121 terms) shows the summary, not a page of LaTeX."""
    for n, full in ((9, True), (11, False)):
        pts = [(i, k, Fraction((7 * i * i + 3 * k ** 3 + i * k) % 13 + 1, 3)) for i in range(n) for k in range(n)]
        s = lagrange_surface(grid_from_points(pts))
        html = shell.display_formatter.format(s)[0]["text/html"]
        terms = sum(1 for row in s.coefficients for c in row if c)
        assert (terms <= LATEX_TERMS) == full
        assert len(html.encode()) < 80_000, len(html.encode())
        if not full:
            assert "$$z = F$$" in html and f"{terms} terms: <code>.expr</code> holds them all" in html
        assert decode_png(png_of(html)).shape == (HEIGHT, WIDTH, 3)


@pytest.fixture
def fresh_render_check():
    """``can_render`` asked afresh, and forgotten again afterwards."""
    from lagsym.plot import inline

    inline.can_render.cache_clear()
    yield inline
    inline.can_render.cache_clear()


def test_no_backend_falls_back_to_the_latex_without_a_traceback(shell, surface4, fresh_render_check, monkeypatch,
                                                                  capfd):
    """Where nothing can render, the HTML is left out (Jupyter shows the LaTeX), nothing is printed, and the
    backend is sought once, not at every display."""
    asked = []

    def cannot_render():
        asked.append(1)
        raise RenderError("no display, and VTK cannot render offscreen here")

    monkeypatch.setattr(fresh_render_check, "rendering_backend", cannot_render)
    for _ in range(2):
        data, _ = shell.display_formatter.format(surface4)
        assert "text/html" not in data and data["text/latex"] == surface4._repr_latex_()
    assert len(asked) == 1
    out, err = capfd.readouterr()
    assert "Traceback" not in out + err and "RenderError" not in out + err


def test_a_render_that_fails_midway_falls_back_too(shell, surface4, fresh_render_check, monkeypatch, capfd):
    """A backend that is found but fails when the figure is drawn: the LaTeX alone, nothing printed."""
    import lagsym.plot.backend as backend

    def fails(*args, **kwargs):
        raise RuntimeError("the OpenGL context was lost")

    monkeypatch.setattr(fresh_render_check, "rendering_backend", lambda: "egl")
    monkeypatch.setattr(backend, "rendering_backend", fails)
    data, _ = shell.display_formatter.format(surface4)
    assert "text/html" not in data and "text/latex" in data
    out, err = capfd.readouterr()
    assert "Traceback" not in out + err and "OpenGL context" not in out + err


# ----------------------------------------------------------------------------- registration and imports


def _run(code: str) -> str:
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def test_import_lagsym_without_ipython_loads_neither_ipython_nor_pyvista():
    out = _run("import sys, lagsym; from lagsym import lagrange_surface; "
               "print(sorted(m for m in ('IPython', 'pyvista', 'vtkmodules') if m in sys.modules))")
    assert out == "[]"


def test_import_lagsym_in_a_running_shell_registers_the_display():
    out = _run(
        "import sys\n"
        "from IPython.core.interactiveshell import InteractiveShell\n"
        "from traitlets.config import Config\n"
        "c = Config(); c.HistoryManager.hist_file = ':memory:'\n"
        "html = InteractiveShell.instance(config=c).display_formatter.formatters['text/html']\n"
        "import lagsym\n"
        "print(sorted(k[1] for k in html.deferred_printers if k[0] == 'lagsym.lagrange'),\n"
        "      sorted(m for m in ('pyvista', 'vtkmodules', 'lagsym.plot', 'lagsym.lagrange') if m in sys.modules))"
    )
    assert out == "['LagrangeCurve', 'LagrangeSurface'] []"


def test_a_terminal_shell_renders_nothing():
    """A terminal IPython asks only for text/plain: no figure is drawn, pyvista is never loaded."""
    out = _run(
        "import sys\n"
        "from IPython.terminal.interactiveshell import TerminalInteractiveShell\n"
        "from traitlets.config import Config\n"
        "c = Config(); c.HistoryManager.hist_file = ':memory:'\n"
        "sh = TerminalInteractiveShell.instance(config=c)\n"
        "from lagsym import lagrange_surface, read_points\n"
        "s = lagrange_surface(read_points('examples/paper-example-2.json'))\n"
        "print(sorted(sh.display_formatter.format(s)[0]), 'pyvista' in sys.modules)"
    )
    assert out == "['text/plain'] False"


def test_plotting_page_states_the_thumbnail_size():
    from lagsym.plot.inline import THUMBNAIL_SIZE

    page = " ".join((ROOT / "docs" / "plotting.md").read_text().split())
    assert THUMBNAIL_SIZE == (WIDTH, HEIGHT) and f"then a {WIDTH} x {HEIGHT} PNG rendered offscreen" in page
    assert f"more than {LATEX_TERMS} terms shows the one-line summary" in page


def test_ipython_without_a_shell_is_left_alone():
    out = _run("import IPython, sys, lagsym; print(IPython.get_ipython(), 'lagsym.plot' in sys.modules)")
    assert out == "None False"


@pytest.mark.slow
def test_a_notebook_shows_the_surface_as_the_last_expression(opengl, tmp_path):
    """In a real kernel, importing lagsym is enough: the cell's result carries the HTML and the LaTeX."""
    import nbclient
    import nbformat

    code = (f"import sys; sys.path.insert(0, {str(ROOT)!r})\n"
            "from lagsym import lagrange_surface, read_points\n"
            f"lagrange_surface(read_points({str(EXAMPLES / 'paper-example-2.json')!r}))")
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(code)])
    nbclient.NotebookClient(nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
                            ).execute()
    outputs = nb.cells[0].outputs
    assert [o.output_type for o in outputs] == ["execute_result"], outputs
    data = outputs[0].data
    assert data["text/latex"].startswith("$z = ") and "LagrangeSurface(4x4 nodes" in data["text/plain"]
    assert decode_png(png_of(data["text/html"])).shape == (HEIGHT, WIDTH, 3)
