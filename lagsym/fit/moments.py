"""The exact integer moments of a least-squares fit, modulo many small primes and put together by the CRT.

The normal equations of a fit of degree ``p x q`` need ``M[s][t] = sum_k
W_k U_k**s V_k**t`` (``s <= 2p``, ``t <= 2q``) and ``R[a][b] = sum_k W_k Z_k
U_k**a V_k**b`` (``a <= p``, ``b <= q``) exactly, integers of hundreds of
bits.  Modulo a prime below ``2**16`` every residue is below ``2**16``, so a
product of two is below ``2**32`` and a sum of ``2**20`` of them below
``2**52``: a float64 matrix product computes it exactly, at BLAS speed.  Enough
primes that their product exceeds twice the largest possible ``|M|`` or
``|R|`` give every entry exactly by the Chinese remainder theorem.  Data that
does not fit 64-bit integers is left to the caller (:func:`moments` returns
None).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["moments", "PRIME_LIMIT"]

PRIME_LIMIT = 1 << 16
_CHUNK = 1 << 18  # points a matrix product takes at once (at most 2**20 keeps its sums exact)
_FITS = 1 << 62  # values whose residues numpy takes exactly (int64)


def _primes(count: int) -> list[int]:
    """The ``count`` largest primes below :data:`PRIME_LIMIT`."""
    sieve = np.ones(PRIME_LIMIT, dtype=bool)
    sieve[:2] = False
    for i in range(2, math.isqrt(PRIME_LIMIT) + 1):
        if sieve[i]:
            sieve[i * i::i] = False
    found = np.flatnonzero(sieve)[::-1]
    if count > len(found):
        raise ValueError(f"{count} primes asked below {PRIME_LIMIT}, there are {len(found)}")
    return [int(v) for v in found[:count]]


def _powers_mod(base: np.ndarray, top: int, m: int, first: np.ndarray) -> np.ndarray:
    """``first * base**e mod m`` for ``e = 0..top``, as float64 columns (exact: below ``2**16``)."""
    out = np.empty((len(base), top + 1), order="F")  # a column at a time
    cur = first % m
    out[:, 0] = cur
    for e in range(1, top + 1):
        cur = cur * base % m
        out[:, e] = cur
    return out


def moments(U, V, W, Z, degree: tuple[int, int]):
    """``(M, R)`` as nested lists of Python ints (see the module), or None when a value does not fit 64 bits.

    Examples
    --------
    >>> M, R = moments([0, 1, 2], [1, 1, -1], [1, 1, 1], [3, 4, 5], (1, 1))
    >>> M[1][0], M[2][2], R[1][1]   # sum u, sum u**2 v**2, sum z u v
    (3, 5, -6)
    """
    p, q = degree
    if not len(U):
        return None
    largest = [max(map(abs, a)) for a in (U, V, W, Z)]
    if max(largest) >= _FITS:
        return None
    u, v, w, z = (np.array(a, dtype=np.int64) for a in (U, V, W, Z))
    umax, vmax = max(largest[0], 1), max(largest[1], 1)  # u**0 is 1 even where u is 0
    bound = max(sum(map(abs, W)) * umax ** (2 * p) * vmax ** (2 * q),
                sum(abs(a * b) for a, b in zip(W, Z)) * umax ** p * vmax ** q)
    # Primes below 2**16 are above 2**15: enough of them that their product exceeds 2 * bound.
    primes = _primes(max(1, (2 * bound).bit_length() // 15 + 1))
    mom = np.zeros((len(primes), 2 * p + 1, 2 * q + 1), dtype=np.int64)
    rhs = np.zeros((len(primes), p + 1, q + 1), dtype=np.int64)
    for s in range(0, len(u), _CHUNK):
        uc, vc, wc, zc = (a[s:s + _CHUNK] for a in (u, v, w, z))
        for k, m in enumerate(primes):
            um, vm, wm = uc % m, vc % m, wc % m
            vp = _powers_mod(vm, 2 * q, m, np.ones_like(vm))
            mom[k] = (mom[k] + (_powers_mod(um, 2 * p, m, wm).T @ vp).astype(np.int64)) % m
            wz = _powers_mod(um, p, m, wm * (zc % m) % m)
            rhs[k] = (rhs[k] + (wz.T @ vp[:, :q + 1]).astype(np.int64)) % m
    return _crt(mom, primes), _crt(rhs, primes)


def _crt(residues: np.ndarray, primes: list[int]) -> list[list[int]]:
    """The integers of least magnitude with the given residues modulo each prime (the first axis)."""
    whole = math.prod(primes)
    weights = [(whole // m) * pow(whole // m, -1, m) for m in primes]
    rows, cols = residues.shape[1:]
    out = []
    for i in range(rows):
        row = []
        for j in range(cols):
            x = sum(int(r) * c for r, c in zip(residues[:, i, j], weights)) % whole
            row.append(x - whole if 2 * x > whole else x)
        out.append(row)
    return out
