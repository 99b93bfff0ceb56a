"""Cutter locations: the tool dropped onto the exact surface until it touches it anywhere under it.

For a ball of radius ``R`` centred over ``c = (cx, cy)`` the tip height is

    CL(c) = max over p in D(c, R) ∩ B of  F(p) + sqrt(R**2 - |p - c|**2) - R,

for a flat end ``max F(p)`` over the same set, and for a bull-nose end mill of
corner radius ``r`` the same maximum of ``F(p) - P(|p - c|)``, ``P`` its profile
(0 across the flat, ``r - sqrt(r**2 - (d - R + r)**2)`` on the corner; the ball
and the flat end are its limits ``r = R`` and ``r = 0``,
:func:`lagsym.cutter.cutter_profile`); ``D`` is the disc under the
tool and ``B`` the box spanned by the control points.  Only the surface inside
the box counts: the polynomial is never evaluated outside it (beyond the box
lies no part, not a cliff and not an extrapolated surface), so near an edge the
tool rests on what lies inside.  The maximum is found by a dense lattice of
candidate contact points in the disc, then a pattern search from the best few
candidates that shrinks to ``1e-9`` of the tool radius (where the maximum lies on
the rim or on a box edge the height converges only as fast as the step).  Every value found is
the height of a real contact, so it can only err low; :data:`CL_MARGIN` (a
relative ``1e-7``, far below any program's resolution) is added to absorb
that error.  No normal offset is
involved, so concave regions tighter than the tool are handled: the tool rests
on the two walls instead of cutting into them.

The search runs in drop-cutter's compiled kernel (:mod:`.kernel`), a tool
position at a time, with the float64 arithmetic of
:meth:`lagsym.evaluate.SurfaceEvaluator.fast_points`; this module checks the
input, lays out the lattice and shares the positions out in chunks.
"""

from __future__ import annotations

import contextlib

import numpy as np
from numpy.polynomial import chebyshev as C

from ..cutter import corner_radius
from ..evaluate import SurfaceEvaluator, surface_evaluator
from ..progress import COMPILING, Progress
from ..surfaces.piecewise import PiecewiseEvaluator, PiecewiseSurface
from ..values import positive
from .droplattice import (CL_MARGIN, _HEIGHT_SCALES, _inside_box, _kernel_surface, _lattice)
from .workers import Workers

__all__ = ["CL_MARGIN", "drop_cutter", "evaluator_of", "telling_compiles"]


_CHUNK = 1 << 12  # positions per call of the kernel, and per worker's task


def drop_cutter(surface, x, y, radius: float, shape: str | None = None, *, corner: float | None = None,
                lattice: int = 8, starts: int = 3, margin: bool = True, evaluator: SurfaceEvaluator | None = None,
                workers: Workers | None = None, feature: float | None = None) -> np.ndarray:
    """Tool-tip heights of a cutter dropped onto the exact surface at ``(x, y)``.

    Parameters
    ----------
    surface : LagrangeSurface
        The exact surface; only its part inside the control points' box counts.
    x, y : array_like
        Tool axis positions in surface units, no further than ``radius``
        from the box.
    radius : float
        Tool radius in surface units (0: a point, the surface itself).
    shape : {"ball", "flat", "bull"}, optional
        Cutter shape (:data:`lagsym.cutter.SHAPES`); without one, ``corner``
        says the shape (:func:`lagsym.cutter.corner_radius`), and without
        either the cutter is a ball.
    corner : float, optional
        Corner radius in surface units: of a bull-nose cutter
        (``shape="bull"``), more than 0 and less than ``radius``; without a
        shape, 0 (a flat end) to ``radius`` (a ball).  A cutter's own is
        :meth:`lagsym.cutter.Cutter.grown_mm` scaled to surface units.
    lattice : int
        Candidate contact points per tool radius in the first, dense search.
    starts : int
        How many of the best candidates the local search refines.
    margin : bool
        Add :data:`CL_MARGIN`; without it the value is the best contact found,
        a lower bound of the exact one.
    evaluator : SurfaceEvaluator, optional
        The surface's evaluator (by default :func:`lagsym.evaluate.surface_evaluator`).
    workers : Workers, optional
        Worker processes for this evaluator (:mod:`.workers`) that share the
        positions out in chunks; the values are the same as without.
    feature : float, optional
        The smallest feature the lattice resolves (spacing at most half of it): by default the box over
        twice the degree; on a piecewise surface, half its narrowest cell.

    Returns
    -------
    numpy.ndarray
        Tip heights, shape of ``x`` broadcast with ``y``; never below the exact
        drop-cutter value, above it by at most :data:`CL_MARGIN` relative.

    Examples
    --------
    >>> from lagsym.grid import grid_from_points
    >>> from lagsym.lagrange import lagrange_surface
    >>> s = lagrange_surface(grid_from_points([(0, 0, 0), (0, 2, 0), (2, 0, 0), (2, 2, 0)]))
    >>> round(float(drop_cutter(s, 1.0, 1.0, 0.5)), 6)
    0.0
    """
    radius = positive(radius, "tool radius", allow_zero=True)
    corner = corner_radius(shape, radius, corner)
    ev = evaluator or evaluator_of(surface)
    if isinstance(ev, PiecewiseEvaluator):
        from .droppieces import drop_piecewise  # here: it builds on this module's search

        return drop_piecewise(ev, x, y, radius, corner, lattice=lattice, starts=starts, margin=margin,
                              workers=workers)
    return _drop_polynomial(ev, x, y, radius, corner, lattice=lattice, starts=starts, margin=margin, workers=workers,
                            feature=feature)


def _drop_polynomial(ev: SurfaceEvaluator, x, y, radius: float, corner: float, *, lattice: int, starts: int,
                     margin: bool, workers: Workers | None = None, feature: float | None = None) -> np.ndarray:
    """:func:`drop_cutter` on one polynomial's evaluator."""
    x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    shape_out = x.shape
    box = ev.bounds
    cx, cy = _inside_box(x.ravel(), y.ravel(), box, radius)
    if radius == 0:
        return ev.fast_points(cx, cy).reshape(shape_out)
    x0, x1, y0, y1 = box
    if feature is None:
        deg = max(*ev.shape, 2)
        feature = min(x1 - x0, y1 - y0) / (2 * deg)
    spacing = max(min(radius / lattice, feature / 2), radius / 40)  # bounded work for a tool far larger than the box
    lattice_ = _lattice(radius, spacing)
    span = _height_scale(ev) + radius + 1.0
    parallel = workers is not None and workers.parallel and workers.evaluator is ev
    # Each position's value is independent of the chunk it is computed in.
    chunk = max(256, min(_CHUNK, -(-cx.size // (4 * workers.processes)))) if parallel else _CHUNK
    tasks = [(cx[s:s + chunk], cy[s:s + chunk], radius, corner, lattice_, spacing, starts, 0.01 * CL_MARGIN * span)
             for s in range(0, cx.size, chunk)]
    parts = workers.map(_drop_chunk, tasks) if parallel else [_drop_chunk(ev, *t) for t in tasks]
    out = np.concatenate(parts) if parts else np.empty(0)
    return (out + (CL_MARGIN * span if margin else 0.0)).reshape(shape_out)


def evaluator_of(surface):
    """The numeric evaluator drop-cutter and the planner use: a piecewise surface's own, else the polynomial's."""
    if isinstance(surface, PiecewiseSurface):
        return surface.evaluator
    return surface_evaluator(surface)


def _height_scale(ev: SurfaceEvaluator) -> float:
    """Spread of the surface's coefficients in the power basis of the normalized coordinates.

    The scale :data:`CL_MARGIN` and the search's settling threshold are
    relative to; the Chebyshev coefficients are converted back (in floats) only
    to measure it, once per evaluator.
    """
    found = _HEIGHT_SCALES.get(ev)
    if found is None:
        found = _HEIGHT_SCALES[ev] = _power_spread(ev.coefficients)
    return found


def _power_spread(coefficients: np.ndarray) -> float:
    n, m = coefficients.shape
    to_power_x = np.array([np.pad(C.cheb2poly(np.eye(n)[k]), (0, n))[:n] for k in range(n)]).T
    to_power_y = np.array([np.pad(C.cheb2poly(np.eye(m)[k]), (0, m))[:m] for k in range(m)]).T
    return float(np.ptp(to_power_x @ coefficients @ to_power_y.T))


@contextlib.contextmanager
def telling_compiles(progress: Progress | None):
    """A block in which a compilation of the kernel that keeps the caller waiting over two seconds is reported to
    ``progress`` as the stage :data:`~lagsym.progress.COMPILING` (a first run after an install); numba is loaded.
    Where the background process started after the install is compiling it, the block waits for it first.

    Keep the block to one small drop: the report comes from a timer thread,
    and no other report may be made meanwhile.
    """
    from .compiling import told_if_compiling
    from .kernelahead import compile_ahead
    from .kernelcache import cache_folder, hold_planning_lock, kernel_cached, wait_for_background

    told = []

    def tell() -> None:
        if not told and progress is not None:
            progress(0, None, COMPILING)
        told.append(True)

    hold_planning_lock()  # the background compile leaves the evaluation kernels until this process ends
    wait_for_background(tell)  # a plan just after an install: the kernel is being compiled in the background
    with told_if_compiling(tell):
        if cache_folder() is not None and not kernel_cached():  # compiled here: its heaviest callees on two cores
            compile_ahead()
        yield
    if told and progress is not None:
        progress(1, 1, COMPILING)


def _drop_chunk(ev, cx, cy, radius, corner, lattice, spacing, starts, settle):
    """Drop-cutter over one chunk of positions (no margin), in the compiled kernel; numba is imported here, on
    first use, so that importing lagsym loads no compiler."""
    from .kernel import drop_chunk

    c, jet, geo = _kernel_surface(ev, radius, corner, spacing, settle)
    # Writable arrays everywhere, as a worker process receives them: Numba compiles one version per kind of array,
    # and a read-only lattice here would leave the workers to compile their own.
    lattice = [np.require(a, requirements="W") for a in lattice]
    cx, cy = np.require(cx, float, "CW"), np.require(cy, float, "CW")
    return drop_chunk(c, jet, geo, cx, cy, *lattice, int(starts), corner == radius)
