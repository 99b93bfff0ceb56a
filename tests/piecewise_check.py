"""An independent piecewise surface for the tests: bicubic Hermite pieces built from their definition.

The points are read by the csv module as exact decimals, the slopes at the
nodes by the 3-point Lagrange parabola in Fractions (Newton's divided
differences), and each cell is the bicubic Hermite patch of its corners'
heights, slopes and twists, evaluated in NumPy from the cubic Hermite basis
functions.  Nothing here comes from lagsym.
"""

from __future__ import annotations

import csv
from fractions import Fraction

import numpy as np


class Reference:
    """The C1 bicubic Hermite surface through the CSV's points, built from its definition."""

    def __init__(self, path):
        rows = list(csv.reader(path.read_text().splitlines()))[1:]
        pts = {(Fraction(r[0]), Fraction(r[1])): Fraction(r[2]) for r in rows if r}
        self.x = sorted({p[0] for p in pts})
        self.y = sorted({p[1] for p in pts})
        z = [[pts[xi, yk] for yk in self.y] for xi in self.x]
        zx = [list(c) for c in zip(*[self._slopes(self.x, col) for col in zip(*z)])]
        zy = [self._slopes(self.y, row) for row in z]
        zxy = [self._slopes(self.y, row) for row in zx]
        self.tables = [np.array([[float(v) for v in row] for row in t]) for t in (z, zx, zy, zxy)]
        self.bx, self.by = np.array([float(v) for v in self.x]), np.array([float(v) for v in self.y])

    @staticmethod
    def _slopes(t, f):
        """The slope at every node of the parabola through it and its neighbours (the nearest three at an end)."""
        out = []
        for i in range(len(t)):
            lo = min(max(i - 1, 0), len(t) - 3)
            a, b, c = t[lo:lo + 3]
            fa, fb, fc = f[lo:lo + 3]
            # Newton form f[a] + f[a,b](x-a) + f[a,b,c](x-a)(x-b), differentiated at t[i].
            ab, bc = (fb - fa) / (b - a), (fc - fb) / (c - b)
            abc = (bc - ab) / (c - a)
            out.append(ab + abc * ((t[i] - a) + (t[i] - b)))
        return out

    @staticmethod
    def _basis(s, d):
        """The cubic Hermite basis h00, h01, h10, h11 on [0, 1] (or its d-th derivative) at ``s``."""
        if d == 0:
            return 2 * s**3 - 3 * s**2 + 1, -2 * s**3 + 3 * s**2, s**3 - 2 * s**2 + s, s**3 - s**2
        if d == 1:
            return 6 * s**2 - 6 * s, -6 * s**2 + 6 * s, 3 * s**2 - 4 * s + 1, 3 * s**2 - 2 * s
        return 12 * s - 6, -12 * s + 6, 6 * s - 4, 6 * s - 2

    def __call__(self, x, y, dx=0, dy=0):
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        i = np.clip(np.searchsorted(self.bx, x, side="right") - 1, 0, len(self.bx) - 2)
        k = np.clip(np.searchsorted(self.by, y, side="right") - 1, 0, len(self.by) - 2)
        hx, hy = self.bx[i + 1] - self.bx[i], self.by[k + 1] - self.by[k]
        s, t = (x - self.bx[i]) / hx, (y - self.by[k]) / hy
        u0, u1, u2, u3 = self._basis(s, dx)
        v0, v1, v2, v3 = self._basis(t, dy)
        z, zx, zy, zxy = self.tables
        total = 0.0
        for hu, du in ((u0, 0), (u1, 1)):
            for hv, dv in ((v0, 0), (v1, 1)):
                r, c = i + du, k + dv
                total = total + z[r, c] * hu * hv
            for hv, dv in ((v2, 0), (v3, 1)):
                r, c = i + du, k + dv
                total = total + hy * zy[r, c] * hu * hv
        for hu, du in ((u2, 0), (u3, 1)):
            for hv, dv in ((v0, 0), (v1, 1)):
                r, c = i + du, k + dv
                total = total + hx * zx[r, c] * hu * hv
            for hv, dv in ((v2, 0), (v3, 1)):
                r, c = i + du, k + dv
                total = total + hx * hy * zxy[r, c] * hu * hv
        return total / (hx**dx * hy**dy)
