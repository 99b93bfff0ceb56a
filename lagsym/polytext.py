"""The exact polynomial as text, printed as SymPy prints it, straight from its rational coefficients.

``lagsym equation`` and ``lagsym curve`` print a polynomial whose coefficients
are exact fractions; importing SymPy to print it takes most of a second, far
longer than computing it.  These functions write the same characters SymPy's
printers write for the same expression (``str(expr)``, ``sympy.latex(expr)``,
``str`` of the nested form), from the coefficients and without SymPy:

- the terms in SymPy's order: lexicographic in the variables sorted by name,
  highest first, with SymPy's one exception, ``a - b*x`` (a positive number
  and one negative two-factor term) printed number first;
- a term as ``29*x**4*y**3/720`` (str) or ``\\frac{29 x^{4} y^{3}}{720}`` (LaTeX);
- the nested (Horner) form built by the rules SymPy evaluates ``form*x + c``
  with: a number times a symbol is a term, a sum times a symbol stays a
  product ``x*(...)``, sums flatten.

Only variables named by one ASCII letter are written here (:func:`supported`);
any other name (``alpha`` is ``\\alpha`` in LaTeX) goes through SymPy.  Each
function is checked against SymPy's own printing on every example and on random
coefficients (tests/test_polytext.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

__all__ = ["supported", "plain_text", "latex_text", "nested_text", "latex_decimal_text", "fraction_text"]

Monomial = tuple[int, ...]


def supported(names) -> bool:
    """True if every variable is a distinct single ASCII letter, the names this module prints."""
    names = tuple(names)
    return all(isinstance(n, str) and len(n) == 1 and n.isascii() and n.isalpha() for n in names) and \
        len(set(names)) == len(names)


def _ordered(coeffs: dict[Monomial, Fraction], names: tuple[str, ...]) -> list[tuple[Monomial, Fraction]]:
    """The nonzero terms in the order SymPy prints a sum of them."""
    order = sorted(range(len(names)), key=lambda v: names[v])
    terms = sorted(((k, c) for k, c in coeffs.items() if c), key=lambda t: tuple(t[0][v] for v in order),
                   reverse=True)
    if len(terms) == 2:
        (k0, c0), (k1, c1) = terms
        # SymPy writes Add(number, Mul(number, one factor)) as 'a - b*x' when a > 0 > b.
        if not any(k1) and c1 > 0 and c0 < 0 and sum(1 for p in k0 if p) == 1:
            terms.reverse()
    return terms


def _factors(key: Monomial, names: tuple[str, ...]) -> list[tuple[str, int]]:
    return sorted(((names[v], p) for v, p in enumerate(key) if p), key=lambda t: t[0])


def _digits(n: int) -> str:
    """``str(n)`` for an integer of any length: Python's own conversion stops at 4,300 digits (an exact fit of
    many points has longer coefficients); python-flint's does not."""
    if n.bit_length() < 14_000:
        return str(n)
    import flint

    return str(flint.fmpz(n))


def fraction_text(c: Fraction) -> str:
    """``str(c)`` for a fraction of any length.

    Examples
    --------
    >>> fraction_text(Fraction(-3, 4)), fraction_text(Fraction(5))
    ('-3/4', '5')
    """
    return _digits(c.numerator) if c.denominator == 1 else f"{_digits(c.numerator)}/{_digits(c.denominator)}"


def _plain_term(key: Monomial, c: Fraction, names: tuple[str, ...]) -> str:
    """One term without its sign, as ``str`` writes it."""
    c = abs(c)
    num = [_digits(c.numerator)] if c.numerator != 1 or not any(key) else []
    num += [n if p == 1 else f"{n}**{p}" for n, p in _factors(key, names)]
    text = "*".join(num)
    return text if c.denominator == 1 else f"{text}/{_digits(c.denominator)}"


def _join(parts: list[tuple[bool, str]], sep_minus: str = " - ", first_minus: str = "-") -> str:
    if not parts:
        return "0"
    out = [(first_minus if parts[0][0] else "") + parts[0][1]]
    out += [(sep_minus if neg else " + ") + text for neg, text in parts[1:]]
    return "".join(out)


def plain_text(coeffs: dict[Monomial, Fraction], names: tuple[str, ...]) -> str:
    """``str(expr)`` of the polynomial ``sum coeffs[k] * prod names[v]**k[v]``.

    Examples
    --------
    >>> from fractions import Fraction as F
    >>> plain_text({(2, 0): F(1), (0, 1): F(3), (1, 1): F(-29, 720)}, ("x", "y"))
    'x**2 - 29*x*y/720 + 3*y'
    >>> plain_text({(0,): F(8), (1,): F(-2)}, ("x",))
    '8 - 2*x'
    """
    return _join([(c < 0, _plain_term(k, c, names)) for k, c in _ordered(coeffs, names)])


def _latex_term(key: Monomial, c: Fraction, names: tuple[str, ...]) -> str:
    c = abs(c)
    mono = " ".join(n if p == 1 else f"{n}^{{{p}}}" for n, p in _factors(key, names))
    num = " ".join(t for t in (_digits(c.numerator) if c.numerator != 1 or not mono else "", mono) if t)
    return num if c.denominator == 1 else f"\\frac{{{num}}}{{{_digits(c.denominator)}}}"


def latex_text(coeffs: dict[Monomial, Fraction], names: tuple[str, ...]) -> str:
    """``sympy.latex(expr)`` of the polynomial.

    Examples
    --------
    >>> from fractions import Fraction as F
    >>> latex_text({(4, 4): F(-1, 2880), (2, 0): F(1), (0, 1): F(3)}, ("x", "y"))
    '- \\\\frac{x^{4} y^{4}}{2880} + x^{2} + 3 y'
    """
    terms = _ordered(coeffs, names)
    parts = [(c < 0, _latex_term(k, c, names)) for k, c in terms]
    if len(parts) == 1 and not any(terms[0][0]) and terms[0][1].denominator == 1:
        return str(terms[0][1])  # an integer alone is printed as Python prints it: -5
    return _join(parts, first_minus="- ")


# The nested form: a small model of the SymPy expressions that Horner's scheme builds.


@dataclass(frozen=True)
class _Term:
    """``coeff * prod(var**power) * (sum)``: a SymPy Mul (or number, or symbol) with at most one sum factor."""

    coeff: Fraction
    powers: tuple[tuple[str, int], ...] = ()
    sum: tuple[_Term, ...] | None = None

    def times(self, name: str) -> _Term:
        powers = dict(self.powers)
        powers[name] = powers.get(name, 0) + 1
        return _Term(self.coeff, tuple(sorted(powers.items())), self.sum)


def _times(form: tuple[_Term, ...], name: str) -> tuple[_Term, ...]:
    """``form * name`` as SymPy evaluates it: a sum times a symbol stays a product, a term gains a power."""
    if not form:
        return ()
    if len(form) == 1:
        return (form[0].times(name),)
    return (_Term(Fraction(1), ((name, 1),), form),)


def _plus(form: tuple[_Term, ...], c: tuple[_Term, ...]) -> tuple[_Term, ...]:
    """``form + c``, flattened and with like terms collected, as SymPy's Add does."""
    out: dict[tuple, Fraction] = {}
    for t in form + c:
        key = (t.powers, t.sum)
        out[key] = out.get(key, Fraction(0)) + t.coeff
    return tuple(_Term(v, *k) for k, v in out.items() if v)


def _number(c: Fraction) -> tuple[_Term, ...]:
    return (_Term(Fraction(c)),) if c else ()


def _horner1(coeffs: list[Fraction], name: str) -> tuple[_Term, ...]:
    """``sympy.horner`` of a polynomial in one variable, ``coeffs[a]`` multiplying ``name**a``."""
    while coeffs and not coeffs[-1]:
        coeffs = coeffs[:-1]
    form: tuple[_Term, ...] = ()
    for c in reversed(coeffs):
        form = _plus(_times(form, name), _number(c))
    return form


def _key(t: _Term, names: tuple[str, ...]) -> tuple:
    # SymPy orders a sum by the powers of its generators: the symbols by name, then any sum factors.
    powers = dict(t.powers)
    return tuple(powers.get(n, 0) for n in sorted(names)) + (1 if t.sum is not None else 0,)


def _str_sum(form: tuple[_Term, ...], names: tuple[str, ...]) -> str:
    terms = sorted(form, key=lambda t: _key(t, names), reverse=True)
    if len(terms) == 2:
        t0, t1 = terms
        if not t1.powers and t1.sum is None and t1.coeff > 0 and t0.coeff < 0 and \
                len(t0.powers) + (t0.sum is not None) == 1:
            terms.reverse()
    return _join([(t.coeff < 0, _str_term(t, names)) for t in terms])


def _str_term(t: _Term, names: tuple[str, ...]) -> str:
    c = abs(t.coeff)
    num = [_digits(c.numerator)] if c.numerator != 1 or not (t.powers or t.sum) else []
    num += [n if p == 1 else f"{n}**{p}" for n, p in t.powers]
    if t.sum is not None:
        num.append(f"({_str_sum(t.sum, names)})")
    text = "*".join(num)
    return text if c.denominator == 1 else f"{text}/{_digits(c.denominator)}"


def nested_text(coefficients, names: tuple[str, ...]) -> str:
    """``str`` of the nested (Horner) form: Horner in x whose coefficients are Horner in y.

    ``coefficients`` is a sequence of rows for a surface (``coefficients[a][b]``
    multiplies ``x**a * y**b``), or a flat sequence for a curve.

    Examples
    --------
    >>> from fractions import Fraction as F
    >>> nested_text([F(-5), F(8), F(-2)], ("x",))
    'x*(8 - 2*x) - 5'
    >>> nested_text([[F(0), F(3)], [F(0)], [F(1)]], ("x", "y"))
    'x**2 + 3*y'
    """
    if len(names) == 1:
        return _str_sum(_horner1(list(coefficients), names[0]), names)
    sx, sy = names
    form: tuple[_Term, ...] = ()
    for row in reversed(coefficients):
        form = _plus(_times(form, sx), _horner1(list(row), sy))
    return _str_sum(form, names)


def _latex_number(text: str) -> str:
    """``sympy.latex(sympify(text))`` of a decimal literal without a sign, as SymPy reads and prints it.

    SymPy reads a literal without ``.`` or ``e`` as an Integer and any other as a
    Float of ``max(15, digits)`` decimal digits (an integer written with ``e`` counts
    all its digits), which it prints through mpmath: the same calls here.
    """
    if "." not in text and "e" not in text:
        return text
    from decimal import Decimal

    from mpmath.libmp import dps_to_prec, from_str, prec_to_dps, round_nearest, to_str

    dec = Decimal(text)
    dps = len(dec.as_tuple().digits)
    if "." not in text and dec.as_tuple().exponent >= 0:
        dps = max(dps, len(str(int(dec))))
    prec = dps_to_prec(max(15, dps))
    out = to_str(from_str(text, prec, round_nearest), prec_to_dps(prec), strip_zeros=True)
    if "e" in out:
        mant, exp = out.split("e")
        return f"{mant} \\cdot 10^{{{exp.lstrip('+')}}}"
    return out


def latex_decimal_text(coeffs: dict[Monomial, tuple[bool, str]], names: tuple[str, ...]) -> str:
    """``sympy.latex(sympy.sympify(text))`` of a polynomial printed with decimal coefficients.

    ``coeffs[k]`` is ``(negative, magnitude)``, the magnitude as the text writes it
    (``"6.5"``, ``"8.333e-10"``, ``"1"``).

    Examples
    --------
    >>> latex_decimal_text({(3,): (False, "0.8333"), (1,): (True, "6.5"), (0,): (True, "9")}, ("x",))
    '0.8333 x^{3} - 6.5 x - 9'
    """
    signed = {k: Fraction(-1 if neg else 1) for k, (neg, _) in coeffs.items()}
    terms = _ordered(signed, names)
    parts = []
    for key, sign in terms:
        mag = coeffs[key][1]
        mono = " ".join(n if p == 1 else f"{n}^{{{p}}}" for n, p in _factors(key, names))
        if not any(key):
            parts.append((sign < 0, _latex_number(mag)))
        else:
            parts.append((sign < 0, mono if mag == "1" else f"{_latex_number(mag)} {mono}"))
    if len(parts) == 1 and not any(terms[0][0]):
        return ("-" if parts[0][0] else "") + parts[0][1]  # a number alone keeps its sign without a space
    return _join(parts, first_minus="- ")
