"""Where to probe: the nodes of a box, Chebyshev-spaced by default, and how many for a wanted fit degree.

A least-squares fit of degree ``P`` in x needs more than ``P + 1`` distinct
x values, and a few more so that generalized cross-validation can tell the
degree from the noise: :func:`node_plan` takes ``P + 1 + margin`` nodes a
side (``margin`` 2 by default), likewise in y.

The nodes are by default the Chebyshev extrema of each side, ends
included: ``x_k = (a + b) / 2 - (b - a) / 2 * cos(k * pi / (n - 1))``.
Polynomial interpolation at these nodes has a Lebesgue constant that grows
only as ``(2 / pi) * log(n)``, where at evenly spaced nodes it grows as
``2**n / (n log n)``: measured errors at the nodes near the box's edges are
amplified far less, and a least-squares fit on them inherits that (see
docs/probing.md).  Even spacing and nodes the user lists are the options.
Every node is rounded to ``decimals`` places, the digits the program writes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

from ..errors import InputError
from ..values import as_exact, choice

__all__ = ["SPACINGS", "MAX_NODES", "ProbePlan", "node_plan", "axis_nodes"]

SPACINGS = ("chebyshev", "even", "given")
MAX_NODES = 2500  # nodes in one program: at a few seconds a node, beyond two hours of probing
DEFAULT_MARGIN = 2


@dataclass(frozen=True)
class ProbePlan:
    """The nodes of a probing program: x and y values (exact decimals) and how they were chosen.

    ``nodes()`` lists them in the order the program probes them: along x,
    row by row in y, every other row backwards (no long move back).
    """

    xs: tuple[Fraction, ...]
    ys: tuple[Fraction, ...]
    spacing: str
    degree: tuple[int, int] | None = None
    margin: int = DEFAULT_MARGIN

    def __len__(self) -> int:
        return len(self.xs) * len(self.ys)

    def nodes(self) -> tuple[tuple[int, Fraction, Fraction], ...]:
        """``(number, x, y)`` for each node, numbered from 1 in probing order."""
        order = [(x, y) for j, y in enumerate(self.ys) for x in (self.xs if j % 2 == 0 else self.xs[::-1])]
        return tuple((k, x, y) for k, (x, y) in enumerate(order, start=1))

    def describe(self) -> str:
        """One line: ``7 x 7 chebyshev nodes, degree 4x4 + margin 2``."""
        why = f", degree {self.degree[0]}x{self.degree[1]} + margin {self.margin}" if self.degree else ""
        return f"{len(self.xs)} x {len(self.ys)} {self.spacing} nodes{why}"


def axis_nodes(lo, hi, n: int, spacing: str = "chebyshev", decimals: int = 3) -> tuple[Fraction, ...]:
    """``n`` nodes on ``[lo, hi]``, ends included, rounded to ``decimals`` places.

    Examples
    --------
    >>> [float(v) for v in axis_nodes(0, 10, 5)]
    [0.0, 1.464, 5.0, 8.536, 10.0]
    >>> [float(v) for v in axis_nodes(0, 10, 5, "even")]
    [0.0, 2.5, 5.0, 7.5, 10.0]
    """
    choice(spacing, SPACINGS[:2], "node spacing")
    lo, hi = as_exact(lo, "box start"), as_exact(hi, "box end")
    if not hi > lo:
        raise InputError(f"box side {float(lo):g} to {float(hi):g}: the end must be above the start")
    if n < 2:
        raise InputError(f"{n} nodes a side: at least 2")
    scale = 10 ** decimals
    out = []
    for k in range(n):
        t = (1 - math.cos(math.pi * k / (n - 1))) / 2 if spacing == "chebyshev" else Fraction(k, n - 1)
        if k in (0, n - 1):
            t = Fraction(k // (n - 1))
        v = lo + (hi - lo) * Fraction(t)
        out.append(Fraction(round(v * scale), scale))
    if len(set(out)) != n:
        raise InputError(f"{n} nodes on {float(lo):g} to {float(hi):g} are closer than {decimals} decimals tell apart")
    return tuple(out)


def node_plan(box, degree=(4, 4), *, spacing: str = "chebyshev", margin: int = DEFAULT_MARGIN,
              nodes=None, given=None, decimals: int = 3) -> ProbePlan:
    """The nodes to probe over ``box = (x0, x1, y0, y1)``.

    Parameters
    ----------
    box : (x0, x1, y0, y1)
        The region to probe, in program units.
    degree : int or (int, int)
        The fit degree wanted in x and y; ``degree + 1 + margin`` nodes a side.
    spacing : {"chebyshev", "even", "given"}
        Chebyshev extrema (the default), even spacing, or the values in ``given``.
    margin : int
        Nodes a side beyond the ``degree + 1`` an interpolant would need (0 to 20).
    nodes : (int, int), optional
        Nodes a side given outright (overrides ``degree`` and ``margin``).
    given : (sequence, sequence), optional
        The x and y values for ``spacing="given"``.

    Examples
    --------
    >>> p = node_plan((0, 100, 0, 50), 4)
    >>> len(p), p.describe()
    (49, '7 x 7 chebyshev nodes, degree 4x4 + margin 2')
    """
    spacing = choice(spacing, SPACINGS, "node spacing")
    if spacing == "given":
        if given is None:
            raise InputError("node spacing 'given' needs the x and y values")
        xs, ys = (tuple(sorted({as_exact(v, f"{a} node") for v in vals})) for a, vals in zip("xy", given))
        if len(xs) < 2 or len(ys) < 2:
            raise InputError(f"given nodes: {len(xs)} x and {len(ys)} y values; at least 2 of each")
        plan = ProbePlan(xs, ys, spacing)
    else:
        x0, x1, y0, y1 = box
        if nodes is not None:
            nx, ny, deg = int(nodes[0]), int(nodes[1]), None
        else:
            deg = (int(degree), int(degree)) if isinstance(degree, int) else (int(degree[0]), int(degree[1]))
            if not all(0 <= d <= 12 for d in deg):
                raise InputError(f"fit degree {deg[0]}x{deg[1]}: 0 to 12 in each direction")
            if not 0 <= int(margin) <= 20:
                raise InputError(f"margin {margin}: 0 to 20 nodes a side")
            nx, ny = deg[0] + 1 + int(margin), deg[1] + 1 + int(margin)
        plan = ProbePlan(axis_nodes(x0, x1, nx, spacing, decimals), axis_nodes(y0, y1, ny, spacing, decimals),
                         spacing, deg, int(margin))
    if len(plan) > MAX_NODES:
        raise InputError(f"{len(plan.xs)} x {len(plan.ys)} = {len(plan)} nodes, more than the limit of {MAX_NODES}")
    return plan
