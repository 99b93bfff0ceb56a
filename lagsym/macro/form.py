"""The well-conditioned forms of the surface for the control: normalized coordinates, then Horner or Lagrange basis.

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

That *Horner* form is short, and exact enough for 15-digit arithmetic, but its
coefficients grow with the degree (to about 400 times the heights at 7x7
equally spaced nodes) and with 8 significant digits a 7x7 surface loses up to
a micrometre.  The *Lagrange* form evaluates the tensor-product basis itself,

    Z = ZO + sum_i L_i(U) * G_i(V),    G_i(V) = sum_k L_k(V) * H[i][k],
    L_i(U) = W_i * prod_{j != i} (U - U_j),

whose constants are the scaled heights ``H`` and the weights ``W``; its error
is bounded by the Lebesgue constants, some 6 times below Horner's at 7x7 with
8 digits (100 times at 10x10), for a little more program text.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from ..grid import grid_from_table
from ..lagrange import LagrangeSurface, lagrange_surface
from ..machine import MachineSettings
from ..values import choice
from ._placement import placement
from .model import Assign, Const, Var, add, const, mul, sub, var

__all__ = ["FORMS", "RowForm", "row_form", "row_statements", "point_statements", "differentiation_matrix"]

FORMS = ("horner", "lagrange")


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
    kind : str
        ``"horner"`` or ``"lagrange"``: which statements the control runs.
    p_nodes, r_nodes : tuple of Fraction
        The normalized nodes on each axis (for the Lagrange form).
    heights : tuple of tuple of Fraction
        ``heights[i][k]``: the scaled height at ``(p_nodes[i], r_nodes[k])``.
    """

    direction: str
    coefficients: tuple[tuple[Fraction, ...], ...]
    pc: Fraction
    pk: Fraction
    rc: Fraction
    rk: Fraction
    z0: Fraction
    kind: str = "horner"
    p_nodes: tuple[Fraction, ...] = ()
    r_nodes: tuple[Fraction, ...] = ()
    heights: tuple[tuple[Fraction, ...], ...] = ()

    @property
    def shape(self) -> tuple[int, int]:
        """Number of coefficients in ``U`` and in ``V``."""
        return len(self.coefficients), len(self.coefficients[0])


def _norm(nodes, scale, origin):
    lo, hi = nodes[0] * scale + origin, nodes[-1] * scale + origin
    centre, half = (lo + hi) / 2, (hi - lo) / 2
    return centre, 1 / half, tuple((n * scale + origin - centre) / half for n in nodes)


def row_form(surface: LagrangeSurface, settings: MachineSettings, direction: str = "x",
             kind: str = "horner") -> RowForm:
    """The normalized Horner form of ``surface`` in program units, for rows along ``direction``.

    Examples
    --------
    >>> from lagsym.grid import grid_from_table
    >>> from lagsym.lagrange import lagrange_surface
    >>> f = row_form(lagrange_surface(grid_from_table([0, 2], [0, 1], [[0, 1], [2, 3]])), MachineSettings())
    >>> f.coefficients, f.pc, f.pk
    (((Fraction(3, 2), Fraction(1, 2)), (Fraction(1, 1), Fraction(0, 1))), Fraction(1, 1), Fraction(1, 1))
    """
    g = surface.grid
    place = placement(settings)
    s, (ox, oy, oz) = place.scale, place.origin
    xc, xk, un = _norm(g.x, s, ox)
    yc, yk, vn = _norm(g.y, s, oy)
    zn = [[z * s for z in row] for row in g.z]
    c = lagrange_surface(grid_from_table(un, vn, zn)).coefficients
    z0 = oz + place.stock
    zt = tuple(tuple(row) for row in zn)
    choice(kind, FORMS, "form")
    if direction == "x":
        return RowForm("x", c, xc, xk, yc, yk, z0, kind, un, vn, zt)
    ct = tuple(tuple(c[a][b] for a in range(len(c))) for b in range(len(c[0])))
    ht = tuple(tuple(zt[i][k] for i in range(len(zt))) for k in range(len(zt[0])))
    return RowForm("y", ct, yc, yk, xc, xk, z0, kind, vn, un, ht)


def _horner(target: Var, coeffs, x: Var) -> list[Assign]:
    coeffs = list(coeffs)
    while len(coeffs) > 1 and isinstance(coeffs[-1], Const) and coeffs[-1].value == 0:
        coeffs.pop()  # an exact zero leading coefficient costs a statement and changes nothing
    if len(coeffs) == 1:
        return [Assign(target, coeffs[0])]
    out = [Assign(target, add(mul(coeffs[-1], x), coeffs[-2]))]
    for c in reversed(coeffs[:-2]):
        out.append(Assign(target, add(mul(target, x), c)))
    return out


def _weights(nodes) -> list[Fraction]:
    out = []
    for i, a in enumerate(nodes):
        w = Fraction(1)
        for j, b in enumerate(nodes):
            if j != i:
                w /= a - b
        out.append(w)
    return out


def _basis(t: Var, nodes, tag: str) -> list[Assign]:
    """``e_j = t - t_j`` and ``L_i = W_i * prod_{j != i} e_j`` (a left-to-right product)."""
    out = [Assign(var(f"e{tag}{j}"), sub(t, const(x)) if x else t) for j, x in enumerate(nodes)]
    for i, w in enumerate(_weights(nodes)):
        acc = const(w)
        for j in range(len(nodes)):
            if j != i:
                acc = mul(acc, var(f"e{tag}{j}"))
        out.append(Assign(var(f"l{tag}{i}"), acc))
    return out


def _dot(target: Var, terms, chunk: int = 4) -> list[Assign]:
    """``target = sum of terms`` (each ``(factor, const-or-var, sign)``), left to right, ``chunk`` terms a block."""
    out: list[Assign] = []
    acc = None
    for n, (a, b, negative) in enumerate(terms):
        term = mul(a, b)
        if acc is None:
            acc = sub(const(0), term) if negative else term
        else:
            acc = sub(acc, term) if negative else add(acc, term)
        if (n + 1) % chunk == 0 and n + 1 < len(terms):
            out.append(Assign(target, acc))
            acc = target
    out.append(Assign(target, acc if acc is not None else const(0)))
    return out


def differentiation_matrix(nodes) -> list[list[Fraction]]:
    """``D[i][j] = L_j'(t_i)``: derivative values at the nodes from values at the nodes, exact.

    Examples
    --------
    >>> differentiation_matrix([-1, 0, 1])[1]
    [Fraction(-1, 2), Fraction(0, 1), Fraction(1, 2)]
    """
    t = [Fraction(x) for x in nodes]
    w = _weights(t)
    n = len(t)
    d = [[Fraction(0)] * n for _ in range(n)]
    for i in range(n):
        for j in range(n):
            if i != j:
                d[i][j] = w[j] / w[i] / (t[i] - t[j])
        d[i][i] = -sum(d[i][j] for j in range(n) if j != i)
    return d


def row_statements(form: RowForm, r: Var, prefix: str = "g", slopes: bool = False) -> list[Assign]:
    """Statements run once per row: ``v`` from ``r``, then every ``G_a(v)`` into ``g0 .. g(n-1)``.

    With ``slopes`` also what the partial derivatives need: ``dG_a/dv`` into
    ``gv0 ..`` and, for the Lagrange form, the ``u``-derivative values at the
    nodes into ``gu0 ..``.
    """
    v = var("v")
    out = [Assign(v, mul(sub(r, const(form.rc)), const(form.rk)))]
    if form.kind == "lagrange":
        out += _basis(v, form.r_nodes, "")
        for i, row in enumerate(form.heights):
            terms = [(var(f"l{k}"), const(abs(h)), h < 0) for k, h in enumerate(row) if h]
            out += _dot(var(f"{prefix}{i}"), terms)
        if slopes:
            dv = differentiation_matrix(form.r_nodes)
            for i, row in enumerate(form.heights):
                slope = [sum(dv[k][q] * row[q] for q in range(len(row))) for k in range(len(row))]
                terms = [(var(f"l{k}"), const(abs(h)), h < 0) for k, h in enumerate(slope) if h]
                out += _dot(var(f"{prefix}v{i}"), terms)
            du = differentiation_matrix(form.p_nodes)
            for i, drow in enumerate(du):
                out += _dot(var(f"{prefix}u{i}"),
                            [(const(abs(c)), var(f"{prefix}{j}"), c < 0) for j, c in enumerate(drow) if c])
        return out
    for a, row in enumerate(form.coefficients):
        out += _horner(var(f"{prefix}{a}"), [const(c) for c in row], v)
    if slopes:
        for a, row in enumerate(form.coefficients):
            out += _horner(var(f"{prefix}v{a}"), [const(b * c) for b, c in enumerate(row)][1:] or [const(0)], v)
    return out


def point_statements(form: RowForm, p: Var, z: Var, prefix: str = "g", slopes: bool = False) -> list[Assign]:
    """Statements run once per point: ``u`` from ``p``, then ``z = ZO + sum_a u**a * g_a``.

    With ``slopes`` also the exact partial derivatives in program units:
    ``zp = dZ/dP`` and ``zr = dZ/dR``.
    """
    u = var("u")
    n = form.shape[0]
    out = [Assign(u, mul(sub(p, const(form.pc)), const(form.pk)))]
    if form.kind == "lagrange":
        out += _basis(u, form.p_nodes, "")
        out += _dot(z, [(var(f"l{i}"), var(f"{prefix}{i}"), False) for i in range(n)])
        if slopes:
            out += _dot(var("zp"), [(var(f"l{i}"), var(f"{prefix}u{i}"), False) for i in range(n)])
            out += _dot(var("zr"), [(var(f"l{i}"), var(f"{prefix}v{i}"), False) for i in range(n)])
    else:
        out += _horner(z, [var(f"{prefix}{a}") for a in range(n)], u)
        if slopes:
            out += _horner(var("zp"), [mul(const(a), var(f"{prefix}{a}")) for a in range(1, n)], u)
            out += _horner(var("zr"), [var(f"{prefix}v{a}") for a in range(n)], u)
    if slopes:
        out.append(Assign(var("zp"), mul(var("zp"), const(form.pk))))
        out.append(Assign(var("zr"), mul(var("zr"), const(form.rk))))
    if form.z0:
        out.append(Assign(z, add(z, const(form.z0))))
    return out
