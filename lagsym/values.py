"""One policy for the numbers and choices that reach lagsym from outside.

Every setting, option and file value passes one of these checks once, where it
enters: an exact number (:func:`as_exact`), a finite float within its range
(:func:`finite`, :func:`positive`), or one of a list of choices
(:func:`choice`).  Each raises :class:`~lagsym.errors.InputError` with a
message that names the value and what it was for.

The exact-number policy: decimal text is the decimal it spells (``"1.06"`` is
53/50), and so is a Python float (``0.1`` is 1/10, the decimal its ``repr``
prints), so a step typed on the command line and the same step passed from
Python mean one number everywhere.
"""

from __future__ import annotations

import functools
import keyword
import math
import re
from collections.abc import Iterable, Mapping
from decimal import Decimal, InvalidOperation
from fractions import Fraction

from .errors import InputError

__all__ = ["FrozenMap", "frozen", "as_exact", "exact_number", "finite", "positive", "in_range", "whole", "choice",
           "NotANumber", "MAX_EXPONENT", "MAX_NAME", "SYMPY_LETTERS", "check_name", "of_type"]

MAX_EXPONENT = 300  # beyond this a coordinate has no use and no float to go with it
_RATIONAL = re.compile(r"^\s*([+-]?\d+)\s*/\s*(\d+)\s*$")
_DECIMAL = re.compile(r"^\s*[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?\s*$")
_PLAIN = re.compile(r"\s*([+-]?)(\d*)(?:\.(\d*))?\s*")  # a decimal without exponent: most numbers of a file
_PLAIN_DIGITS = 100  # the plain path's digits, well within MAX_EXPONENT: longer numbers take the checked path
_TENS = tuple(10**k for k in range(_PLAIN_DIGITS + 1))


class NotANumber(InputError):
    """Text that is not an exact number; the message says why (without saying where: callers add that)."""


QUOTED = 60  # characters of a value a message quotes: a 10,000-character cell is shown by its start


def _quoted(text: str) -> str:
    return repr(text) if len(text) <= QUOTED else f"{text[:QUOTED]!r}... ({len(text) - QUOTED:,} more characters)"


def exact_number(text: str) -> Fraction:
    """Read an exact decimal or rational from text.

    Only ASCII digits count: the text of a file or an option, not a locale's
    numerals.

    Examples
    --------
    >>> exact_number("1.06"), exact_number("-1/3"), exact_number("2e3")
    (Fraction(53, 50), Fraction(-1, 3), Fraction(2000, 1))
    """
    m = _PLAIN.fullmatch(text)
    if m and text.isascii():
        sign, whole, fraction = m.groups()
        digits = whole + (fraction or "")
        if digits and len(digits) <= _PLAIN_DIGITS:
            n = int(digits)
            return Fraction(-n if sign == "-" else n, _TENS[len(fraction or "")])
    m = _RATIONAL.match(text)
    if m and text.isascii():
        num, den = m.groups()
        if len(num) > MAX_EXPONENT or len(den) > MAX_EXPONENT:
            raise NotANumber(f"{_quoted(text)} is too large")
        if int(den) == 0:
            raise NotANumber(f"{_quoted(text)} divides by zero")
        return Fraction(int(num), int(den))
    if not text.isascii() or not _DECIMAL.match(text):
        raise NotANumber(f"{_quoted(text.strip())} is not a number")
    exponent = re.search(r"[eE]([+-]?\d+)", text)
    if exponent and len(exponent.group(1).lstrip("+-0")) > 6:
        raise NotANumber(f"{_quoted(text.strip())} is out of range ({_flow(exponent.group(1).startswith('-'))})")
    d = Decimal(text.strip())
    if len(d.as_tuple().digits) > MAX_EXPONENT or abs(d.adjusted()) > MAX_EXPONENT:
        tiny = d.adjusted() < -MAX_EXPONENT and len(d.as_tuple().digits) <= MAX_EXPONENT
        raise NotANumber(f"{_quoted(text.strip())} is out of range ({_flow(tiny)})")
    return Fraction(d)


def _flow(tiny: bool) -> str:
    return f"too small: below 1e-{MAX_EXPONENT}, give 0 if it is nothing" if tiny else "overflow"


def as_exact(value, where: str) -> Fraction:
    """``value`` as an exact rational; ``where`` names it in the message if it is not a number.

    Examples
    --------
    >>> as_exact(0.1, "step"), as_exact("2/3", "x"), as_exact(3, "n")
    (Fraction(1, 10), Fraction(2, 3), Fraction(3, 1))
    >>> as_exact(float("nan"), "--step")
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: --step = nan is not a finite number
    """
    if isinstance(value, bool):
        raise InputError(f"{where} = {value!r} is not a number")
    if isinstance(value, Fraction):
        return value
    if isinstance(value, int):
        return Fraction(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise InputError(f"{where} = {value!r} is not a finite number")
        return Fraction(repr(value))
    if isinstance(value, str):
        try:
            return exact_number(value)
        except NotANumber as e:
            raise InputError(f"{where}: {e}") from None
    if isinstance(value, Decimal):
        if not value.is_finite():
            raise InputError(f"{where} = {value} is not a finite number")
        return Fraction(value)
    try:
        f = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{where} = {value!r} is not a number") from None
    return as_exact(f, where)


def _subject(what: str, value) -> str:
    """How a message names the value: ``--feed = '0'``, or the value alone where the caller names it."""
    return f"{what} = {value!r}" if what else repr(value)


def finite(value, what: str, *, low: float | None = None, high: float | None = None) -> float:
    """``value`` as a finite float within ``[low, high]`` (either bound optional).

    Examples
    --------
    >>> finite("2.5", "--feed", low=0)
    2.5
    >>> finite(float("inf"), "--gouge-limit")
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: --gouge-limit = inf is not a finite number
    """
    if isinstance(value, bool):
        raise InputError(f"{_subject(what, value)} is not a number")
    if isinstance(value, str) and not value.strip().isascii():
        raise InputError(f"{_subject(what, value)} is not a number (only ASCII digits count)")
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError, InvalidOperation):
        raise InputError(f"{_subject(what, value)} is not a number") from None
    if not math.isfinite(v):
        raise InputError(f"{_subject(what, value)} is not a finite number")
    if low is not None and v < low:
        raise InputError(f"{_subject(what, value)} is below {low:g}")
    if high is not None and v > high:
        raise InputError(f"{_subject(what, value)} is above {high:g}")
    return v


def in_range(value, what: str, low: float, high: float, *, above: bool = False, unit: str = "") -> float:
    """``value`` as a finite float from ``low`` (or, with ``above``, greater than it) to ``high``.

    The message gives the range, so the user sees at once what to type.

    Examples
    --------
    >>> in_range("600", "--feed", 1, 100_000, unit="mm/min")
    600.0
    >>> in_range("1e-308", "--feed", 1, 100_000, unit="mm/min")
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: --feed = '1e-308' is out of range: give a number from 1 to 100000 mm/min
    """
    v = finite(value, what)
    if v < low or (above and v == low) or v > high:
        span = f"above {low:g}, up to {high:g}" if above else f"from {low:g} to {high:g}"
        raise InputError(f"{_subject(what, value)} is out of range: give a number {span}{' ' + unit if unit else ''}")
    return v


def whole(value, what: str, low: int, high: int) -> int:
    """``value`` as a whole number from ``low`` to ``high``; text must be ASCII digits.

    Examples
    --------
    >>> whole("12", "--digits", 1, 1000)
    12
    >>> whole("999999999999999999", "--digits", 1, 1000)
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: --digits = '999999999999999999' is out of range: give a whole number from 1 to 1000
    """
    if isinstance(value, bool):
        raise InputError(f"{_subject(what, value)} is not a whole number")
    if isinstance(value, str):
        text = value.strip()
        if not (text.isascii() and text.lstrip("+-").isdigit()):
            raise InputError(f"{_subject(what, value)} is not a whole number")
        v = int(text) if len(text) <= 30 else (high + 1 if text[0] != "-" else low - 1)
    elif isinstance(value, int):
        v = int(value)
    else:
        raise InputError(f"{_subject(what, value)} is not a whole number")
    if not low <= v <= high:
        raise InputError(f"{_subject(what, value)} is out of range: give a whole number from {low} to {high}")
    return v


def positive(value, what: str, *, allow_zero: bool = False, high: float | None = None) -> float:
    """``value`` as a finite float above zero (or at zero where ``allow_zero``), at most ``high``.

    Examples
    --------
    >>> positive(6, "tool diameter")
    6.0
    >>> positive(-1, "tool diameter")
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: tool diameter -1 must be a positive number
    """
    v = finite(value, what, high=high)
    if not (v > 0 or (allow_zero and v == 0)):
        raise InputError(f"{what + ' ' if what else ''}{value!r} must be {'zero or ' if allow_zero else ''}a positive number")
    return v


def of_type(value, cls: type, what: str, make: str | None = None):
    """``value`` if it is a ``cls``, else an InputError that names it (and says how to ``make`` one, if given)."""
    if not isinstance(value, cls):
        hint = f": make one with {make}" if make else ""
        raise InputError(f"{what} = {value!r:.80} is not a {cls.__name__}{hint}")
    return value


def choice(value, options: Iterable, what: str):
    """Check ``value`` against its list of options; the message names the valid choices.

    Examples
    --------
    >>> choice("ball", ("ball", "flat"), "tool shape")
    'ball'
    >>> choice("cone", ("ball", "flat"), "tool shape")
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: tool shape 'cone' is not one of ball, flat
    """
    options = tuple(options)
    if value not in options:
        raise InputError(f"{what} {value!r} is not one of {', '.join(str(o) for o in options)}")
    return value


MAX_NAME = 64  # characters in a variable's name
# The single letters SymPy's parser reads as its own (E: e, I: the imaginary unit, N, O, Q, S: functions and
# registries); known here so that a one-letter name, which lagsym prints without SymPy, needs no SymPy to check.
# tests/test_hostile_limits.py checks the set against the SymPy installed.
SYMPY_LETTERS = frozenset("EINOQS")


def check_name(name, what: str = "variable") -> str:
    """``name`` if it is a plain ASCII identifier (letters, digits, ``_``; a letter first; no keyword) that SymPy's
    parser reads back as a symbol of that name.

    A variable's name reaches SymPy's parser (``sympify``), the code ``sympy.lambdify``
    writes and the Python text of ``lagsym equation --format python``: a name that is
    not a plain identifier could be read there as code, and one of SymPy's own names
    (``I``, ``E``, ``pi``, ``sin``, ``gamma``) is read back as the constant or function
    it names, so the ``sympy`` format would not read back.  Both are refused here,
    where the value is made.

    >>> check_name("u"), check_name("theta")
    ('u', 'theta')
    >>> check_name("I", "x")
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: x name 'I' is one of SymPy's own names: sympify reads it back as SymPy's I, not as a variable, so the sympy format would not read back; choose another name
    """
    if not isinstance(name, str) or not (0 < len(name) <= MAX_NAME and name.isascii() and name[0].isalpha()
                                         and name.isidentifier() and not keyword.iskeyword(name)):
        shown = repr(name) if not isinstance(name, str) or len(name) <= 80 else repr(name[:80]) + "..."
        raise InputError(f"{what} name {shown} is not a plain identifier (ASCII letters, digits and _, a letter "
                         f"first, at most {MAX_NAME} characters, not a Python keyword)")
    if not _read_back(name):
        raise InputError(f"{what} name {name!r} is one of SymPy's own names: sympify reads it back as SymPy's "
                         f"{name}, not as a variable, so the sympy format would not read back; choose another name")
    return name


@functools.lru_cache(maxsize=256)
def _read_back(name: str) -> bool:
    """Whether ``sympy.sympify(name)`` is the plain symbol ``name`` (a letter is looked up, not parsed)."""
    if len(name) == 1:
        return name not in SYMPY_LETTERS
    import sympy

    try:
        value = sympy.sympify(name)
    except Exception:  # noqa: BLE001 - a name SymPy keeps for a function or a class: its parser fails on its own way
        return False
    return isinstance(value, sympy.Symbol) and value.name == name


class FrozenMap(Mapping):
    """A read-only mapping for the tables a frozen value holds (a job's stock, tools, an operation's options).

    Made from a mapping, whose dicts become frozen maps and lists tuples, all the way down, so the value that
    holds it cannot be changed through it.  Equal to any mapping with the same items; pickles (for worker
    processes) and hashes where its values do.

    Examples
    --------
    >>> m = FrozenMap({"block": [0, 1], "top": 5})
    >>> m["block"], m == {"block": (0, 1), "top": 5}
    ((0, 1), True)
    >>> m["top"] = 6
    Traceback (most recent call last):
    ...
    TypeError: 'FrozenMap' object does not support item assignment
    """

    __slots__ = ("_items",)

    def __init__(self, items=()):
        object.__setattr__(self, "_items", {key: frozen(value) for key, value in dict(items).items()})

    def __setattr__(self, name, value):
        raise AttributeError(f"a {type(self).__name__} is read-only")

    def __getitem__(self, key):
        return self._items[key]

    def __iter__(self):
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def __hash__(self) -> int:
        return hash(frozenset(self._items.items()))

    def __repr__(self) -> str:
        return f"FrozenMap({self._items!r})"

    def __reduce__(self):
        return (FrozenMap, (self._items,))


def frozen(value):
    """``value`` with every dict made a :class:`FrozenMap` and every list or tuple a tuple, all the way down."""
    if isinstance(value, FrozenMap):
        return value
    if isinstance(value, Mapping):
        return FrozenMap(value)
    if type(value) in (list, tuple):  # a named tuple is a value of its own, kept as it is
        return tuple(frozen(v) for v in value)
    return value
