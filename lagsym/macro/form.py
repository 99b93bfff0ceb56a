"""The well-conditioned form of the surface for the control: normalized coordinates and nested Horner.

The expanded polynomial in millimetre coordinates is useless on a control that
rounds every result to 8 significant digits: its monomial coefficients run to
thousands and cancel.  Instead each axis is mapped onto ``[-1, 1]``,

    U = (P - PC) * PK,    V = (R - RC) * RK,

where ``P`` is the coordinate along a raster row and ``R`` the coordinate
across the rows, and the height in program units is

    Z = ZO + sum_a U**a * G_a(V),    G_a(V) = sum_b K[a][b] * V**b.

``G_a`` depends only on the row, so the control evaluates it once per row
(Horner in ``V``) and per point runs one Horner in ``U`` of ``n - 1`` steps.
The coefficients ``K`` are exact rationals; the program writes them with the
control's number of significant digits.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from ..grid import grid_from_table
from ..lagrange import LagrangeSurface, lagrange_surface
from ..machine import MachineSettings
from .model import Assign, Const, Var, add, const, mul, sub, var
from .plan import exact

__all__ = ["RowForm", "row_form", "row_statements", "point_statements"]


@dataclass(frozen=True)
class RowForm:
    """The surface in normalized coordinates, arranged for a raster along ``direction``.

    Attributes
    ----------
    direction : str
        ``"x"``: ``P`` is X and ``R`` is Y; ``"y"``: ``P`` is Y and ``R`` is X.
    coefficients : tuple of tuple of Fraction
        ``coefficients[a][b]`` multiplies ``U**a * V**b``; heights in program units.
    pc, pk, rc, rk : Fraction
        Centre and inverse half-width of the ``P`` and ``R`` axes, in program units.
    z0 : Fraction
        Height offset added last (Z origin plus stock to leave).
    """

    direction: str
    coefficients: tuple[tuple[Fraction, ...], ...]
    pc: Fraction
    pk: Fraction
    rc: Fraction
    rk: Fraction
    z0: Fraction

    @property
    def shape(self) -> tuple[int, int]:
        """Number of coefficients in ``U`` and in ``V``."""
        return len(self.coefficients), len(self.coefficients[0])


def _norm(nodes, scale, origin):
    lo, hi = nodes[0] * scale + origin, nodes[-1] * scale + origin
    centre, half = (lo + hi) / 2, (hi - lo) / 2
    return centre, 1 / half, tuple((n * scale + origin - centre) / half for n in nodes)


def row_form(surface: LagrangeSurface, settings: MachineSettings, direction: str = "x") -> RowForm:
    """The normalized Horner form of ``surface`` in program units, for rows along ``direction``.

    >>> from lagsym.grid import grid_from_table
    >>> from lagsym.lagrange import lagrange_surface
    >>> f = row_form(lagrange_surface(grid_from_table([0, 2], [0, 1], [[0, 1], [2, 3]])), MachineSettings())
    >>> f.coefficients, f.pc, f.pk
    (((Fraction(3, 2), Fraction(1, 2)), (Fraction(1, 1), Fraction(0, 1))), Fraction(1, 1), Fraction(1, 1))
    """
    g = surface.grid
    uf = exact(settings.unit_factor)
    s = exact(settings.scale) * uf
    ox, oy, oz = (exact(v) * uf for v in settings.origin_mm)
    xc, xk, un = _norm(g.x, s, ox)
    yc, yk, vn = _norm(g.y, s, oy)
    zn = [[z * s for z in row] for row in g.z]
    c = lagrange_surface(grid_from_table(un, vn, zn)).coefficients
    z0 = oz + exact(settings.stock_to_leave_mm) * uf
    if direction == "x":
        return RowForm("x", c, xc, xk, yc, yk, z0)
    ct = tuple(tuple(c[a][b] for a in range(len(c))) for b in range(len(c[0])))
    return RowForm("y", ct, yc, yk, xc, xk, z0)


def _horner(target: Var, coeffs, x: Var) -> list[Assign]:
    coeffs = list(coeffs)
    while len(coeffs) > 1 and isinstance(coeffs[-1], Const) and coeffs[-1].value == 0:
        coeffs.pop()  # an exact zero leading coefficient costs a statement and changes nothing
    out = [Assign(target, coeffs[-1])]
    for c in reversed(coeffs[:-1]):
        out.append(Assign(target, add(mul(target, x), c)))
    return out


def row_statements(form: RowForm, r: Var, prefix: str = "g") -> list[Assign]:
    """Statements run once per row: ``v`` from ``r``, then every ``G_a(v)`` into ``g0 .. g(n-1)``."""
    v = var("v")
    out = [Assign(v, mul(sub(r, const(form.rc)), const(form.rk)))]
    for a, row in enumerate(form.coefficients):
        out += _horner(var(f"{prefix}{a}"), [const(c) for c in row], v)
    return out


def point_statements(form: RowForm, p: Var, z: Var, prefix: str = "g") -> list[Assign]:
    """Statements run once per point: ``u`` from ``p``, then ``z = ZO + sum_a u**a * g_a``."""
    u = var("u")
    n = form.shape[0]
    out = [Assign(u, mul(sub(p, const(form.pc)), const(form.pk)))]
    out += _horner(z, [var(f"{prefix}{a}") for a in range(n)], u)
    if form.z0:
        out.append(Assign(z, add(z, const(form.z0))))
    return out
