"""Pictures, rendered offscreen for real and checked as pixels.

Every figure is rendered at a fixed size and checked three ways: the image has
the size asked for, it is not blank (a fair share of pixels differ from the
white background), and it matches a stored reference image within a
tolerance.  The reference check is shown to fail for a blank image and for a
picture taken with the camera turned.  To store new reference images after a
deliberate change to a figure, run

    LAGSYM_UPDATE_REFERENCE_IMAGES=1 python3 -m pytest -q tests/test_plot.py

and look at every image in tests/reference_images/ before committing it.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import pyvista as pv
from PIL import Image

from conftest import EXAMPLES, ROOT, missing_system_package, need_opengl
from lagsym import plot
from lagsym.errors import InputError
from lagsym.evaluate import evaluate_grid, evaluate_points
from lagsym.io import read_curve_points, read_points
from lagsym.lagrange import lagrange_curve, lagrange_surface
from lagsym.plot.surface import sampled_surface
from lagsym.sampling import sample_grid


@pytest.fixture(autouse=True, scope="module")
def _offscreen_opengl():
    """Every test here draws: without an OpenGL to draw with, they skip naming the packages to install."""
    need_opengl("the pictures")


REFERENCE = Path(__file__).resolve().parent / "reference_images"
UPDATE = os.environ.get("LAGSYM_UPDATE_REFERENCE_IMAGES") == "1"
SIZE = (320, 240)
WIDE = (480, 300)

# Two images are compared block by block (8x8 pixel averages, which forgive
# anti-aliasing and text a pixel off, as differ between OpenGL drivers): the
# score is the share of the drawn blocks whose colour changed by more than
# CHANGED (0-255).  A blank image scores about 0.85, a camera turned by 5
# degrees about 0.3, leaving out the control net about 0.15.
BLOCK = 8
CHANGED = 16.0
TOLERANCE = 0.08


# ----------------------------------------------------------------------------- helpers


def _blocks(img: np.ndarray) -> np.ndarray:
    h, w = (img.shape[0] // BLOCK) * BLOCK, (img.shape[1] // BLOCK) * BLOCK
    img = img[:h, :w, :3].astype(float)
    return img.reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK, 3).mean(axis=(1, 3))


def image_difference(a: np.ndarray, b: np.ndarray) -> float:
    """Share of the blocks drawn in either image (not white) whose mean colour differs by more than CHANGED."""
    if a.shape != b.shape:
        return 1.0
    ba, bb = _blocks(a), _blocks(b)
    changed = np.abs(ba - bb).mean(axis=-1) > CHANGED
    drawn = (np.abs(ba - 255).max(axis=-1) > 8) | (np.abs(bb - 255).max(axis=-1) > 8)
    return float(changed.sum() / max(int(drawn.sum()), 1))


def render(plotter) -> np.ndarray:
    img = plotter.screenshot(return_img=True)
    plotter.close()
    return np.asarray(img)


def ink(img: np.ndarray) -> float:
    """Share of pixels that are not the white background."""
    return float((np.abs(img[..., :3].astype(int) - 255).max(axis=-1) > 30).mean())


def check_reference(img: np.ndarray, name: str) -> None:
    path = REFERENCE / f"{name}.png"
    if UPDATE or not path.exists():
        if not UPDATE:
            pytest.fail(f"no reference image {path}; run with LAGSYM_UPDATE_REFERENCE_IMAGES=1 to store one")
        REFERENCE.mkdir(exist_ok=True)
        Image.fromarray(img).save(path, optimize=True)
    ref = np.asarray(Image.open(path).convert("RGB"))
    diff = image_difference(img, ref)
    assert diff <= TOLERANCE, f"{name}: {diff:.1%} of the picture differs from {path.name} (tolerance {TOLERANCE:.0%})"


def check_picture(img: np.ndarray, size, least_ink: float) -> None:
    w, h = size
    assert img.shape == (h, w, 3)
    assert ink(img) >= least_ink, f"only {ink(img):.1%} of the pixels are drawn"


# ----------------------------------------------------------------------------- data


@pytest.fixture(scope="module")
def surface4():
    return lagrange_surface(read_points(EXAMPLES / "paper-example-4.json"))


@pytest.fixture(scope="module")
def surface2():
    return lagrange_surface(read_points(EXAMPLES / "paper-example-2.json"))


@pytest.fixture(scope="module")
def curve3():
    return lagrange_curve(read_curve_points(EXAMPLES / "paper-curve-3rd.json"))


def comparison(surface):
    """Stand-ins for the other methods' surfaces: plain, fixed arrays."""
    x = np.linspace(1.0, 5.0, 33)
    y = np.linspace(1.0, 5.0, 33)
    z = evaluate_grid(surface, x, y)
    bump = np.outer(np.sin(np.pi * (x - 1) / 4), np.sin(np.pi * (y - 1) / 4))
    return x, y, {"Lagrange": z, "Bezier": z - 0.6 * bump, "B-spline": z - 0.4 * bump, "Hermite": z + 0.3 * bump}


def raster(surface, rows: int = 7, per_row: int = 25, safe_z: float = 5.0):
    """A zigzag path along x over the surface, with rapids in and out at ``safe_z``."""
    pts, rapid = [(1.0, 1.0, safe_z)], [False]
    for j, y in enumerate(np.linspace(1.0, 5.0, rows)):
        xs = np.linspace(1.0, 5.0, per_row)[:: 1 if j % 2 == 0 else -1]
        zs = evaluate_points(surface, xs, np.full_like(xs, y))
        for k, (x, z) in enumerate(zip(xs, zs)):
            pts.append((x, y, z))
            rapid.append(j == 0 and k == 0)
    pts.append((pts[-1][0], pts[-1][1], safe_z))
    rapid.append(True)
    return np.array(pts), np.array(rapid)


# ----------------------------------------------------------------------------- the figures


def test_surface_figure(surface4):
    img = render(plot.surface_figure(surface4, samples=41, window_size=SIZE))
    check_picture(img, SIZE, 0.12)
    check_reference(img, "surface")


def test_surface_colours_span_the_colour_map(surface4):
    """The shaded surface alone (no colour bar, no net) shows both ends of the colour map."""
    import matplotlib

    img = render(plot.surface_figure(surface4, samples=41, window_size=SIZE, scalar_bar=False, control_net=False,
                                     title=""))
    lut = matplotlib.colormaps[plot.SURFACE_CMAP](np.linspace(0.0, 1.0, 64))[:, :3] * 255
    px = img.reshape(-1, 3).astype(float)
    px = px[np.abs(px - 255).max(axis=1) > 30]
    # Shading scales a colour's brightness, so match directions in RGB space, not values.
    unit = px / np.linalg.norm(px, axis=1, keepdims=True).clip(1e-9)
    lut_unit = lut / np.linalg.norm(lut, axis=1, keepdims=True)
    nearest = np.argmax(unit @ lut_unit.T, axis=1)
    close = np.max(unit @ lut_unit.T, axis=1) > 0.998
    hit = np.bincount(nearest[close], minlength=len(lut)) > 20
    positions = np.flatnonzero(hit) / (len(lut) - 1)
    assert positions.min() <= 0.15 and positions.max() >= 0.85, positions
    assert hit.mean() >= 0.5, f"only {hit.mean():.0%} of the colour map shows"


def test_curve_figure(curve3):
    img = render(plot.curve_figure(curve3, window_size=SIZE))
    check_picture(img, SIZE, 0.03)
    # The curve is drawn in its own colour, and the points in theirs.
    blue = (np.abs(img.astype(int) - (31, 119, 180)).max(axis=-1) < 40).mean()
    red = (np.abs(img.astype(int) - (220, 20, 60)).max(axis=-1) < 40).mean()
    assert blue > 0.005 and red > 0.001
    check_reference(img, "curve")


def test_curve_basis_figure(curve3):
    img = render(plot.curve_basis_figure(curve3, window_size=SIZE))
    check_picture(img, SIZE, 0.05)
    check_reference(img, "curve_basis")


@pytest.mark.slow
def test_basis_figure(surface2):
    img = render(plot.basis_figure(surface2, samples=15, window_size=WIDE))
    check_picture(img, WIDE, 0.08)
    check_reference(img, "basis")


def test_compare_figure(surface4):
    x, y, surfaces = comparison(surface4)
    pts = np.array(surface4.grid.points(), dtype=float)
    img = render(plot.compare_figure(x, y, surfaces, control_points=pts, window_size=WIDE))
    check_picture(img, WIDE, 0.12)
    check_reference(img, "compare")


def test_toolpath_figure(surface4):
    moves, rapid = raster(surface4)
    img = render(plot.toolpath_figure(surface4, moves, rapid=rapid, samples=31, window_size=SIZE))
    check_picture(img, SIZE, 0.11)
    # Feed moves and rapids are drawn, each in its own colour.
    red = (np.abs(img.astype(int) - (255, 69, 0)).max(axis=-1) < 40).mean()
    blue = (np.abs(img.astype(int) - (65, 105, 225)).max(axis=-1) < 40).mean()
    assert red > 0.003 and blue > 0.0005
    check_reference(img, "toolpath")


def drawn_bounds(p) -> tuple[float, ...]:
    """The bounds of what a figure draws (meshes), its axes grid left out."""
    b = np.array([a.bounds for a in p.actors.values() if isinstance(a, pv.Actor)])
    return (*[v for lo, hi in zip(b[:, 0::2].min(axis=0), b[:, 1::2].max(axis=0)) for v in (lo, hi)],)


def check_axes_read_true_values(p) -> None:
    """The axes grid holds the drawing, its labels read true heights, and they lie on round values (or the ends)."""
    axes = p.renderer.cube_axes_actor
    gx0, gx1, gy0, gy1, gz0, gz1 = axes.GetBounds()
    x0, x1, y0, y1, z0, z1 = drawn_bounds(p)
    k = p.scale[2]
    assert gx0 <= x0 and gx1 >= x1 and gy0 <= y0 and gy1 >= y1 and gz0 <= z0 * k + 1e-9 and gz1 >= z1 * k - 1e-9
    assert axes.GetXAxisRange() == pytest.approx((gx0, gx1)) and axes.GetYAxisRange() == pytest.approx((gy0, gy1))
    assert axes.GetZAxisRange() == pytest.approx((gz0 / k, gz1 / k))  # the drawing's heights over its z scale


def test_toolpath_figure_is_in_machine_millimetres(surface4):
    """Placed at 20 mm per unit from (100, 0, -5), the surface and the moves share the machine's millimetres."""
    from lagsym.machine import Placement

    moves, rapid = raster(surface4)
    moves_mm = moves * 20.0 + (100.0, 0.0, -5.0)
    p = plot.toolpath_figure(surface4, moves_mm, rapid=rapid, placement=Placement(20.0, (100.0, 0.0, -5.0)),
                             samples=9, window_size=SIZE, z_exaggeration=1)
    x0, x1, y0, y1, z0, z1 = drawn_bounds(p)
    check_axes_read_true_values(p)
    p.close()
    # The control box is [1, 5] x [1, 5]; the highest point is the safe height 5 (surface units).
    assert (x0, x1, y0, y1) == (120.0, 200.0, 20.0, 100.0)
    zs = np.array(surface4.grid.points(), dtype=float)[:, 2]
    assert z1 == 5.0 * 20 - 5 and z0 <= zs.min() * 20 - 5


def test_deviation_map_writes_a_png(surface4, tmp_path):
    x, y, surfaces = comparison(surface4)
    devs = {name: surfaces["Lagrange"] - z for name, z in surfaces.items() if name != "Lagrange"}
    out = plot.deviation_map(x, y, devs, tmp_path / "dev.png", window_size=WIDE)
    assert out == tmp_path / "dev.png"
    img = np.asarray(Image.open(out).convert("RGB"))
    check_picture(img, WIDE, 0.07)
    check_reference(img, "deviation")


def _warmth(img: np.ndarray, box) -> float:
    """Red minus blue over the saturated pixels of ``img[r0:r1, c0:c1]``: above 0 when the panel is mostly red."""
    r0, r1, c0, c1 = box
    px = img[r0:r1, c0:c1].reshape(-1, 3).astype(float)
    px = px[px.max(axis=1) - px.min(axis=1) > 40]
    return float((px[:, 0] - px[:, 2]).mean()) if len(px) else 0.0


@pytest.mark.slow
def test_one_sign_for_deviations(surface4):
    """Both deviation pictures draw d = z_f - z_a: Hermite lies above the reference (blue), Bezier below (red)."""
    x, y, surfaces = comparison(surface4)
    order = {"Lagrange": surfaces["Lagrange"], "Hermite": surfaces["Hermite"], "Bezier": surfaces["Bezier"]}
    w, h = 640, 400
    both = render(plot.compare_figure(x, y, order, window_size=(w, h)))
    panel = int(w / 3.55)
    hermite, bezier = (h // 2, h, panel, 2 * panel), (h // 2, h, 2 * panel, 3 * panel)
    assert _warmth(both, hermite) < -20 and _warmth(both, bezier) > 20
    z_f = surfaces["Lagrange"]
    alone = render(plot.deviation_figure(x, y, {"Hermite": z_f - surfaces["Hermite"], "Bezier": z_f - surfaces["Bezier"]},
                                         reference="Lagrange", window_size=(w, 250)))
    panel = int(w / 2.55)
    assert _warmth(alone, (0, 250, 0, panel)) < -20 and _warmth(alone, (0, 250, panel, 2 * panel)) > 20


def test_every_comparison_panel_has_axes(surface4):
    x, y, surfaces = comparison(surface4)
    p = plot.compare_figure(x, y, surfaces, window_size=WIDE)
    n = len(surfaces)
    bottom = [p.renderers[p.renderers.loc_to_index((1, col))] for col in range(n)]
    for r in bottom:
        axes = r.cube_axes_actor
        assert axes is not None and axes.GetXAxisVisibility() and axes.GetYAxisVisibility()
        assert axes.GetXTitle() == "x (mm)" and axes.GetYTitle() == "y (mm)"
    p.close()
    d = plot.deviation_figure(x, y, {"Bezier": surfaces["Lagrange"] - surfaces["Bezier"]}, window_size=WIDE)
    assert d.renderers[0].cube_axes_actor.GetYTitle() == "y (mm)"
    d.close()


def test_z_exaggeration(tmp_path):
    """Example 1 rises 30 mm over a 4 x 2 mm box: squeezed by default, the ticks still read the true heights."""
    s1 = lagrange_surface(read_points(EXAMPLES / "paper-example-1.json"))
    zs = [float(p[2]) for p in s1.grid.points()]
    p = plot.surface_figure(s1, samples=9, window_size=SIZE)
    assert p.scale[2] == pytest.approx(4.0 / (max(zs) - min(zs)))  # the drawn height equals the larger plan side
    # the labels on round heights: 7 to 37 mm labelled 0 to 40 in steps of 10
    assert p.renderer.cube_axes_actor.GetZAxisRange() == pytest.approx((0.0, 40.0))
    check_axes_read_true_values(p)
    p.close()
    p = plot.surface_figure(s1, samples=9, window_size=SIZE, z_exaggeration=1)
    assert p.scale[2] == 1.0
    p.close()
    img = render(plot.surface_figure(s1, samples=21, window_size=SIZE))
    check_picture(img, SIZE, 0.12)
    check_reference(img, "surface_example1")
    with pytest.raises(InputError, match="z exaggeration -2 must be a positive number"):
        plot.surface_figure(s1, z_exaggeration=-2)


def runge_brute_force(n: int, samples: int = 81) -> float:
    """Largest |f - F| of the n x n Lagrange interpolant of 1/(1 + 4(x^2 + y^2)) on [-2, 2]^2, by the basis products."""
    nodes = np.linspace(-2.0, 2.0, n)
    t = np.linspace(-2.0, 2.0, samples)
    basis = np.ones((samples, n))
    for i in range(n):
        for k in range(n):
            if k != i:
                basis[:, i] *= (t - nodes[k]) / (nodes[i] - nodes[k])
    z = 1 / (1 + 4 * (nodes[:, None] ** 2 + nodes[None, :] ** 2))
    f = 1 / (1 + 4 * (t[:, None] ** 2 + t[None, :] ** 2))
    return float(np.abs(basis @ z @ basis.T - f).max())


def test_growth_past_degree_6():
    """Figure 11's numbers: the Lagrange deviation against the degree, checked by brute force."""
    from lagsym.formula import parse_formula

    g = plot.degree_growth(parse_formula("1/(1 + 4*(x**2 + y**2))"), (-2, 2, -2, 2), degrees=[2, 4, 6, 8, 10])
    assert g.degrees == (2, 4, 6, 8, 10) and list(g.largest) == ["Lagrange", "B-spline"]
    expected = [runge_brute_force(d + 1) for d in g.degrees]
    assert g.largest["Lagrange"] == pytest.approx(expected, rel=1e-9)
    lag = g.largest["Lagrange"]
    assert lag[2] < lag[3] < lag[4] and lag[4] > 5 * lag[2]  # past degree 6 it grows greatly
    img = render(plot.growth_figure(g, window_size=SIZE))
    check_picture(img, SIZE, 0.03)
    check_reference(img, "growth")


def test_growth_refuses_a_runaway_degree():
    from lagsym.formula import parse_formula

    with pytest.raises(InputError, match="degree 40 is out of range: give degrees from 1 to 20"):
        plot.degree_growth(parse_formula("x"), (0, 1, 0, 1), degrees=[2, 40])


# ----------------------------------------------------------------------------- the checks themselves


def test_reference_check_fails_on_a_blank_image():
    ref = np.asarray(Image.open(REFERENCE / "surface.png").convert("RGB"))
    blank = np.full_like(ref, 255)
    assert image_difference(blank, ref) > 0.5
    assert ink(blank) == 0.0


def test_reference_check_fails_when_the_camera_moves(surface4):
    p = plot.surface_figure(surface4, samples=41, window_size=SIZE)
    p.camera.azimuth += 10.0
    turned = render(p)
    ref = np.asarray(Image.open(REFERENCE / "surface.png").convert("RGB"))
    assert ink(turned) > 0.12  # a real picture ...
    assert image_difference(turned, ref) > TOLERANCE  # ... but not the one expected


def test_reference_check_fails_for_another_surface(surface2):
    img = render(plot.surface_figure(surface2, samples=41, window_size=SIZE))
    ref = np.asarray(Image.open(REFERENCE / "surface.png").convert("RGB"))
    assert image_difference(img, ref) > TOLERANCE


# ----------------------------------------------------------------------------- values in, no global state


def test_figures_leave_the_global_theme_alone(surface2):
    import pyvista as pv

    before = pv.global_theme.to_dict()
    p = plot.surface_figure(surface2, samples=5, window_size=SIZE)
    assert p.theme.jupyter_backend == "static"  # inline in Jupyter, also when run headless
    p.close()
    assert pv.global_theme.to_dict() == before


@pytest.mark.slow
def test_jupyter_shows_a_static_image_headless(tmp_path):
    """A notebook run headless, as CI runs one, gets the figure inline as a PNG."""
    import nbclient
    import nbformat

    code = (
        f"import sys; sys.path.insert(0, {str(ROOT)!r})\n"
        "from lagsym import plot\n"
        "from lagsym.io import read_points\n"
        "from lagsym.lagrange import lagrange_surface\n"
        f"s = lagrange_surface(read_points({str(EXAMPLES / 'paper-example-2.json')!r}))\n"
        "plot.surface_figure(s, samples=9, window_size=(200, 150)).show()"
    )
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(code)])
    nbclient.NotebookClient(nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
                            ).execute()
    outputs = nb.cells[0].outputs
    assert [o.output_type for o in outputs] == ["display_data"], outputs
    assert "image/png" in outputs[0].data


def test_importing_lagsym_does_not_load_vtk():
    code = "import sys, lagsym, lagsym.plot, lagsym.cli.plot, lagsym.cli; assert 'pyvista' not in sys.modules " \
           "and 'vtkmodules' not in sys.modules, sorted(m for m in sys.modules if 'vtk' in m)[:5]"
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)


def test_rendering_backend_is_known():
    assert plot.rendering_backend() in ("display", "egl", "osmesa", "xvfb") or \
        plot.rendering_backend() == os.environ.get("VTK_DEFAULT_OPENGL_WINDOW")


@pytest.mark.slow
@pytest.mark.skipif(sys.platform != "linux", reason="Xvfb is the Linux fallback")
def test_xvfb_fallback_renders():
    """The last resort where neither EGL nor OSMesa works: a private Xvfb server, gone with its process."""
    if shutil.which("Xvfb") is None:
        missing_system_package("xvfb", "Xvfb")
    code = (
        "import os; from lagsym.plot.backend import _start_xvfb\n"
        "os.environ['DISPLAY'] = _start_xvfb()\n"
        "os.environ['VTK_DEFAULT_OPENGL_WINDOW'] = 'vtkXOpenGLRenderWindow'\n"
        "import pyvista as pv\n"
        "p = pv.Plotter(off_screen=True, window_size=(64, 48)); p.add_mesh(pv.Sphere(), color='red')\n"
        "img = p.screenshot(return_img=True); p.close()\n"
        "print(int((img[..., 1] < 60).mean() * 100))\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "VTK_DEFAULT_OPENGL_WINDOW")}
    done = subprocess.run([sys.executable, "-c", code], env=env, cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert int(done.stdout.split()[-1]) >= 5  # a red sphere fills part of the picture


_ENVIRONMENT_AFTER_A_FIGURE = """
import os, subprocess, sys
before = dict(os.environ)
from lagsym.cli import main
from lagsym.plot import backend
status = main(['plot', {points!r}, '-o', {png!r}])
p = backend.new_plotter(window_size=(64, 48)); window = p.ren_win.GetClassName(); p.close()
child = subprocess.run([sys.executable, '-c', 'import os; print(sorted(os.environ) == {{names!r}})'.format(
    names=sorted(before)), ], capture_output=True, text=True, env=None).stdout.strip()
print(status, dict(os.environ) == before, backend.rendering_backend(), window, child)
"""


@pytest.mark.slow
def test_a_figure_leaves_the_process_environment_as_it_was(tmp_path):
    """The offscreen backend is handed to VTK while it makes a window, not written into the process's environment:
    after a picture, the variables (and those a child process inherits) are those the process started with."""
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "VTK_DEFAULT_OPENGL_WINDOW")}
    code = _ENVIRONMENT_AFTER_A_FIGURE.format(points=str(EXAMPLES / "paper-example-1.json"),
                                              png=str(tmp_path / "a.png"))
    done = subprocess.run([sys.executable, "-c", code], env=env, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    status, same, name, window, child = done.stdout.split()
    assert (status, same, child) == ("0", "True", "True")
    windows = {"egl": "vtkEGLRenderWindow", "osmesa": "vtkOSOpenGLRenderWindow", "xvfb": "vtkXOpenGLRenderWindow"}
    assert window == windows[name]  # the chosen window all the same
    assert (tmp_path / "a.png").stat().st_size > 10_000


def test_the_rendering_environment_is_restored_after_an_error(monkeypatch):
    from lagsym.plot import backend

    monkeypatch.setattr(backend, "_chosen", lambda: ("xvfb", (("DISPLAY", ":97"), ("LAGSYM_TEST_WINDOW", "w"))))
    monkeypatch.setenv("DISPLAY", ":5")
    monkeypatch.delenv("LAGSYM_TEST_WINDOW", raising=False)
    with pytest.raises(RuntimeError, match="midway"):
        with backend.rendering_environment() as variables:
            assert variables == {"DISPLAY": ":97", "LAGSYM_TEST_WINDOW": "w"}
            assert os.environ["DISPLAY"] == ":97" and os.environ["LAGSYM_TEST_WINDOW"] == "w"
            raise RuntimeError("midway")
    assert os.environ["DISPLAY"] == ":5" and "LAGSYM_TEST_WINDOW" not in os.environ


@pytest.mark.slow
@pytest.mark.skipif(sys.platform != "linux", reason="Xvfb is the Linux fallback")
def test_the_xvfb_fallback_leaves_the_process_environment_as_it_was(tmp_path):
    """Where neither EGL nor OSMesa works: the private server's DISPLAY is seen by VTK's window alone."""
    if shutil.which("Xvfb") is None:
        missing_system_package("xvfb", "Xvfb")
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "VTK_DEFAULT_OPENGL_WINDOW")}
    code = ("from lagsym.plot import backend; backend._probe = lambda window_class: False\n"
            + _ENVIRONMENT_AFTER_A_FIGURE.format(points=str(EXAMPLES / "paper-example-1.json"),
                                                 png=str(tmp_path / "a.png")))
    done = subprocess.run([sys.executable, "-c", code], env=env, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["0", "True", "xvfb", "vtkXOpenGLRenderWindow", "True"]
    assert (tmp_path / "a.png").stat().st_size > 10_000


@pytest.mark.slow
def test_pictures_without_ipython(tmp_path):
    """A plain install has no IPython: pictures are drawn all the same (pyvista's notebook setting is skipped)."""
    code = (
        "import importlib.abc, sys\n"
        "class NoIPython(importlib.abc.MetaPathFinder):\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] == 'IPython':\n"
        "            raise ModuleNotFoundError(name)\n"
        "sys.meta_path.insert(0, NoIPython())\n"
        "from lagsym.cli import main\n"
        f"sys.exit(main(['plot', {str(EXAMPLES / 'paper-example-1.json')!r}, '-o', {str(tmp_path / 'a.png')!r}]))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "a.png").stat().st_size > 10_000


def test_figures_sample_on_the_exact_lines(surface4):
    """The pictures take their axes from the one builder, so every node is a sample, to the last bit."""
    xs, ys, z = sampled_surface(surface4, 41)
    g = sample_grid(surface4, 41, 41)
    assert xs.tolist() == g.xs.tolist() and ys.tolist() == g.ys.tolist()
    assert xs[::10].tolist() == surface4.grid.x_array.tolist()
    assert z[::10, ::10].tolist() == surface4.grid.z_array.tolist()


# ----------------------------------------------------------------------------- errors name the value


def test_compare_needs_its_reference(surface4):
    x, y, surfaces = comparison(surface4)
    with pytest.raises(InputError, match=r"'Lagrangian' is not among the surfaces: 'Lagrange', 'Bezier'"):
        plot.compare_figure(x, y, surfaces, reference="Lagrangian")


def test_compare_checks_shapes(surface4):
    x, y, surfaces = comparison(surface4)
    surfaces["Bezier"] = surfaces["Bezier"][:, :-1]
    with pytest.raises(InputError, match=r"surface 'Bezier' has shape \(33, 32\), but the axes x and y give \(33, 33\)"):
        plot.compare_figure(x, y, surfaces)


def test_axes_must_increase(surface4):
    x, y, surfaces = comparison(surface4)
    with pytest.raises(InputError, match=r"x must increase strictly, but x\[0\] = 5.0"):
        plot.deviation_figure(x[::-1], y, {"a": surfaces["Bezier"]})


def test_moves_shape_and_rapid_mask(surface4):
    with pytest.raises(InputError, match=r"moves_mm should be an \(N, 3\) array"):
        plot.toolpath_figure(surface4, np.zeros((4, 2)))
    with pytest.raises(InputError, match=r"moves_mm\[1\] = \[1.0, nan, 0.0\] is not finite"):
        plot.toolpath_figure(surface4, [[0, 0, 0], [1, np.nan, 0]])
    with pytest.raises(InputError, match=r"rapid should be a boolean array of shape \(2,\)"):
        plot.toolpath_figure(surface4, np.zeros((2, 3)), rapid=np.array([0, 1]))


def test_bad_options(surface2, tmp_path):
    with pytest.raises(InputError, match="samples = 1 should be an integer of at least 2"):
        plot.surface_figure(surface2, samples=1)
    with pytest.raises(InputError, match="window size 10x10 is out of range"):
        plot.surface_figure(surface2, window_size=(10, 10))
    with pytest.raises(InputError, match=r"'\.svg'; use one of: \.png, \.jpg"):
        plot.image_format(tmp_path / "a.svg")


# ----------------------------------------------------------------------------- the command


def png_size(path: Path) -> tuple[int, int]:
    with Image.open(path) as im:
        assert im.format == "PNG"
        return im.size


@pytest.mark.parametrize("file, show", [
    ("paper-example-4.json", []),
    ("paper-example-1.json", ["--show", "basis"]),
    ("paper-curve-3rd.json", []),
    ("paper-curve-2nd.json", ["--show", "basis"]),
    ("paper-example-4.json", ["--show", "compare"]),
    ("paper-example-4.json", ["--show", "growth", "x**2 * y"]),
    ("paper-example-1.json", ["--z-exaggeration", "2"]),
])
def test_cli_writes_pictures(run_cli, tmp_path, file, show):
    out = tmp_path / "fig.png"
    status, stdout, stderr = run_cli("plot", EXAMPLES / file, *show, "-o", out, "--size", "200x150",
                                     "--samples", "9")
    assert (status, stderr) == (0, "")
    assert png_size(out) == (200, 150)
    assert ink(np.asarray(Image.open(out).convert("RGB"))) > 0.01


@pytest.mark.slow
def test_cli_draws_a_program_over_the_surface(run_cli, tmp_path):
    program = tmp_path / "rough.nc"
    status, _, err = run_cli("toolpath", EXAMPLES / "paper-example-4.json", "--scale", "20", "--tool-diameter", "6",
                             "--stepover", "4", "--step", "2", "--safe-z", "80", "-o", program)
    assert status == 0, err
    out = tmp_path / "tp.png"
    status, _, err = run_cli("plot", EXAMPLES / "paper-example-4.json", "--show", "toolpath", program,
                             "--scale", "20", "-o", out, "--size", "300x200", "--samples", "9")
    assert (status, err) == (0, "")
    img = np.asarray(Image.open(out).convert("RGB")).astype(int)
    assert img.shape == (200, 300, 3) and ink(img) > 0.05
    red = (img[..., 0] > 180) & (img[..., 1] < 120) & (img[..., 2] < 80)
    assert red.mean() > 0.002  # the feed moves are drawn


def test_cli_show_before_file(run_cli, tmp_path):
    out = tmp_path / "b.png"
    status, _, stderr = run_cli("plot", "--show", "basis", EXAMPLES / "paper-example-1.json", "-o", out,
                                "--size", "200x150", "--samples", "5")
    assert (status, stderr) == (0, "")
    assert out.exists()


def test_cli_units_reach_the_axes(run_cli, tmp_path, monkeypatch):
    seen = {}
    real = plot.surface_figure

    def spy(surface, **opts):
        seen.update(opts)
        return real(surface, **opts)

    monkeypatch.setattr(plot, "surface_figure", spy)
    status, _, _ = run_cli("plot", EXAMPLES / "paper-example-1.json", "--units", "in", "-o", tmp_path / "s.png",
                           "--size", "100x80", "--samples", "5")
    assert status == 0 and seen["units"] == "in"


@pytest.mark.parametrize("argv, message", [
    (["--show", "toolpath"], "--show toolpath needs exactly one PROGRAM"),
    (["--show", "growth"], "--show growth needs exactly one FORMULA"),
    (["--scale", "20", "-o", "x.png"], "--scale and --origin place a program on the machine"),
    (["--show", "basis", "--z-exaggeration", "2", "-o", "x.png"], "--z-exaggeration applies to a surface"),
    (["--z-exaggeration", "0", "-o", "x.png"], "argument --z-exaggeration: '0' is out of range"),
    (["--show", "toolpath", "part.ngc", "-o", "x.png"], "part.ngc: no such file"),
    (["--show", "wireframe"], "--show 'wireframe' is not one of: surface, basis, compare, toolpath, growth"),
    (["--show", "basis", "extra"], "--show basis takes no file, but got 'extra'"),
    (["-o", "out.svg"], "cannot tell the image format from '.svg'"),
    (["--size", "10x10", "-o", "x.png"], "window size 10x10 is out of range"),
])
def test_cli_refuses(run_cli, argv, message):
    status, stdout, stderr = run_cli("plot", EXAMPLES / "paper-example-1.json", *argv)
    assert status == 2 and stdout == ""
    assert message in stderr and stderr.count("\n") == 1


def test_cli_without_output_needs_a_display(run_cli, monkeypatch):
    monkeypatch.setattr(plot, "rendering_backend", lambda: "egl")
    status, _, stderr = run_cli("plot", EXAMPLES / "paper-example-1.json")
    assert status == 2 and "no display to open a window on: give -o FILE" in stderr


def test_cli_bad_size_is_a_usage_error(run_cli):
    status, _, stderr = run_cli("plot", EXAMPLES / "paper-example-1.json", "--size", "big")
    assert status == 2 and "'big' should be WIDTHxHEIGHT" in stderr


def test_cli_missing_file(run_cli, tmp_path):
    status, _, stderr = run_cli("plot", tmp_path / "none.json", "-o", tmp_path / "x.png")
    assert status == 2 and "no such file" in stderr
    assert not (tmp_path / "x.png").exists()


# ----------------------------------------------------------------------------- the machined part


def _slot_part():
    from lagsym.gcode import parse_moves, tool_changes
    from lagsym.grid import grid_from_table
    from lagsym.machine import Tool
    from lagsym.machined import machine_part

    flat = lagrange_surface(grid_from_table([0, 10], [0, 10], [[0, 0], [2, 2]]))
    text = ("T1 M06\nG00 X-5. Y5. Z10.\nG00 Z2.\nG01 X15. F500.\nG00 Z10.\n"
            "T2 M06\nG00 X-5. Y3.\nG00 Z1.\nG01 X15. F500.\nG00 Z10.\nM30\n")
    return machine_part(flat, parse_moves(text), tool_changes(text), {1: Tool("flat", 4.0), 2: Tool("ball", 2.0)},
                        (-2.0, 12.0, 0.0, 10.0, 5.0), cell_mm=0.1)


@pytest.mark.slow
def test_machined_figure_draws_each_stage_coloured_by_material_left():
    part = _slot_part()
    img = render(plot.machined_figure(part, window_size=WIDE, off_screen=True))
    check_picture(img, WIDE, 0.1)
    check_reference(img, "machined_slots")
    # One colour scale: the stage after the ball shows less bright (much material left) than the one before.
    one = render(plot.machined_figure(part, stages=[0], window_size=SIZE, off_screen=True, left_max_mm=5.0))
    two = render(plot.machined_figure(part, stages=[1], window_size=SIZE, off_screen=True, left_max_mm=5.0))
    assert not np.array_equal(one, two)
    with pytest.raises(InputError, match="stages"):
        plot.machined_figure(part, stages=[2])


def test_cli_draws_a_job_machined(run_cli, tmp_path):
    pts = tmp_path / "ramp.json"
    pts.write_text('{"units": "mm", "points": [[0, 0, 0], [0, 10, 0], [10, 0, 2], [10, 10, 2]]}')
    job = tmp_path / "job.toml"
    job.write_text('points = "ramp.json"\nsafe_z = 20\n[stock]\ntop = 5\n[tools.a]\nnumber = 1\nshape = "flat"\n'
                   'diameter = 4\n[tools.b]\nnumber = 2\nshape = "ball"\ndiameter = 2\n'
                   '[[operations]]\nkind = "finish"\ntool = "b"\nstepover = 1\n')
    prog = tmp_path / "slot.nc"
    prog.write_text("T1 M06\nG00 X-5. Y5. Z10.\nG00 Z2.\nG01 X15. F500.\nG00 Z10.\nM30\n")
    target = tmp_path / "m.png"
    status, _, err = run_cli("plot", job, "--show", "machined", prog, "--cell", "0.2", "--size", "480x300", "-o", target)
    assert status == 0, err
    with Image.open(target) as im:
        assert im.size == (480, 300)
    status, _, err = run_cli("plot", job, "--show", "machined", prog, "--scale", "2", "-o", target)
    assert status == 2 and "--scale is not for --show machined" in err
    status, _, err = run_cli("plot", EXAMPLES / "paper-example-1.json", "--cell", "0.2", "-o", target)
    assert status == 2 and "--cell is the height-map cell of --show machined" in err
