"""Feed moves with arcs: straight moves between the arcs of :class:`~lagsym.toolpath.arcs.Arcs`, arcs as ``G02``/``G03``.

An arc is written in centre format, ``G18 G03 X.. Z.. I.. K..`` (``G19``
with ``Y``, ``Z``, ``J``, ``K``): the end point in both axes of the plane
and the centre as its offset from the start, all in units of the program's
last decimal, as the fitter rounded them.  No ``R`` word: a radius leaves the
centre to the control, and LinuxCNC and Grbl both check a centre against the
start and end.  The plane is stated on the first arc and ``G17`` comes back
after the last feed move, so a program's set-up plane holds for whatever
follows.  Fanuc, LinuxCNC and Grbl 1.1 all read ``G18``/``G19`` arcs with
``I J K`` offsets from the start.
"""

from __future__ import annotations

import numpy as np

from ..gcode.numbers import fixed, program_ints
from ..machine import MachineSettings
from .moves import format_moves

__all__ = ["feed_blocks"]

_AXES = {"G18": ("X", "I", 0), "G19": ("Y", "J", 1)}


def _word(letter: str, k: int, digits: int) -> str:
    sign = "-" if k < 0 else ""
    q, r = divmod(abs(int(k)), 10 ** digits)
    return f"{letter}{sign}{q}.{r:0{digits}d}" if digits else f"{letter}{sign}{q}."


def feed_blocks(p: np.ndarray, arcs, s: MachineSettings) -> list[str]:
    """The blocks of the feed moves from ``p[0]`` through ``p[1:]``, the runs ``arcs`` names as arcs.

    The first block carries the cutting feed.  Without arcs, the straight
    moves of :func:`~lagsym.post.moves.format_moves`.
    """
    feed = s.feed_mm_min
    if arcs is None or not len(arcs):
        rest = format_moves(p[1:], s, previous=p[0], first_feed=feed, motion="") if len(p) > 1 else []
        return [ln.lstrip() for ln in rest]
    d = s.digits
    ints = program_ints(p, s.unit_factor, d)
    centre = np.rint(np.asarray(arcs.centre_mm) * (s.unit_factor * 10 ** d)).astype(np.int64)
    along, offset, ax = _AXES[arcs.plane]
    out, pos, motion, plane = [], 0, "", arcs.plane + " "
    for a, b, c, ccw in zip(arcs.start, arcs.end, centre, arcs.ccw):
        if a > pos:
            out += [ln.strip() for ln in format_moves(p[pos + 1:a + 1], s, previous=p[pos],
                                                      first_feed=feed, motion=motion)]
            feed = None
        words = [f"{plane}G0{3 if ccw else 2}", _word(along, ints[b, ax], d), _word("Z", ints[b, 2], d),
                 _word(offset, c[0] - ints[a, ax], d), _word("K", c[1] - ints[a, 2], d)]
        if feed is not None:
            words.append("F" + fixed(float(feed) * s.unit_factor, 1 if s.units == "mm" else 2))
            feed = None
        out.append(" ".join(words))
        pos, motion, plane = int(b), "G01", ""
    if pos < len(p) - 1:
        out += [ln.strip() for ln in format_moves(p[pos + 1:], s, previous=p[pos], first_feed=feed, motion=motion)]
    out.append("G17")
    return [ln for ln in out if ln]
