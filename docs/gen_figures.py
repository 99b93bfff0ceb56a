"""Render the pictures of the docs with lagsym itself: ``python3 docs/gen_figures.py [NAME.png ...]``."""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))

FIGURES = {
    "fig3-curve.png": ["plot", "examples/paper-curve-3rd.json"],
    "fig4-basis.png": ["plot", "examples/paper-example-2.json", "--show", "basis"],
    "fig9-surface.png": ["plot", "examples/paper-example-4.json"],
    "fig10-compare.png": ["plot", "examples/paper-example-4.json", "--show", "compare"],
    "fig11-growth.png": ["plot", "examples/parabola.json", "--show", "growth", "1/(1 + ((x-20)**2 + (y-20)**2)/25)"],
    "measured-residuals.png": ["plot", "--show", "residuals", "examples/probe-12x12.csv"],
    "probe-residuals.png": ["plot", "--show", "residuals", "examples/probe-results.txt"],
}


def export_figure(path: Path) -> None:
    """docs/export.md: Example 2 with the control net of its exact Bezier patch, and the points it interpolates."""
    import numpy as np
    import pyvista as pv

    from lagsym import bezier_patch, lagrange_surface, read_points
    from lagsym.plot import save_figure, surface_figure

    surface = lagrange_surface(read_points(HERE.parent / "examples" / "paper-example-2.json"))
    net = np.array([[[float(c) for c in p] for p in row] for row in bezier_patch(surface).control_points])
    p = surface_figure(surface, control_net=False, window_size=(800, 600),
                       title="Example 2 and the control net of its exact Bezier patch (black), the data points (white)")
    grid = pv.StructuredGrid(net[..., 0], net[..., 1], net[..., 2])
    p.add_mesh(grid.extract_all_edges(), color="black", line_width=2, lighting=False)
    p.add_mesh(pv.PolyData(net.reshape(-1, 3)), color="black", point_size=11, render_points_as_spheres=True)
    data = np.array([[float(c) for c in pt] for pt in surface.grid.points()])
    p.add_mesh(pv.PolyData(data), color="white", point_size=11, render_points_as_spheres=True)
    p.reset_camera()  # the net reaches above the surface
    p.camera.zoom(0.95)
    save_figure(p, path)


def steep_shallow_figure(path: Path) -> int:
    """docs/toolpaths.md: steep-and-shallow on Example 4, a coarse cusp so that the passes show apart."""
    from lagsym.cli import main as lagsym

    with tempfile.TemporaryDirectory() as d:
        program = str(Path(d) / "steep.nc")
        if lagsym(["toolpath", "examples/paper-example-4.json", "--scale", "20", "--tool-diameter", "6",
                   "--strategy", "steep-shallow", "--scallop", "0.3", "--tolerance", "0.02", "--safe-z", "80",
                   "-o", program]) != 0:
            return 1
        return lagsym(["plot", "examples/paper-example-4.json", "--show", "toolpath", program, "--scale", "20",
                       "-o", str(path)])


def main(names: list[str] | None = None) -> int:
    from lagsym.cli import main as lagsym

    size = []  # the default size: sharp on the page, text legible
    if names:  # only these
        for name in names:
            if name == "export-net.png":
                export_figure(HERE / "images" / name)
            elif name == "steep-shallow.png" and steep_shallow_figure(HERE / "images" / name):
                return 1
            elif name in FIGURES and lagsym([*FIGURES[name], *size, "-o", str(HERE / "images" / name)]):
                return 1
        return 0
    export_figure(HERE / "images" / "export-net.png")
    if steep_shallow_figure(HERE / "images" / "steep-shallow.png"):
        return 1
    for name, argv in FIGURES.items():
        if lagsym([*argv, *size, "-o", str(HERE / "images" / name)]) != 0:
            return 1
    with tempfile.TemporaryDirectory() as d:
        program = str(Path(d) / "rough.nc")
        if lagsym(["toolpath", "examples/paper-example-4.json", "--scale", "20", "--tool-diameter", "6",
                   "--stepover", "2", "--step", "1", "--safe-z", "80", "-o", program]) != 0:
            return 1
        if lagsym(["plot", "examples/paper-example-4.json", "--show", "toolpath", program, "--scale", "20",
                   *size, "-o", str(HERE / "images" / "fig12-toolpath.png")]) != 0:
            return 1
        job = str(Path(d) / "job.ngc")
        if lagsym(["job", "examples/example-4-job.toml", "-o", job]) != 0:
            return 1
        if lagsym(["plot", "examples/example-4-job.toml", "--show", "machined", job, "--cell", "0.25",
                   *size, "-o", str(HERE / "images" / "job-machined.png")]) != 0:
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
