"""Reference formulas ``z = f(x, y)`` read with a strict grammar.

A formula given on the command line is text from outside, so it is never
handed to :func:`eval` or to ``sympy.sympify``.  A small recursive-descent
parser accepts exactly this grammar and nothing else::

    formula := ["z" "="] sum
    sum     := product (("+" | "-") product)*
    product := unary (("*" | "/") unary)*
    unary   := ("+" | "-") unary | power
    power   := atom ["**" unary]              (right-associative: 2**3**2 is 2**9)
    atom    := NUMBER | "x" | "y" | "pi" | FUNCTION "(" sum ")" | "(" sum ")"

with ``FUNCTION`` one of :data:`FUNCTIONS`.  Numbers are exact decimals
(``0.1`` is 1/10, as in point files).  Anything else (``^``, names such as
``__import__``, attribute access, commas, brackets, keywords) is refused with a
:class:`~lagsym.errors.FormulaError` that names the offending text and its
column.

The parsed tree is a tuple of nested tuples; :class:`Formula` evaluates it in
floating point on NumPy arrays, or in exact rational arithmetic when it uses
only ``+ - * /`` and integer powers.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from .errors import FormulaError, InputError
from .values import as_exact

__all__ = ["FUNCTIONS", "Formula", "parse_formula"]

FUNCTIONS = ("sin", "cos", "tan", "exp", "log", "sqrt", "abs")
MAX_LENGTH = 2000
MAX_DEPTH = 60  # nesting of brackets and unary signs; deeper text is refused, not a RecursionError
MAX_HEIGHT = 200  # operations one inside another in the parsed tree (a chain of 200 terms), for the same reason
MAX_EXACT_EXPONENT = 64
MAX_EXACT_BITS = 1_000_000  # bits of numerator and denominator of one exact value (about 300000 digits)

_NUMPY = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log, "sqrt": np.sqrt, "abs": np.abs}
_TOKEN = re.compile(
    r"\s*(?:(?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)|(?P<name>[A-Za-z_][A-Za-z_0-9]*)"
    r"|(?P<op>\*\*|[-+*/()=]))",
    re.ASCII,
)


def _tokens(text: str) -> list[tuple[str, str, int]]:
    out = []
    pos = 0
    end = len(text.rstrip())
    while pos < end:
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            bad = text[pos:].lstrip()[:1]
            col = len(text) - len(text[pos:].lstrip()) + 1
            hint = " (write powers as **)" if bad == "^" else ""
            raise FormulaError(f"formula {text!r}: unexpected {bad!r} at column {col}{hint}")
        kind = m.lastgroup
        out.append((kind, m.group(kind), m.start(kind) + 1))
        pos = m.end()
    out.append(("end", "", len(text) + 1))
    return out


class _Parser:
    def __init__(self, text: str):
        self.text = text
        self.toks = _tokens(text)
        self.i = 0
        self.depth = 0

    def error(self, message: str, col: int) -> FormulaError:
        return FormulaError(f"formula {self.text!r}: {message} at column {col}")

    def peek(self) -> tuple[str, str, int]:
        return self.toks[self.i]

    def take(self) -> tuple[str, str, int]:
        tok = self.toks[self.i]
        self.i += 1
        return tok

    def expect(self, value: str) -> None:
        kind, text, col = self.take()
        if text != value or kind == "end":
            found = "the end" if kind == "end" else repr(text)
            raise self.error(f"expected {value!r}, found {found}", col)

    def deeper(self, col: int) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise self.error(f"nested more than {MAX_DEPTH} levels deep", col)

    def formula(self):
        kind, text, _ = self.peek()
        if kind == "name" and text == "z" and self.toks[self.i + 1][1] == "=":
            self.i += 2
        tree = self.sum()
        kind, text, col = self.peek()
        if kind != "end":
            raise self.error(f"unexpected {text!r}", col)
        if _height(tree) > MAX_HEIGHT:
            raise FormulaError(f"formula {self.text!r}: more than {MAX_HEIGHT} operations in a chain; "
                               f"group the terms in brackets or simplify it")
        return tree

    def sum(self):
        left = self.product()
        while self.peek()[1] in ("+", "-") and self.peek()[0] == "op":
            op = self.take()[1]
            left = (op, left, self.product())
        return left

    def product(self):
        left = self.unary()
        while self.peek()[1] in ("*", "/") and self.peek()[0] == "op":
            op = self.take()[1]
            left = (op, left, self.unary())
        return left

    def unary(self):
        kind, text, col = self.peek()
        if kind == "op" and text in ("+", "-"):
            self.take()
            self.deeper(col)
            operand = self.unary()
            self.depth -= 1
            return operand if text == "+" else ("neg", operand)
        return self.power()

    def power(self):
        base = self.atom()
        kind, text, col = self.peek()
        if kind == "op" and text == "**":
            self.take()
            self.deeper(col)
            exponent = self.unary()
            self.depth -= 1
            return ("**", base, exponent)
        return base

    def atom(self):
        kind, text, col = self.take()
        if kind == "number":
            from .values import NotANumber, exact_number

            try:
                return ("num", exact_number(text))
            except NotANumber as e:
                raise self.error(str(e), col) from None
        if kind == "name":
            if text in ("x", "y"):
                return ("var", text)
            if text == "pi":
                return ("pi",)
            if text in FUNCTIONS:
                self.expect("(")
                self.deeper(col)
                arg = self.sum()
                self.depth -= 1
                self.expect(")")
                return ("call", text, arg)
            raise self.error(f"unknown name {text!r} (allowed: x, y, pi and the functions {', '.join(FUNCTIONS)})",
                             col)
        if kind == "op" and text == "(":
            self.deeper(col)
            inner = self.sum()
            self.depth -= 1
            self.expect(")")
            return inner
        found = "the end of the formula" if kind == "end" else repr(text)
        raise self.error(f"expected a number, x, y, a function or '(', found {found}", col)


def _height(tree) -> int:
    """Operations one inside another in ``tree``, counted without recursion (the tree may be deep)."""
    best, stack = 0, [(tree, 1)]
    while stack:
        node, h = stack.pop()
        best = max(best, h)
        stack.extend((c, h + 1) for c in node[1:] if isinstance(c, tuple))
    return best


def _numeric(tree, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    tag = tree[0]
    if tag == "num":
        return np.full(x.shape, float(tree[1]))
    if tag == "var":
        return x if tree[1] == "x" else y
    if tag == "pi":
        return np.full(x.shape, np.pi)
    if tag == "neg":
        return -_numeric(tree[1], x, y)
    if tag == "call":
        return _NUMPY[tree[1]](_numeric(tree[2], x, y))
    a, b = _numeric(tree[1], x, y), _numeric(tree[2], x, y)
    if tag == "+":
        return a + b
    if tag == "-":
        return a - b
    if tag == "*":
        return a * b
    if tag == "/":
        return a / b
    return np.power(a, b)


def _exact(tree, x: Fraction, y: Fraction, text: str, max_bits: int) -> Fraction:
    tag = tree[0]
    if tag == "num":
        return tree[1]
    if tag == "var":
        return x if tree[1] == "x" else y
    if tag in ("pi", "call"):
        name = "pi" if tag == "pi" else tree[1]
        raise FormulaError(f"formula {text!r}: {name} has no exact rational value")
    if tag == "neg":
        return -_exact(tree[1], x, y, text, max_bits)
    a = _exact(tree[1], x, y, text, max_bits)
    b = _exact(tree[2], x, y, text, max_bits)
    if tag == "+":
        return a + b
    if tag == "-":
        return a - b
    if tag == "*":
        return a * b
    if tag == "/":
        if b == 0:
            raise FormulaError(f"formula {text!r}: division by zero at (x, y) = ({x}, {y})")
        return a / b
    if b.denominator != 1 or abs(b) > MAX_EXACT_EXPONENT:
        raise FormulaError(
            f"formula {text!r}: exponent {b} is not an integer within +-{MAX_EXACT_EXPONENT}, no exact value"
        )
    if a == 0 and b < 0:
        raise FormulaError(f"formula {text!r}: 0 to a negative power at (x, y) = ({x}, {y})")
    # The size of the power, known before it is computed: powers of powers reach millions of digits.
    bits = (a.numerator.bit_length() + a.denominator.bit_length()) * abs(int(b))
    if bits > max_bits:
        raise FormulaError(f"formula {text!r}: a power at (x, y) = ({x}, {y}) would be an exact value of about "
                           f"{bits:,} bits, more than the limit of {max_bits:,} (max_bits=); no exact value")
    return a ** int(b)


@dataclass(frozen=True)
class Formula:
    """A parsed reference formula ``z = f(x, y)``.

    Attributes
    ----------
    text : str
        The formula as the user wrote it.
    tree : tuple
        The parse tree (nested tuples), the only thing ever evaluated.

    Examples
    --------
    >>> f = parse_formula("z = 0.5*x**2 + y")
    >>> f.exact_value(3, 1)
    Fraction(11, 2)
    >>> f(np.array([1.0, 2.0]), 0.0).tolist()
    [0.5, 2.0]
    """

    text: str
    tree: tuple = field(repr=False)

    @property
    def name(self) -> str:
        """A label for tables: ``f(x, y) = ...``."""
        return f"f(x, y) = {self.text.strip()}"

    def __call__(self, x, y) -> np.ndarray:
        """``f(x, y)`` in floating point; ``x`` and ``y`` broadcast together.

        Overflow and division by zero give ``inf`` or ``nan``, which the caller checks.
        """
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        with np.errstate(all="ignore"):
            return np.asarray(_numeric(self.tree, x, y), dtype=float)

    def evaluate_grid(self, xs, ys) -> np.ndarray:
        """``Z[i, j] = f(xs[i], ys[j])``."""
        xs = np.asarray(xs, dtype=float).ravel()
        ys = np.asarray(ys, dtype=float).ravel()
        return self(xs[:, None], ys[None, :])

    def exact_value(self, x, y, max_bits: int = MAX_EXACT_BITS) -> Fraction:
        """``f(x, y)`` in exact rational arithmetic.

        Raises
        ------
        FormulaError
            If the formula uses a function or ``pi``, a power that is not a
            small integer, or divides by zero at this point, or a power
            would take more than ``max_bits`` bits (checked before it is
            computed).
        """
        try:
            at = as_exact(x, "x"), as_exact(y, "y")
        except InputError as e:
            raise FormulaError(f"{self.text}: {e}") from None
        return _exact(self.tree, *at, self.text, max_bits)


def parse_formula(text: str) -> Formula:
    """Parse ``text`` under the strict grammar of this module.

    Parameters
    ----------
    text : str
        A formula in ``x`` and ``y``, optionally starting with ``z =``.

    Returns
    -------
    Formula

    Raises
    ------
    FormulaError
        Naming the offending text and its column.

    Examples
    --------
    >>> parse_formula("sqrt(x**2 + y**2)")(3.0, 4.0)
    array(5.)
    >>> parse_formula("__import__")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    lagsym.errors.FormulaError: formula '__import__': unknown name '__import__' (allowed: x, y, pi and ...) at column 1
    """
    if not isinstance(text, str):
        raise FormulaError(f"formula {text!r} is not text")
    if len(text) > MAX_LENGTH:
        raise FormulaError(f"formula of {len(text)} characters is longer than the limit of {MAX_LENGTH}")
    if not text.strip():
        raise FormulaError("formula '': empty")
    return Formula(text=text, tree=_Parser(text).formula())
