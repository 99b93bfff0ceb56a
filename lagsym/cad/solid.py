"""What a solid under a patch needs: the surface's lowest height, a base below it, the volume.

The solid is the region between the patch (the top face) and the plane
``z = base_z`` over the patch's ``(x, y)`` box.  Both quantities are exact:

* The lowest height: every Bernstein coefficient bounds the patch from
  below by its minimum (the convex hull property), and the heights at the
  corners are attained.  Halving the patch (de Casteljau, across the
  direction in which its net varies most) narrows the two bounds; a
  best-first search halves only the pieces that may hold the minimum.  A base is accepted only when it lies strictly below a proven
  lower bound, so an accepted solid never touches its base.
* The volume: with ``x`` a polynomial in ``u`` alone and ``y`` in ``v`` alone,
  ``V = int int (z - base_z) x'(u) y'(v) du dv``, and the integral of a
  Bernstein polynomial times the derivative of another is a rational number.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass
from fractions import Fraction
from math import comb

from ..errors import InputError
from ..values import as_exact
from .patch import BezierPatch, BSplinePatch, split_half

__all__ = ["HeightBounds", "lowest_height", "check_base", "exact_height", "volume", "polynomial_volume"]

RELATIVE_TOLERANCE = Fraction(1, 2**40)  # of the Bernstein coefficients' range: far below any machining use
MAX_PIECES = 4_000  # a safety net bounding the search; near a single minimum it needs a few hundred


@dataclass(frozen=True)
class HeightBounds:
    """The lowest height of a patch lies in ``[lower, upper]``; ``upper`` is attained."""

    lower: Fraction
    upper: Fraction


def _halves(z: list[list[Fraction]]) -> list[list[list[Fraction]]]:
    """The two halves of a Bezier net of heights, cut across the direction in which it varies most.

    Cutting one way only keeps a valley along one axis from multiplying the
    pieces: along the valley nothing is learnt by cutting.
    """
    along_u = max(abs(a - b) for col in zip(*z) for a, b in zip(col, col[1:])) if len(z) > 1 else 0
    along_v = max(abs(a - b) for row in z for a, b in zip(row, row[1:])) if len(z[0]) > 1 else 0
    if along_v >= along_u:
        left, right = zip(*(split_half(row) for row in z))
        return [[list(r) for r in left], [list(r) for r in right]]
    a, b = zip(*(split_half(list(col)) for col in zip(*z)))
    return [[list(r) for r in zip(*a)], [list(r) for r in zip(*b)]]


def _corners(z) -> Fraction:
    return min(z[0][0], z[0][-1], z[-1][0], z[-1][-1])


def _search(pieces: list[list[list[Fraction]]], tolerance: Fraction, below: Fraction | None) -> HeightBounds:
    heap = []
    upper = min(_corners(z) for z in pieces)
    for j, z in enumerate(pieces):
        heapq.heappush(heap, (min(min(r) for r in z), j, z))
    count = len(pieces)
    while True:
        lower = min(heap[0][0], upper)  # pieces kept before upper last fell may lie wholly above it
        z = heap[0][2]
        if upper - lower <= tolerance or count > MAX_PIECES:
            return HeightBounds(lower, upper)
        if below is not None and (lower > below or upper <= below):
            return HeightBounds(lower, upper)  # decided: no need for the exact height
        heapq.heappop(heap)
        for half in _halves(z):
            upper = min(upper, _corners(half))
            low = min(min(r) for r in half)
            if low < upper:
                count += 1
                heapq.heappush(heap, (low, count, half))
        if not heap:
            return HeightBounds(upper, upper)


def _pieces(patch) -> list[BezierPatch]:
    return patch.bezier_pieces() if isinstance(patch, BSplinePatch) else [patch]


def _tolerance(pieces: list[BezierPatch]) -> Fraction:
    flat = [v for p in pieces for row in p.heights() for v in row]
    return (max(flat) - min(flat) or 1) * RELATIVE_TOLERANCE


def lowest_height(patch: BSplinePatch | BezierPatch, tolerance: Fraction | None = None) -> HeightBounds:
    """Exact bounds on the lowest height of ``patch`` over its box.

    Parameters
    ----------
    patch : BSplinePatch or BezierPatch
    tolerance : Fraction, optional
        Width of the bounds (default ``2**-40`` of the range of the Bernstein coefficients).

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> from lagsym.cad import cad_patch
    >>> g = grid_from_table([-1, 0, 1], [0, 1], [[1, 1], [0, 0], [1, 1]])  # z = x**2
    >>> b = lowest_height(cad_patch(g))
    >>> b.lower <= 0 <= b.upper, float(b.upper)
    (True, 0.0)
    """
    pieces = _pieces(patch)
    return _search([p.heights() for p in pieces], Fraction(tolerance) if tolerance is not None else _tolerance(pieces),
                   None)


def check_base(patch: BSplinePatch | BezierPatch, base_z, source: str = "<surface>") -> Fraction:
    """``base_z`` as an exact number if it lies below the whole surface, else an InputError.

    The error names the base and the surface's lowest height.
    """
    base = exact_height(base_z, "--base-z", source)
    pieces = _pieces(patch)
    tol = _tolerance(pieces)
    decided = _search([p.heights() for p in pieces], tol, base)
    if decided.lower > base:
        return base
    # Refused early on a height the surface reaches: find how low it goes, for the message.
    low = _search([p.heights() for p in pieces], tol, None) if decided.upper <= base else decided
    lowest = _height(low.upper, tol)
    if low.upper - low.lower > tol:  # the search stopped short (a valley at a height it cannot reach)
        lowest = f"between {_height(low.lower, tol)} and {lowest}"
    raise InputError(f"{source}: --base-z {_show(base)} is not below the surface, whose lowest height is "
                     f"{lowest}; a solid needs its base below the whole surface")


def exact_height(value, name: str = "base_z", source: str = "<surface>") -> Fraction:
    """A height as an exact number, by lagsym's one policy (:func:`lagsym.values.as_exact`).

    Examples
    --------
    >>> exact_height("1.06"), exact_height(0.1)
    (Fraction(53, 50), Fraction(1, 10))
    """
    if value is None or isinstance(value, (list, tuple, dict)):
        raise InputError(f"{source}: {name} {value!r} is not a number")
    return as_exact(value, f"{source}: {name}")


def _height(v: Fraction, tol: Fraction) -> str:
    """``v`` to ten digits, or 0 when it is within the search's tolerance of 0."""
    return "0" if abs(v) <= tol else f"{float(v):.10g}"


def _show(v: Fraction) -> str:
    return str(v.numerator) if v.denominator == 1 else f"{float(v):g}"


def _weights(nodes: list[Fraction]) -> list[Fraction]:
    """``w_i = int_0^1 b_{i,p}(s) x'(s) ds`` for ``x(s) = sum_i b_{i,p}(s) nodes[i]``."""
    p = len(nodes) - 1
    diffs = [b - a for a, b in zip(nodes, nodes[1:])]
    return [sum(p * d * Fraction(comb(p, i) * comb(p - 1, j), comb(2 * p - 1, i + j) * 2 * p)
                for j, d in enumerate(diffs)) for i in range(p + 1)]


def volume(patch: BSplinePatch | BezierPatch, base_z=0) -> Fraction:
    """The exact volume between ``patch`` and the plane ``z = base_z`` over the patch's box.

    Heights below the base count negative (the signed integral).

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> from lagsym.cad import cad_patch
    >>> volume(cad_patch(grid_from_table([0, 1, 2], [0, 1], [[0, 0], [1, 1], [4, 4]])))  # int_0^2 x**2
    Fraction(8, 3)
    """
    base = Fraction(base_z)
    total = Fraction(0)
    for piece in _pieces(patch):
        net = piece.control_points
        wx = _weights([row[0][0] for row in net])
        wy = _weights([p[1] for p in net[0]])
        total += sum(wx[i] * wy[k] * (net[i][k][2] - base) for i in range(len(wx)) for k in range(len(wy)))
    return total


def polynomial_volume(surface, base_z=0) -> Fraction:
    """The exact integral of ``F - base_z`` over the control box, from the power coefficients.

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> from lagsym.lagrange import lagrange_surface
    >>> polynomial_volume(lagrange_surface(grid_from_table([0, 1, 2], [0, 1], [[0, 0], [1, 1], [4, 4]])), -1)
    Fraction(14, 3)
    """
    x0, x1, y0, y1 = surface.grid.bounds
    top = sum(c * (x1 ** (a + 1) - x0 ** (a + 1)) / (a + 1) * (y1 ** (b + 1) - y0 ** (b + 1)) / (b + 1)
              for a, row in enumerate(surface.coefficients) for b, c in enumerate(row))
    return top - Fraction(base_z) * (x1 - x0) * (y1 - y0)
