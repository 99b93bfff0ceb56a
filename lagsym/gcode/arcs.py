"""Circular moves (``G02``/``G03`` in the ``G17``, ``G18`` or ``G19`` plane) as fine straight pieces.

As LinuxCNC's interpreter reads them: the centre is given as ``I J K``
offsets from the start (the default incremental arc distance mode), ``G02``
turns clockwise and ``G03`` counter-clockwise seen from the positive end of
the plane's normal (+Z for ``G17``, +Y for ``G18``, +X for ``G19``), so in
``G18`` a positive turn takes Z towards X.  When the start and end lie at
different distances from the centre the radius changes evenly with the angle
(a spiral, as LinuxCNC and Grbl move); the axis off the plane moves evenly
too (a helix).  An end on the start is a full circle.

:func:`arc_points` splits the move into pieces whose chords stay within
:data:`ARC_SAG_MM` of the arc, far below any simulation's resolution (the
verifier's cells are tenths of a millimetre, a program's last decimal a
micrometre).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ProgramError

__all__ = ["PLANES", "arc_points", "ARC_SAG_MM", "MAX_PIECES"]

ARC_SAG_MM = 1e-5
MAX_PIECES = 200_000  # pieces of one arc at most (a full circle of 4 m radius)
# Plane: the first and second axis (a positive turn takes the first towards the second) and the normal.
PLANES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}


def arc_points(start, end, offset, plane: int, ccw: bool, where: str = "<program>") -> np.ndarray:
    """The points (mm) ending the straight pieces of an arc from ``start`` to ``end``, ``end`` last.

    Parameters
    ----------
    start, end : sequence of float
        X, Y, Z (mm).
    offset : sequence of float
        The centre's offset from the start, ``(I, J, K)`` (mm).
    plane : int
        17, 18 or 19.
    ccw : bool
        True for ``G03``.

    Examples
    --------
    >>> p = arc_points((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (-1.0, 0.0, 0.0), 17, True)
    >>> len(p) > 100, bool(np.allclose(np.hypot(p[:, 0], p[:, 1]), 1.0)), p[-1].tolist()
    (True, True, [0.0, 1.0, 0.0])
    """
    a, b, n = PLANES[plane]
    s, e, o = (np.asarray(v, dtype=float) for v in (start, end, offset))
    c = s + o
    c[n] = 0.0
    u0, v0 = s[a] - c[a], s[b] - c[b]
    u1, v1 = e[a] - c[a], e[b] - c[b]
    r0, r1 = math.hypot(u0, v0), math.hypot(u1, v1)
    if not all(math.isfinite(v) for v in (*s, *e, *c, r0, r1)):
        raise ProgramError(f"{where}: an arc beyond any machine's travel (centre {c[a]:g}, {c[b]:g})")
    if r0 == 0.0 or r1 == 0.0:
        raise ProgramError(f"{where}: an arc whose centre is on its start or end")
    t0, t1 = math.atan2(v0, u0), math.atan2(v1, u1)
    sweep = (t1 - t0) % (2 * math.pi) if ccw else -((t0 - t1) % (2 * math.pi))
    if abs(sweep) < 1e-12 and math.hypot(u1 - u0, v1 - v0) < 1e-9:
        sweep = 2 * math.pi if ccw else -2 * math.pi  # end on the start: a full circle
    r = max(r0, r1)
    # The angle of a chord that sags ARC_SAG_MM, 2 acos(1 - sag/r), written so that it stays above 0 for any
    # radius: 1 - sag/r rounds to 1 above r = 1e11 mm, and the arc would need 1/0 pieces.
    per = 4.0 * math.asin(math.sqrt(ARC_SAG_MM / (2.0 * r))) if r > ARC_SAG_MM else math.pi / 2
    pieces = max(1, int(math.ceil(abs(sweep) / per)))
    if pieces > MAX_PIECES:
        raise ProgramError(f"{where}: an arc of radius {r:g} mm turning {abs(sweep):g} rad would take {pieces} "
                           f"pieces, more than {MAX_PIECES}")
    t = np.arange(1, pieces + 1) / pieces
    ang, rad = t0 + sweep * t, r0 + (r1 - r0) * t
    out = np.empty((pieces, 3))
    out[:, a] = c[a] + rad * np.cos(ang)
    out[:, b] = c[b] + rad * np.sin(ang)
    out[:, n] = s[n] + (e[n] - s[n]) * t
    out[-1] = e
    return out
