"""Checking a program by simulating the cut on a height map of the stock.

The box of the control points, in machine millimetres, is covered by a grid
of cells; each cell keeps the lowest height any part of the tool reached over
its centre.  Every move of the program (feed and rapid alike: a rapid into the
part is a crash) is sampled densely enough that consecutive tool positions are
at most half a cell apart sideways and ``dz_mm`` apart in height, and at each
position the exact lower surface of the tool (a sphere for a ball end, a disc
for a flat end) is pressed into every cell centre under it.  The result is
compared with the exact surface at the same cell centres:

* **gouge**: how far the cut went below the surface (0 for a good program);
* **scallop**: how much material stands above the surface where the tool
  passed;
* **not reached**: cells no part of the tool passed over.

The simulation errs towards missing a little cut, never towards inventing one:
between two sampled positions the tool sweeps at most ``resolution_mm`` lower
than the samples show (the sag of the ball over half the sample spacing, plus
half a height step).  A gouge counts when it is deeper than ``gouge_limit_mm``,
by default the program's own rounding (half a unit of its last decimal) plus
that resolution.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._arrays import freeze_fields
from .errors import InputError, ToolpathError
from .evaluate import evaluate_grid
from .gcode import Moves
from .machine import Placement, Tool, cutter_profile

__all__ = ["CutReport", "simulate_cut", "press_moves", "height_map_axes", "MAX_CELLS", "MAX_CONTACTS"]

_MOVES_PER_PASS = 20_000
MAX_CELLS = 16_000_000  # height-map cells by default: 4000 x 4000, about 0.5 GB with the arrays compared
MAX_CONTACTS = 20_000_000_000  # tool positions (all, before those far from the box are dropped) times cells under the tool


@dataclass(frozen=True)
class CutReport:
    """What a simulated cut left, against the exact surface (all lengths in mm).

    Attributes
    ----------
    xs_mm, ys_mm : ndarray
        Cell centres; ``cut_mm[i, j]`` and ``surface_mm[i, j]`` are at
        ``(xs_mm[i], ys_mm[j])``.  Read-only.
    cut_mm : ndarray
        Lowest tool height over each cell (``inf`` where the tool never passed).
    surface_mm : ndarray
        The exact surface in machine coordinates.
    gouge_mm, gouge_at : float, tuple
        Deepest cut below the surface (0 if none) and where.
    scallop_mm, scallop_at : float, tuple
        Highest material left above the surface where the tool passed, and where.
    unreached_mm2 : float
        Area of the cells the tool never passed over.
    resolution_mm, gouge_limit_mm : float
        The simulation's vertical resolution and the depth from which a cut counts as a gouge.
    positions : int
        Number of tool positions simulated.
    """

    xs_mm: np.ndarray
    ys_mm: np.ndarray
    cut_mm: np.ndarray
    surface_mm: np.ndarray
    gouge_mm: float
    gouge_at: tuple[float, float]
    scallop_mm: float
    scallop_at: tuple[float, float]
    unreached_mm2: float
    resolution_mm: float
    gouge_limit_mm: float
    positions: int

    def __post_init__(self):
        freeze_fields(self, ("xs_mm", "ys_mm", "cut_mm", "surface_mm"), dtype=float)

    @property
    def gouges(self) -> bool:
        """True when the program cuts below the surface by more than the limit."""
        return self.gouge_mm > self.gouge_limit_mm

    @property
    def cell_mm(self) -> tuple[float, float]:
        """Cell size in X and Y."""
        return (float(self.xs_mm[1] - self.xs_mm[0]) if len(self.xs_mm) > 1 else 0.0,
                float(self.ys_mm[1] - self.ys_mm[0]) if len(self.ys_mm) > 1 else 0.0)

    @property
    def unreached_fraction(self) -> float:
        """Share of the box the tool never passed over."""
        return float(np.mean(~np.isfinite(self.cut_mm)))

    def summary(self) -> list[str]:
        """The report as lines of text."""
        cx, cy = self.cell_mm
        return [
            f"simulated {len(self.xs_mm)} x {len(self.ys_mm)} cells of {cx:.3f} x {cy:.3f} mm, "
            f"{self.positions} tool positions, resolution {self.resolution_mm:.4f} mm",
            f"worst gouge       {self.gouge_mm:.4f} mm at X{self.gouge_at[0]:.3f} Y{self.gouge_at[1]:.3f} "
            f"(limit {self.gouge_limit_mm:.4f} mm): {'GOUGE' if self.gouges else 'none'}",
            f"largest scallop   {self.scallop_mm:.4f} mm at X{self.scallop_at[0]:.3f} Y{self.scallop_at[1]:.3f}",
            f"area not reached  {self.unreached_mm2:.2f} mm2 ({100 * self.unreached_fraction:.2f} % of the box)",
        ]


def _samples(a: np.ndarray, b: np.ndarray, ds: float, dz: float) -> np.ndarray:
    """Points along the segments ``a[k] -> b[k]`` no further apart than ``ds`` sideways and ``dz`` in height."""
    d = b - a
    n = np.maximum(np.ceil(np.maximum(np.hypot(d[:, 0], d[:, 1]) / ds, np.abs(d[:, 2]) / dz)), 1).astype(np.int64)
    seg = np.repeat(np.arange(len(a)), n)
    first = np.concatenate([[0], np.cumsum(n)[:-1]])
    t = (np.arange(int(n.sum())) - np.repeat(first, n)) / np.repeat(n, n)
    pts = a[seg] + t[:, None] * d[seg]
    return np.vstack([pts, b[-1:]])


def simulate_cut(surface, moves: Moves, tool: Tool, placement: Placement = Placement(),
                 cell_mm: float | None = None, dz_mm: float = 0.01, program_resolution_mm: float = 0.0005,
                 gouge_limit_mm: float | None = None, max_cells: int | None = MAX_CELLS,
                 max_contacts: int | None = MAX_CONTACTS) -> CutReport:
    """Simulate the moves with the tool on a height map over the surface's box and compare with the surface.

    Parameters
    ----------
    surface : LagrangeSurface
        The exact surface.
    placement : Placement
        Where it sits on the machine (``MachineSettings.placement``).
    moves : Moves
        The program's moves (:func:`lagsym.gcode.parse_moves`).
    tool : Tool
        The cutter; a diameter of 0 is simulated as a flat end one cell wide.
    cell_mm : float, optional
        Cell size; by default the box's longer side over 400.
    dz_mm : float
        Largest height step between simulated positions along a move.
    program_resolution_mm : float
        How far the program's rounding may put a point from the planned one.
    gouge_limit_mm : float, optional
        Depth from which a cut counts as a gouge; by default the program
        resolution plus the simulation's.
    max_cells, max_contacts : int or None
        Refuse, before any work, more cells (``--max-cells``) or tool
        positions times cells under the tool (``--max-contacts``); None: no limit.
    """
    xs, ys = height_map_axes(placement.box_mm(surface.grid.bounds), cell_mm, max_cells)
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    sx, sy = placement.to_surface(xs, ys)
    surf = placement.height_mm(evaluate_grid(surface, sx, sy))
    cut = np.full((len(xs), len(ys)), np.inf)
    # Moves before the program's first Z run at the machine's height, which the program does not say: skip them.
    known = np.asarray(moves.z_known, dtype=bool)
    path = moves.path_mm
    use = known & np.concatenate([[False], known[:-1]]) if len(moves) else known
    a_all, b_all = path[:-1][use], path[1:][use]
    if not len(a_all):
        raise InputError("the program has no move with a known Z to simulate (no G00/G01 after the first Z)")
    positions, resolution = press_moves(cut, xs, ys, a_all, b_all, tool, dz_mm, max_contacts)
    limit = program_resolution_mm + resolution if gouge_limit_mm is None else float(gouge_limit_mm)
    reached = np.isfinite(cut)
    diff = np.where(reached, cut - surf, np.nan)
    if reached.any():
        gi = int(np.nanargmin(diff))
        si = int(np.nanargmax(diff))
        gouge = max(0.0, -float(diff.flat[gi]))
        scallop = max(0.0, float(diff.flat[si]))
    else:
        gi = si = 0
        gouge = scallop = 0.0

    def at(k):
        i, j = np.unravel_index(k, cut.shape)
        return float(xs[i]), float(ys[j])

    return CutReport(xs_mm=xs, ys_mm=ys, cut_mm=cut, surface_mm=surf, gouge_mm=gouge, gouge_at=at(gi),
                     scallop_mm=scallop, scallop_at=at(si), unreached_mm2=float((~reached).sum() * hx * hy),
                     resolution_mm=resolution, gouge_limit_mm=limit, positions=positions)


def _sweep(cut, a_all, b_all, xs, ys, r, corner, ds, dz_mm) -> int:
    """Press the tool into ``cut`` along every move; the number of tool positions simulated.

    A few thousand moves at a time, so a long program never needs all its samples in memory at once.
    """
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    x0, x1, y0, y1 = xs[0], xs[-1], ys[0], ys[-1]
    positions = 0
    for s in range(0, len(a_all), _MOVES_PER_PASS):
        pts = _samples(a_all[s:s + _MOVES_PER_PASS], b_all[s:s + _MOVES_PER_PASS], ds, dz_mm)
        near = (pts[:, 0] >= x0 - r - hx) & (pts[:, 0] <= x1 + r + hx) & (pts[:, 1] >= y0 - r - hy) & (
            pts[:, 1] <= y1 + r + hy)
        pts = pts[near]
        positions += len(pts)
        if len(pts):
            _press(cut, pts, xs, ys, r, corner)
    return positions


def height_map_axes(box_mm, cell_mm: float | None, max_cells: int | None) -> tuple[np.ndarray, np.ndarray]:
    """Cell centres in x and y of a height map over ``box_mm`` ``(x0, x1, y0, y1)``, refused beyond ``max_cells``.

    ``cell_mm`` defaults to the longer side / 400.
    """
    x0, x1, y0, y1 = box_mm
    if cell_mm is None:
        cell_mm = max(x1 - x0, y1 - y0) / 400.0
    if not cell_mm > 0:
        raise ToolpathError(f"cell size {cell_mm!r} must be a positive number of mm")
    nx = max(int(math.ceil((x1 - x0) / cell_mm)) + 1, 2)
    ny = max(int(math.ceil((y1 - y0) / cell_mm)) + 1, 2)
    if max_cells is not None and nx * ny > max_cells:
        raise InputError(f"a height map of {nx} x {ny} cells of {cell_mm:g} mm is {nx * ny:.3g} cells, more than the "
                         f"limit of {max_cells:.3g}; use a larger cell (--cell) or raise the limit (--max-cells)")
    return np.linspace(x0, x1, nx), np.linspace(y0, y1, ny)


def _check_work(a, b, ds: float, dz: float, r: float, hx: float, hy: float, max_contacts: int | None) -> None:
    """Refuse a simulation whose tool positions times cells under the tool would exceed ``max_contacts``."""
    if max_contacts is None:
        return
    d = b - a
    positions = float(np.maximum(np.ceil(np.maximum(np.hypot(d[:, 0], d[:, 1]) / ds, np.abs(d[:, 2]) / dz)), 1).sum())
    footprint = (2 * math.ceil(r / hx) + 3) * (2 * math.ceil(r / hy) + 3)
    if positions * footprint > max_contacts:
        raise InputError(
            f"simulating {positions:.3g} tool positions over {footprint:.3g} cells under the tool each is "
            f"{positions * footprint:.3g} contacts, more than the limit of {max_contacts:.3g}; check the program's "
            f"moves and the tool diameter, use a larger cell (--cell), or raise the limit (--max-contacts)")


def _press(cut, pts, xs, ys, r, corner):
    """Lower ``cut`` to the tool's lower surface at every sampled position (in place)."""
    nx, ny = cut.shape
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    ix = np.rint((pts[:, 0] - xs[0]) / hx).astype(np.int64)
    iy = np.rint((pts[:, 1] - ys[0]) / hy).astype(np.int64)
    # Group the positions by their nearest cell once: the same grouping serves every offset of the tool's footprint.
    key = ix * (ny + 4 * int(r / hy) + 8) + iy
    order = np.argsort(key, kind="stable")
    key, px, py, pz, ix, iy = key[order], pts[order, 0], pts[order, 1], pts[order, 2], ix[order], iy[order]
    starts = np.flatnonzero(np.concatenate([[True], key[1:] != key[:-1]]))
    gx, gy = ix[starts], iy[starts]
    kx, ky = int(math.ceil(r / hx)) + 1, int(math.ceil(r / hy)) + 1
    r2 = r * r
    for di in range(-kx, kx + 1):
        tx = gx + di
        okx = (tx >= 0) & (tx < nx)
        if not okx.any():
            continue
        cxs = xs[np.clip(ix + di, 0, nx - 1)]
        dx2 = (cxs - px) ** 2
        for dj in range(-ky, ky + 1):
            ty = gy + dj
            ok = okx & (ty >= 0) & (ty < ny)
            if not ok.any():
                continue
            cys = ys[np.clip(iy + dj, 0, ny - 1)]
            d2 = dx2 + (cys - py) ** 2
            inside = d2 <= r2
            h = np.where(inside, pz + cutter_profile(np.where(inside, d2, 0.0), r, corner), np.inf)
            m = np.minimum.reduceat(h, starts)
            sel = ok & np.isfinite(m)
            if sel.any():
                a, b = tx[sel], ty[sel]
                cut[a, b] = np.minimum(cut[a, b], m[sel])


def press_moves(cut: np.ndarray, xs: np.ndarray, ys: np.ndarray, a: np.ndarray, b: np.ndarray, tool: Tool,
                dz_mm: float = 0.01, max_contacts: int | None = MAX_CONTACTS) -> tuple[int, float]:
    """Lower the height map ``cut`` (in place) to the tool's lower surface along the moves ``a[k] -> b[k]`` (mm).

    ``cut[i, j]`` is the height over ``(xs[i], ys[j])``, evenly spaced cell
    centres.  Returns the number of tool positions simulated and the
    simulation's vertical resolution (as :func:`simulate_cut` states it).
    """
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    r = tool.radius_mm if tool.radius_mm > 0 else 0.5 * min(hx, hy)
    corner = tool.corner_mm if tool.radius_mm > 0 else 0.0
    ds = 0.5 * min(hx, hy)
    # Between two samples the tool's lower surface can rise by its corner's sag over half a sample step.
    resolution = (corner - math.sqrt(max(corner * corner - (ds / 2) ** 2, 0.0)) if corner > 0 else 0.0) + dz_mm / 2
    if not len(a):
        return 0, resolution
    _check_work(a, b, ds, dz_mm, r, hx, hy, max_contacts)
    return _sweep(cut, a, b, xs, ys, r, corner, ds, dz_mm), resolution
