"""The residuals figure, rendered offscreen for real: a fitted surface and its points on coloured stems."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from conftest import EXAMPLES, need_opengl
from lagsym import plot
from lagsym.cli import main
from lagsym.fit import fit_surface
from lagsym.io import read_scattered_points
from lagsym.plot.residuals import residual_exaggeration

SIZE = (480, 360)


@pytest.fixture(autouse=True, scope="module")
def _offscreen_opengl():
    need_opengl("the pictures")


@pytest.fixture(scope="module")
def probe_fit():
    data = read_scattered_points(EXAMPLES / "probe-12x12.csv")
    return fit_surface(data.points, (4, 4), units="mm")


def _shares(img: np.ndarray) -> tuple[float, float, float]:
    """Shares of the pixels left of the colour bar that are drawn, strongly red and strongly blue."""
    px = img[:, : int(0.8 * img.shape[1])].reshape(-1, 3).astype(int)
    drawn = (np.abs(px - 255).max(axis=1) > 30).mean()
    red = ((px[:, 0] > 150) & (px[:, 0] - px[:, 2] > 80)).mean()
    blue = ((px[:, 2] > 150) & (px[:, 2] - px[:, 0] > 80)).mean()
    return float(drawn), float(red), float(blue)


def test_residuals_figure_draws_both_signs(probe_fit):
    # the residuals' signs, from a float least-squares fit of the same degree written here
    pts = np.array([[float(v) for v in p] for p in probe_fit.points])
    x, y, z = pts.T
    u, v = (x - x.mean()) / x.std(), (y - y.mean()) / y.std()
    a = np.column_stack([u**i * v**j for i in range(5) for j in range(5)])
    r = z - a @ np.linalg.lstsq(a, z, rcond=None)[0]
    assert np.allclose(r, [float(q) for q in probe_fit.residuals], atol=1e-9)
    assert (r > 0).any() and (r < 0).any()
    p = plot.residuals_figure(probe_fit, samples=31, window_size=SIZE, off_screen=True)
    img = np.asarray(p.screenshot(return_img=True))
    p.close()
    assert img.shape == (SIZE[1], SIZE[0], 3)
    drawn, red, blue = _shares(img)
    assert drawn > 0.15 and red > 0.001 and blue > 0.001, (drawn, red, blue)
    # without residuals (every point on the surface) neither colour's strong end appears
    exact = fit_surface([(p[0], p[1], p[0] + p[1]) for p in probe_fit.points], (1, 1))
    q = plot.residuals_figure(exact, samples=31, window_size=SIZE, off_screen=True)
    img = np.asarray(q.screenshot(return_img=True))
    q.close()
    _, red, blue = _shares(img)
    assert red < 0.001 and blue < 0.001, (red, blue)


def test_exaggeration():
    assert residual_exaggeration([0.02, -0.01], 10.0) == 0.25 * 10.0 / 0.02
    assert residual_exaggeration([0, 0], 10.0) == 1.0


def test_command_writes_the_picture(tmp_path):
    out, err = io.StringIO(), io.StringIO()
    dst = tmp_path / "r.png"
    assert main(["plot", "--show", "residuals", str(EXAMPLES / "probe-12x12.csv"), "--size", "400x300", "-o",
                 str(dst)], out, err) == 0, err.getvalue()
    assert Image.open(dst).size == (400, 300)
    out, err = io.StringIO(), io.StringIO()
    assert main(["plot", "--show", "residuals", str(EXAMPLES / "probe-12x12.csv"), "--scale", "2", "-o",
                 str(tmp_path / "s.png")], out, err) == 2
    assert "--scale" in err.getvalue() and not (tmp_path / "s.png").exists()


def test_probe_results_are_drawn_at_the_probed_nodes(tmp_path):
    """A probing program's results, as the control printed them, drawn at the nodes the program probed."""
    import re

    import pyvista as pv

    from lagsym.probe import read_results, surface_points

    text = (EXAMPLES / "probe-results.txt").read_text()
    nodes = sorted((float(m[1]), float(m[2])) for m in re.finditer(r"^P \d+ X (\S+) Y (\S+) Z \S+ OK$", text, re.M))
    assert len(nodes) == 49
    out, err = io.StringIO(), io.StringIO()
    dst = tmp_path / "probed.png"
    assert main(["plot", "--show", "residuals", str(EXAMPLES / "probe-results.txt"), "--size", "400x300", "-o",
                 str(dst)], out, err) == 0, err.getvalue()
    assert Image.open(dst).size == (400, 300)
    fitted = fit_surface(surface_points(read_results(text, "probe-results.txt")).points, None)
    p = plot.residuals_figure(fitted, samples=21, window_size=SIZE, off_screen=True)
    drawn = [a.mapper.dataset.points for a in p.actors.values()
             if isinstance(a, pv.Actor) and a.mapper.dataset.n_points == len(nodes)]
    p.close()
    assert len(drawn) == 1 and sorted(map(tuple, np.round(drawn[0][:, :2], 4))) == nodes
