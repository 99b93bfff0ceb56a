"""The shared program model: the few statements every dialect's macro is made of.

A macro is a tree of :class:`Assign`, :class:`Clamp`, :class:`Loop` and
:class:`Move` over named variables.  Each dialect module renders the tree in
its own syntax (``#105``, ``#<z>``, ``Q6``); :func:`run` executes the
straight-line parts on the PC in decimal arithmetic of a chosen precision,
rounding after every operation as the control does, which is how lagsym
predicts a program's arithmetic error before it is written.
"""

from __future__ import annotations

from dataclasses import dataclass
from decimal import ROUND_HALF_EVEN, ROUND_HALF_UP, Context, Decimal, localcontext
from fractions import Fraction
from typing import Union

from ..errors import ProgramError

__all__ = ["Var", "Const", "Op", "Sqrt", "Round", "div", "sqrt", "round_", "Assign", "Clamp", "Choose", "Item", "SetItem",
           "Loop", "Move",
           "Expr", "Statement",
           "var", "const", "add", "sub", "mul", "decimal_context", "run", "variables", "written"]


@dataclass(frozen=True)
class Var:
    """A variable, by its role name (``"z"``, ``"g3"``); dialects map names to numbers."""

    name: str


@dataclass(frozen=True)
class Const:
    """An exact constant; the dialect writes it with the control's number of significant digits."""

    value: Fraction


@dataclass(frozen=True)
class Op:
    """A binary operation ``a op b`` with ``op`` one of ``+ - * /``."""

    op: str
    a: "Expr"
    b: "Expr"


@dataclass(frozen=True)
class Sqrt:
    """The square root of an expression (``SQRT[..]``, ``FN 5``)."""

    a: "Expr"


@dataclass(frozen=True)
class Round:
    """The nearest integer, halves away from zero (Fanuc and LinuxCNC ``ROUND[..]``)."""

    a: "Expr"


@dataclass(frozen=True)
class Item:
    """The numbered variable whose number is the value of ``index`` (``#[#idx]``): a table's entry."""

    index: Var


Expr = Union[Var, Const, Op, Sqrt, Round, Item]


@dataclass(frozen=True)
class Assign:
    """``target = expr``."""

    target: Var
    expr: Expr


@dataclass(frozen=True)
class Clamp:
    """``if target > limit: target = limit``: the last row or point stops at the box edge."""

    target: Var
    limit: Const


@dataclass(frozen=True)
class SetItem:
    """``#number = value``: one entry of a table the program reads with :class:`Item`."""

    number: int
    value: Const


@dataclass(frozen=True)
class Choose:
    """``if test OP limit: target = value``, ``OP`` ``LT`` or ``GT``: a lower clamp, a maximum, a row's ends.

    ``test`` is a variable; ``limit`` and ``value`` a variable or a constant.
    """

    target: Var
    test: Var
    op: str
    limit: "Expr"
    value: "Expr"

    def __post_init__(self):
        if self.op not in ("LT", "GT"):
            raise ValueError(f"Choose compares with LT or GT, not {self.op!r}")


@dataclass(frozen=True)
class Loop:
    """``counter = 0; while counter <= last: body; counter = counter + 1``. Runs at least once (``last >= 0``)."""

    counter: Var
    last: int
    body: tuple


@dataclass(frozen=True)
class Move:
    """A straight feed move to the values of three variables (X, Y, Z)."""

    x: Var
    y: Var
    z: Var


Statement = Union[Assign, Clamp, Choose, SetItem, Loop, Move]


def var(name: str) -> Var:
    """A variable by role name."""
    return Var(name)


def const(value) -> Const:
    """An exact constant."""
    return Const(Fraction(value))


def add(a: Expr, b: Expr) -> Op:
    """``a + b``."""
    return Op("+", a, b)


def sub(a: Expr, b: Expr) -> Op:
    """``a - b``."""
    return Op("-", a, b)


def mul(a: Expr, b: Expr) -> Op:
    """``a * b``."""
    return Op("*", a, b)


def div(a: Expr, b: Expr) -> Op:
    """``a / b``."""
    return Op("/", a, b)


def sqrt(a: Expr) -> Sqrt:
    """``SQRT[a]``."""
    return Sqrt(a)


def round_(a: Expr) -> Round:
    """``ROUND[a]``."""
    return Round(a)


def decimal_context(precision: int) -> Context:
    """Decimal arithmetic with ``precision`` significant digits, rounding half to even."""
    return Context(prec=precision, rounding=ROUND_HALF_EVEN, Emin=-999, Emax=999)


def written(value: Fraction, digits: int) -> Decimal:
    """``value`` as a program writes it: at most ``digits`` digits, a lone leading zero not counted.

    Controls limit the digits of a constant (a Fanuc 16/18 reads at most 8),
    so a small constant keeps fewer significant digits: 1/3 is 0.33333333,
    1/3000 is 0.00033333.

    Examples
    --------
    >>> written(Fraction(1, 3), 8), written(Fraction(1, 3000), 8), written(Fraction(-400, 3), 8)
    (Decimal('0.33333333'), Decimal('0.00033333'), Decimal('-133.33333'))
    """
    if value == 0:
        return Decimal(0)
    with localcontext() as ctx:
        ctx.prec = 80
        d = Decimal(value.numerator) / Decimal(value.denominator)
        integer_digits = max(d.adjusted() + 1, 0)
        if integer_digits > digits:
            raise ProgramError(f"the constant {d:.0f} has {integer_digits} digits, more than the {digits} the "
                               f"control reads; use 15-digit arithmetic (--precision 15) or fewer control points")
        decimals = max(digits - integer_digits, 0)
        return d.quantize(Decimal(1).scaleb(-decimals), rounding=ROUND_HALF_EVEN)


def _constant(value: Fraction, ctx: Context) -> Decimal:
    return ctx.plus(written(value, ctx.prec))


def _eval(e: Expr, env: dict, ctx: Context) -> Decimal:
    if isinstance(e, Var):
        return env[e.name]
    if isinstance(e, Const):
        return _constant(e.value, ctx)
    if isinstance(e, Sqrt):
        return ctx.sqrt(_eval(e.a, env, ctx))
    if isinstance(e, Round):
        return _eval(e.a, env, ctx).to_integral_value(rounding=ROUND_HALF_UP)
    a, b = _eval(e.a, env, ctx), _eval(e.b, env, ctx)
    if e.op == "+":
        return ctx.add(a, b)
    if e.op == "-":
        return ctx.subtract(a, b)
    if e.op == "*":
        return ctx.multiply(a, b)
    return ctx.divide(a, b)


def run(statements, env: dict, ctx: Context) -> dict:
    """Execute straight-line ``Assign`` and ``Clamp`` statements on ``env`` (name -> Decimal); returns ``env``."""
    for s in statements:
        if isinstance(s, Assign):
            env[s.target.name] = _eval(s.expr, env, ctx)
        elif isinstance(s, Clamp):
            limit = _constant(s.limit.value, ctx)
            if env[s.target.name] > limit:
                env[s.target.name] = limit
        elif isinstance(s, Choose):
            t, lim = env[s.test.name], _eval(s.limit, env, ctx)
            if (t < lim) if s.op == "LT" else (t > lim):
                env[s.target.name] = _eval(s.value, env, ctx)
        else:
            raise TypeError(f"run() executes straight-line code only, not {type(s).__name__}")
    return env


def variables(statements) -> list[str]:
    """Every variable name the statements assign or count with, in order of first appearance."""
    names: list[str] = []

    def see(v: Var):
        if v.name not in names:
            names.append(v.name)

    def walk(stmts):
        for s in stmts:
            if isinstance(s, (Assign, Clamp, Choose)):
                see(s.target)
            elif isinstance(s, Loop):
                see(s.counter)
                walk(s.body)

    walk(statements)
    return names
