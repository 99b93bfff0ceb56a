"""The Lagrange basis itself, in the barycentric form, and the Lebesgue constant it gives.

    L_j(t) = (w_j / (t - t_j)) / sum_k (w_k / (t - t_k)),

kept for what needs the basis values (pictures of the basis, conditioning);
the surfaces themselves are evaluated in the Chebyshev basis.
"""

from __future__ import annotations

import numpy as np

__all__ = ["normalize", "barycentric_weights", "basis_matrix", "lebesgue_constant"]


def normalize(nodes: np.ndarray, t) -> tuple[np.ndarray, np.ndarray]:
    """Map ``nodes`` and ``t`` affinely so that the nodes span ``[-1, 1]``."""
    nodes = np.asarray(nodes, dtype=float)
    a, b = nodes.min(), nodes.max()
    mid, half = (a + b) / 2.0, (b - a) / 2.0
    return (nodes - mid) / half, (np.asarray(t, dtype=float) - mid) / half


def barycentric_weights(nodes) -> np.ndarray:
    """Barycentric weights ``w_j = 1 / prod_{k != j} (t_j - t_k)`` for nodes on [-1, 1], rescaled to max |w| = 1."""
    s = np.asarray(nodes, dtype=float)
    diff = s[:, None] - s[None, :]
    np.fill_diagonal(diff, 1.0)
    # Sum logs instead of multiplying so high degree cannot underflow.
    sign = np.prod(np.sign(diff), axis=1)
    logw = -np.sum(np.log(np.abs(diff)), axis=1)
    return sign * np.exp(logw - logw.max())


def basis_matrix(nodes, t) -> np.ndarray:
    """Values of every Lagrange basis polynomial on ``nodes`` at the points ``t``.

    Returns an array of shape ``t.shape + (len(nodes),)``; entry ``[..., j]``
    is ``L_j(t)``.  At a node the row is exactly one-hot.

    Examples
    --------
    >>> basis_matrix([0.0, 1.0, 2.0], [0.5, 2.0]).round(6).tolist()
    [[0.375, 0.75, -0.125], [0.0, 0.0, 1.0]]
    """
    s, u = normalize(nodes, t)
    w = barycentric_weights(s)
    shape = u.shape
    u = u.reshape(-1, 1)
    d = u - s[None, :]
    exact = d == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        q = w / d
        out = q / q.sum(axis=1, keepdims=True)
    hit = exact.any(axis=1)
    if hit.any():
        out[hit] = exact[hit].astype(float)
    return out.reshape(shape + (len(s),))


def lebesgue_constant(nodes, samples: int = 4001) -> float:
    """The Lebesgue constant ``max_t sum_j |L_j(t)|`` of ``nodes`` over their span.

    It bounds how much the interpolant can amplify an error in the data: 1 for
    two nodes, growing like ``2**n / (e n log n)`` for equally spaced nodes.

    Examples
    --------
    >>> round(lebesgue_constant([0.0, 1.0]), 6)
    1.0
    """
    s = np.asarray(nodes, dtype=float)
    t = np.linspace(s.min(), s.max(), samples)
    lam = np.abs(basis_matrix(s, t)).sum(axis=1)
    # Refine around the worst sample: the maximum lies between two samples.
    k = int(lam.argmax())
    lo, hi = t[max(k - 1, 0)], t[min(k + 1, len(t) - 1)]
    fine = np.linspace(lo, hi, 201)
    return float(max(lam.max(), np.abs(basis_matrix(s, fine)).sum(axis=1).max()))
