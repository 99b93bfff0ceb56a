"""Exact work on large polynomials: its size estimated before it starts, its products in steps.

The rationals of an exact Lagrange polynomial grow with the number of nodes
and with their denominators and span; past a few hundred nodes along one axis
they take gigabytes and minutes.  :func:`check_exact_size` refuses such a
polynomial with the figure and the option that raises the limit, before any
of it is made.  :func:`stepped_product` multiplies exact matrices a few rows
at a time: a signal (Ctrl-C, SIGTERM) is acted on between steps, where one
call into FLINT would hold the interpreter until the whole product is done.

The size says little of the time: digits of many nodes' decimals cost far
more than those of small integers.  So each exact computation (a polynomial's
coefficients; the change of basis its numeric evaluation uses) is timed as
its products run: once a product has run for :data:`FORESEE_SECONDS`, the
pace of its rows gives the time the computation will take on this machine,
and one that would end later than :func:`exact_time_limit` allows (within
such a block, as a command runs, counted from the block's start for all its
computations together; else :data:`MAX_EXACT_S` for each; ``--max-exact-s``)
is refused with that figure, a second or so into it.
"""

from __future__ import annotations

import contextlib
import contextvars
import inspect
import math
import time
from fractions import Fraction
from math import gcd, log2

import flint

from .errors import InputError

__all__ = ["MAX_EXACT_MB", "MAX_EXACT_S", "ExactClock", "check_exact_size", "exact_size_mb", "exact_time_limit",
           "stepped_product", "to_fraction"]

MAX_EXACT_MB = 400  # estimated megabytes of exact rationals one polynomial may take (--max-exact-mb)
STEP_SECONDS = 0.2  # about how long one step of a stepped product holds the interpreter: a signal waits no longer
MAX_EXACT_S = 15.0  # seconds a command's exact computations may take here, foreseen from their rows (--max-exact-s)
FORESEE_SECONDS = 0.5  # how long a product runs before its pace foretells the whole computation's time
# (limit in seconds or None, the time the limit counts from or None: from each computation's own start)
_LIMIT_S: contextvars.ContextVar[tuple[float | None, float | None]] = contextvars.ContextVar(
    "exact_time_limit", default=(MAX_EXACT_S, None))


@contextlib.contextmanager
def exact_time_limit(seconds: float | None):
    """Within the block, an exact computation foreseen to end more than ``seconds`` after the block began is
    refused (None: no limit): the limit holds for all the block's exact work together, as a command's.

    Outside such a block each computation has :data:`MAX_EXACT_S` of its own.

    Examples
    --------
    >>> with exact_time_limit(60.0):
    ...     pass
    """
    token = _LIMIT_S.set((None if seconds is None else float(seconds), time.perf_counter()))
    try:
        yield
    finally:
        _LIMIT_S.reset(token)


class ExactClock:
    """The time one exact computation (``what``, from ``source``) has taken; refuses it once it foresees too long."""

    def __init__(self, what: str, source=None):
        self.what, self.source = what, source
        self.limit, since = _LIMIT_S.get()
        self.started = time.perf_counter() if since is None else since

    def foresee(self, done: int, total: int, spent: float, products_after: int) -> None:
        """Refuse if the computation, its current product ``done`` of ``total`` rows in after ``spent`` seconds and
        ``products_after`` as long to follow, would end past the limit.  A pace is trusted after ``FORESEE_SECONDS``;
        before that, only a computation already past the limit is refused."""
        if self.limit is None or done >= total:
            return
        elapsed = time.perf_counter() - self.started
        if spent < FORESEE_SECONDS and elapsed <= self.limit:
            return
        rest = spent / done * (total - done) + products_after * spent / done * total
        foreseen = elapsed + rest
        if foreseen > self.limit:
            where = f"{self.source}: " if self.source else ""
            raise InputError(f"{where}the exact {self.what} would take about {_seconds(foreseen, self.limit)} s here "
                             f"(foreseen from its first {done} of {total} rows), more than the limit of "
                             f"{self.limit:g} s; use fewer "
                             f"points (a large grid: 'lagsym piecewise') or raise the limit (--max-exact-s, "
                             f"exact_time_limit() in Python)")


def _seconds(foreseen: float, limit: float) -> str:
    """``foreseen`` in whole seconds, rounded up where rounding would read as no more than ``limit``."""
    return str(round(foreseen) if round(foreseen) > limit else math.ceil(foreseen))


def _basis_bits(nodes: tuple[Fraction, ...]) -> float:
    """An upper bound on the bits of the reduced rationals of the basis matrix on ``nodes``.

    With the nodes written ``x_j = P_j / D`` (``D`` the least common multiple of
    their denominators), ``Bx[i, a] = e_(n-1-a)(P_j, j != i) D**a / prod_(j != i)
    (P_i - P_j)``: its numerator is at most ``prod (1 + |P_j|) D**a`` and its
    denominator at most ``R**(n-1)``, ``R`` the span of the ``P_j``.  So an entry
    takes at most ``(n-1) (log2(1 + M) + log2 R) + a log2 D`` bits, ``M`` the
    largest ``|P_j|``; the sum over the ``n**2`` entries grows as ``n**3``.
    """
    n = len(nodes)
    if n < 2:
        return 64.0
    d = 1
    for v in nodes:
        d = d * v.denominator // gcd(d, v.denominator)
    scaled = [v.numerator * (d // v.denominator) for v in nodes]
    m = max(abs(v) for v in scaled)
    r = max(scaled) - min(scaled)
    per_row = n * ((n - 1) * (log2(1 + m) + log2(max(r, 1))) + 2) + n * (n - 1) / 2 * log2(d)
    return n * per_row


def _value_bits(values) -> float:
    return max((v.numerator.bit_length() + v.denominator.bit_length() for v in values), default=1)


def exact_size_mb(x_nodes, y_nodes=None, values=()) -> float:
    """The estimated megabytes of exact rationals the polynomial on these nodes takes, before any is made.

    The Lagrange basis matrix of an axis of ``n`` nodes holds ``n**2``
    rationals whose digits grow with ``n`` and with the nodes' denominators
    and span (:func:`_basis_bits` bounds them); a surface adds its ``n x m``
    coefficients, each about as long as a row of each basis together.  This
    is the figure :func:`lagrange_curve` and :func:`lagrange_surface` check
    against ``max_mb`` before the work starts: memory and time grow with it
    (about 150 MB of rationals and 5 s for a curve of 500 points).

    Examples
    --------
    >>> from fractions import Fraction
    >>> round(exact_size_mb([Fraction(i) for i in range(3)]), 6)
    8e-06
    """
    xs = tuple(Fraction(v) for v in x_nodes)
    bits = _basis_bits(xs)
    if y_nodes is not None:
        ys = tuple(Fraction(v) for v in y_nodes)
        by = _basis_bits(ys)
        n, m = len(xs), len(ys)
        bits += by + n * m * (bits / n / n + by / m / m + _value_bits(values))
    return bits / 8 / 1e6


def check_exact_size(what: str, source, x_nodes, y_nodes, values, max_mb: float | None) -> None:
    """Refuse the exact ``what`` on these nodes if :func:`exact_size_mb` is more than ``max_mb`` (None: no limit)."""
    if max_mb is None:
        return
    size = exact_size_mb(x_nodes, y_nodes, values)
    if size > max_mb:
        where = f"{source}: " if source else ""
        raise InputError(f"{where}the exact {what} would take an estimated {_mb(size)} of exact rationals, more than "
                         f"the limit of {_mb(max_mb)}; use fewer points (a large grid: 'lagsym piecewise') or raise "
                         f"the limit (--max-exact-mb, max_mb= in Python)")


def _mb(size: float) -> str:
    return f"{size / 1000:.3g} GB" if size >= 1000 else f"{size:.3g} MB"


def stepped_product(a: flint.fmpq_mat, b: flint.fmpq_mat, seconds: float = STEP_SECONDS, *,
                    clock: ExactClock | None = None, products_after: int = 0) -> flint.fmpq_mat:
    """``a * b``, exact, computed a block of rows of ``a`` at a time, each block taking about ``seconds``.

    The first block is one row; each next one as many rows as the last
    block's pace fits in ``seconds`` (at most four times as many).  FLINT
    shares a common denominator within a block, so blocks of several rows
    cost no more than the whole product at once.  The result is the same
    exact matrix whatever the blocks.  With a ``clock``, the computation is
    refused once its pace foresees it past the limit
    (:meth:`ExactClock.foresee`; ``products_after``: products as long still
    to come).

    Examples
    --------
    >>> a, b = flint.fmpq_mat(3, 2, [1, 2, 3, 4, 5, 6]), flint.fmpq_mat(2, 2, [flint.fmpq(1, 2), 0, 0, 1])
    >>> stepped_product(a, b) == a * b
    True
    """
    n, k, m = a.nrows(), a.ncols(), b.ncols()
    entries, out = a.entries(), []
    i, rows, began = 0, 1, time.perf_counter()
    while i < n:
        h = min(rows, n - i)
        start = time.perf_counter()
        out.extend((flint.fmpq_mat(h, k, entries[i * k:(i + h) * k]) * b).entries())
        spent = time.perf_counter() - start
        i += h
        rows = max(1, min(4 * h, int(h * seconds / max(spent, 1e-6))))
        if clock is not None:
            clock.foresee(i, n, time.perf_counter() - began, products_after)
    return flint.fmpq_mat(n, m, out)


_UNNORMALIZED = "_normalize" in inspect.signature(Fraction.__new__).parameters


def to_fraction(v: flint.fmpq) -> Fraction:
    """``v`` as a Fraction: FLINT keeps rationals in lowest terms, so their gcd (long for big ones) is not sought again.

    >>> to_fraction(flint.fmpq(6, 4))
    Fraction(3, 2)
    """
    return Fraction(int(v.p), int(v.q), _normalize=False) if _UNNORMALIZED else Fraction(int(v.p), int(v.q))
