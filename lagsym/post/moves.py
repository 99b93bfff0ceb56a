"""Linear feed moves as blocks: coordinates rounded once to integers of the last decimal, modal words left out.

X, Y, Z and F are modal on every control lagsym writes for, so a block holds
only the words that change.  Z is rounded up, so rounding never puts the tool
below a cutter location.
"""

from __future__ import annotations

import numpy as np

from ..machine import MachineSettings
from ..gcode.numbers import fixed, program_ints

__all__ = ["format_moves"]


def _words(letter: str, ints: np.ndarray, digits: int, changed: np.ndarray) -> list[str]:
    """``letter`` + fixed-point text for each entry, '' where the value did not change."""
    out = [""] * len(ints)
    scale = 10 ** digits
    for i in np.flatnonzero(changed):
        k = int(ints[i])
        sign = "-" if k < 0 else ""
        q, r = divmod(abs(k), scale)
        out[i] = f"{letter}{sign}{q}.{r:0{digits}d}" if digits else f"{letter}{sign}{q}."
    return out


def _quantize(points_mm, settings: MachineSettings) -> np.ndarray:
    """Points in units of the program's last decimal (:func:`~lagsym.gcode.numbers.program_ints`)."""
    return program_ints(points_mm, settings.unit_factor, settings.digits)


def format_moves(points_mm: np.ndarray, settings: MachineSettings, previous=None, first_feed: float | None = None,
                 motion: str = "G01") -> list[str]:
    """Blocks of linear feed moves through ``points_mm``, modal words left out.

    Parameters
    ----------
    points_mm : ndarray, shape (N, 3)
    settings : MachineSettings
    previous : sequence of float, optional
        The position (mm) before the first move, to leave out unchanged words.
    first_feed : float, optional
        Feed (mm/min) written on the first block.
    motion : str
        The motion word written on the first block.

    Examples
    --------
    >>> format_moves(np.array([[1.0, 2.0, -0.0008], [1.5, 2.0, 0.0012]]), MachineSettings(), first_feed=600)
    ['G01 X1.000 Y2.000 Z0.000 F600.0', 'X1.500 Z0.002']
    """
    d = settings.digits
    ints = _quantize(points_mm, settings)
    prev = (np.full(3, np.iinfo(np.int64).min) if previous is None
            else _quantize(np.asarray(previous, dtype=float)[None, :], settings)[0])
    before = np.vstack([prev[None, :], ints[:-1]])
    changed = ints != before
    changed[0] = changed[0] | (previous is None)
    cols = [_words(letter, ints[:, k], d, changed[:, k]) for k, letter in enumerate("XYZ")]
    lines = [" ".join(w for w in ws if w) for ws in zip(*cols)]
    if lines:
        head = [motion]
        if lines[0]:
            head.append(lines[0])
        if first_feed is not None:
            head.append("F" + fixed(float(first_feed) * settings.unit_factor, 1 if settings.units == "mm" else 2))
        lines[0] = " ".join(head)
    # A move to the same rounded point is no move: a control may refuse an empty block.
    return [ln for ln in lines if ln]
