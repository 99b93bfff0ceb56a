"""The control's arithmetic against the PC's: the error a macro program is predicted to make.

The control rounds every result to its number of significant digits; the
row and point statements of the loops are run here in decimal arithmetic of
the same precision and compared with the exact (or, for a ball-end cutter,
the stable floating) reference computed on the PC.
"""

from __future__ import annotations

from decimal import Decimal
from fractions import Fraction

import numpy as np

from .loops import MacroLoops
from .model import decimal_context, run

__all__ = ["predicted_error"]


def _spread(lo: int, hi: int, limit: int) -> list[int]:
    """Up to ``limit`` indices from ``lo`` to ``hi`` inclusive, evenly spread, ends included."""
    return sorted(set(np.linspace(lo, hi, min(hi - lo + 1, limit)).round().astype(int).tolist()))


def _decimal(v: Fraction, ctx) -> Decimal:
    return ctx.divide(Decimal(v.numerator), Decimal(v.denominator))


def _errors(loops: MacroLoops, ctx, row_ks, point_ks) -> dict[tuple[int, int], Fraction]:
    """Error at each raster index pair (row, point): the control's arithmetic against the reference."""
    rows, pts = loops.raster.rows, loops.raster.points
    out = {}
    for kr in row_ks:
        env = run(loops.row_code, {"r": _decimal(min(rows.start + kr * rows.step, rows.end), ctx)}, ctx)
        for kp in point_ks:
            env["p"] = _decimal(min(pts.start + kp * pts.step, pts.end), ctx)
            run(loops.point_code, env, ctx)
            ref = loops.reference(Fraction(env["p"]), Fraction(env["r"]))
            out[kr, kp] = max(abs(Fraction(env[name]) - Fraction(want)) for name, want in zip(loops.outputs, ref))
    return out


def predicted_error(loops: MacroLoops, precision: int, rows: int = 25, points: int = 41) -> float:
    """Largest difference between the control's arithmetic and the PC's over the raster, by sampling.

    The row and point statements of ``loops`` are run in decimal arithmetic
    with ``precision`` significant digits, rounding after every operation, at
    up to ``rows`` x ``points`` raster positions (always including the edges),
    and compared with :meth:`MacroLoops.reference`.  The error varies quickly
    between the nodes, so the neighbourhoods of the four worst samples are then
    searched at the raster's own spacing.  Returns the largest coordinate
    difference found, in program units (a :class:`~lagsym.macro.MacroProgram`
    holds it in mm).
    """
    ctx = decimal_context(precision)
    nr, np_ = loops.raster.rows.count, loops.raster.points.count
    row_ks, point_ks = _spread(0, nr, rows), _spread(0, np_, points)
    found = _errors(loops, ctx, row_ks, point_ks)
    dr, dp = max(nr // max(rows - 1, 1), 1), max(np_ // max(points - 1, 1), 1)
    for kr, kp in sorted(found, key=found.get, reverse=True)[:4]:
        near = _errors(loops, ctx, _spread(max(kr - dr, 0), min(kr + dr, nr), 9),
                       _spread(max(kp - dp, 0), min(kp + dp, np_), 13))
        found.update(near)
    return float(max(found.values()))
