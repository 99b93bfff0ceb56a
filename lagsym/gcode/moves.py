"""A reader of point-list G-code: the moves of a program as an array in millimetres.

It understands what point-list programs use, as LinuxCNC's interpreter reads
it: modal ``G00``/``G01`` with ``X Y Z F`` words, ``G20``/``G21`` units,
``G90``/``G91`` absolute and incremental positions, ``(...)`` and ``;``
comments, ``%`` framing lines, ``O`` program numbers and ``N`` block numbers,
and arcs: ``G02``/``G03`` with ``I J K`` centre offsets in the ``G17``,
``G18`` or ``G19`` plane, each read as fine straight moves
(:func:`lagsym.gcode.arcs.arc_points`, within a hundredth of a micrometre of
the arc), all with the arc's line.
Set-up words that do not move the tool (the ``G`` codes of
:data:`~lagsym.gcode.program.PASSED_G`: ``G40 G43 G49 G54..G59 G80 G94`` and
the like; ``S T H D``; the ``M`` codes of
:data:`~lagsym.gcode.program.PLAIN_M`: stops, spindle, tool change, coolant,
end) are passed over.  Anything that would move the tool in another way
(``R``-format arcs, absolute arc centres ``G90.1``, canned cycles, ``G28``,
``G92``, subprogram and macro calls ``M98``/``M97``/``G65``, returns
``M99``, any other ``M`` code, which a machine builder may map to a program;
:func:`~lagsym.gcode.program.unrun_code`), and a move after the program's
end (``M02``/``M30``), which a control never makes, is refused with the line
it is on, so a reader of the result never silently sees a different path.

The tool starts at ``(0, 0, 0)``, as in LinuxCNC's interpreter; a number
without a decimal point is read as a whole number of units (LinuxCNC's
reading, not a Fanuc's least-input-increment one).
"""

from __future__ import annotations

import math

from dataclasses import dataclass

import numpy as np

from .._arrays import freeze_fields
from ..errors import ProgramError
from ..machine import mm_per_program_unit
from .arcs import ARC_SAG_MM, arc_points
from .program import END_M, ascii_program, program_blocks, unrun_code
from .words import WordError, numeric_words, plain_move

__all__ = ["MAX_MOVE_POINTS", "Moves", "parse_moves", "move_points", "tool_changes"]

_IGNORED_LETTERS = set("NSTHDP")


@dataclass(frozen=True)
class Moves:
    """The straight moves of a program, in order.

    Attributes
    ----------
    points_mm : ndarray, shape (N, 3)
        End point of each move (mm); read-only.
    start_mm : ndarray, shape (3,)
        Where the tool was before the first move.
    rapid : ndarray of bool, shape (N,)
        True for ``G00`` moves, False for ``G01`` feed moves.
    feed_mm_min : ndarray, shape (N,)
        Feed rate in force for each move (NaN before any ``F``).
    line : ndarray of int, shape (N,)
        1-based line number of each move in the text.
    z_known : ndarray of bool, shape (N,)
        False until the program has given a Z: before that the height of the
        tool is the machine's, not the program's (the 0 in ``points_mm`` is
        only a placeholder, as in LinuxCNC's interpreter).
    """

    points_mm: np.ndarray
    start_mm: np.ndarray
    rapid: np.ndarray
    feed_mm_min: np.ndarray
    line: np.ndarray
    z_known: np.ndarray | None = None

    def __post_init__(self):
        if self.z_known is None:
            object.__setattr__(self, "z_known", np.ones(len(self.points_mm), dtype=bool))
        freeze_fields(self, ("points_mm", "start_mm", "rapid", "feed_mm_min", "line", "z_known"))

    def __len__(self) -> int:
        return len(self.points_mm)

    @property
    def path_mm(self) -> np.ndarray:
        """Start point followed by every end point: ``(N + 1, 3)``, the polyline the tool tip follows."""
        return np.vstack([self.start_mm[None, :], self.points_mm])

    @property
    def feeds(self) -> np.ndarray:
        """End points of the feed (cutting) moves only."""
        return self.points_mm[~self.rapid]


class _Modal:
    """The modal state a point list sets: units, absolute or incremental, motion, plane, feed."""

    def __init__(self):
        self.factor = 1.0  # mm per program unit
        self.absolute = True
        self.motion = None
        self.plane = 17
        self.feed = float("nan")
        self.ended = 0  # the line of the M02 or M30 that ended the program

    def read(self, words, where: str, line: int) -> dict[str, float]:
        """Apply a block's modal words; its X, Y, Z targets and I, J, K arc offsets (program units)."""
        target = {}
        for letter, value in words:
            v = float(value)
            if letter in "GM":
                why = unrun_code(letter, v)
                if why is not None:
                    raise ProgramError(f"{where}: {letter}{value} {why}, which this reader does not run; "
                                       "only point-list programs (G00/G01, G02/G03 with I J K) can be read")
                if letter == "G":
                    self._g(round(v, 1))
                elif v in END_M and not self.ended:
                    self.ended = line
            elif letter in "XYZIJK":
                if letter in target:
                    raise ProgramError(f"{where}: {letter} given twice")
                target[letter] = v
            elif letter == "R":
                raise ProgramError(f"{where}: an arc by its radius (R{value}) is not read; "
                                   "give its centre with I, J, K")
            elif letter == "F":
                self.feed = v
            elif letter != "O" and letter not in _IGNORED_LETTERS:
                raise ProgramError(f"{where}: word {letter}{value} is not part of a point-list program")
        return target

    def _g(self, g: float) -> None:
        if g in (0, 1, 2, 3):
            self.motion = int(g)
        elif g in (17, 18, 19):
            self.plane = int(g)
        elif g in (20, 21):
            self.factor = mm_per_program_unit("inch" if g == 20 else "mm")
        elif g in (90, 91):
            self.absolute = g == 90


MAX_MOVE_POINTS = 2_000_000  # points of one program's moves, arcs read as pieces: about 550 MB while read


def parse_moves(text: str, source: str = "<program>", max_points: int | None = MAX_MOVE_POINTS) -> Moves:
    """Read the straight moves of a point-list program.

    Parameters
    ----------
    text : str
        The program text (any line ending).
    source : str
        A name for messages (the file name).
    max_points : int or None
        Refuse a program whose moves, each arc read as its pieces, make more
        points than this (``verify --max-moves``), counted before each move's
        points are kept; None: no limit.

    Examples
    --------
    >>> m = parse_moves("%\\nO1000 (DEMO)\\nG21 G90\\nG00 X1. Y2.\\nG01 Z-0.5 F100.\\nX3.\\n%\\n")
    >>> m.points_mm.tolist(), m.rapid.tolist()
    ([[1.0, 2.0, 0.0], [1.0, 2.0, -0.5], [3.0, 2.0, -0.5]], [True, False, False])
    """
    ascii_program(text, source)
    pos = [0.0, 0.0, 0.0]
    start = tuple(pos)
    modal = _Modal()
    pts, rapid, feeds, lines, zk = [], [], [], [], []
    z_seen = False
    for no, raw, block in program_blocks(text):
        where = f"{source}, line {no}"
        ended = modal.ended  # a move on the M30 block itself is made
        plain = plain_move(block)
        if plain is not None:  # most blocks of a point list: no need to go word by word
            if plain[0] is not None:
                modal.motion = int(plain[0])
            if plain[4] is not None:
                modal.feed = float(plain[4])
            target = {letter: float(v) for letter, v in zip("XYZ", plain[1:4]) if v is not None}
        else:
            try:
                words = numeric_words(block)
            except WordError as e:
                raise ProgramError(f"{where}: {e} in {raw.strip()!r}") from None
            target = modal.read(words, where, no)
        if not target:
            continue
        if ended:
            raise ProgramError(f"{where}: a move after the end of the program (M02 or M30 on line {ended}), "
                               "which a control never makes")
        if modal.motion is None:
            raise ProgramError(f"{where}: a coordinate before any G00, G01, G02 or G03")
        if not all(math.isfinite(v) for v in target.values()):
            bad = next(k for k, v in target.items() if not math.isfinite(v))
            raise ProgramError(f"{where}: {bad} beyond any machine's travel (a number of over 300 digits) "
                               f"in {raw.strip()[:60]!r}")
        offset = [target.pop(letter, 0.0) * modal.factor for letter in "IJK"]
        arc = modal.motion in (2, 3)
        if not arc and any(offset):
            raise ProgramError(f"{where}: I, J or K without an arc (G02 or G03)")
        z_seen = z_seen or "Z" in target
        before = tuple(pos)
        for k, letter in enumerate("XYZ"):
            if letter in target:
                v = target[letter] * modal.factor
                pos[k] = v if modal.absolute else pos[k] + v
        ends = arc_points(before, pos, offset, modal.plane, modal.motion == 3, where) if arc else [tuple(pos)]
        _check_count(len(pts) + len(ends), max_points, where)
        for end in ends:
            pts.append(tuple(end))
            rapid.append(modal.motion == 0)
            feeds.append(modal.feed * modal.factor)
            lines.append(no)
            zk.append(z_seen)
    return Moves(
        points_mm=np.array(pts, dtype=float).reshape(-1, 3),
        start_mm=np.array(start, dtype=float),
        rapid=np.array(rapid, dtype=bool),
        feed_mm_min=np.array(feeds, dtype=float),
        line=np.array(lines, dtype=int),
        z_known=np.array(zk, dtype=bool),
    )


def _check_count(count: int, max_points: int | None, where: str) -> None:
    if max_points is not None and count > max_points:
        raise ProgramError(f"{where}: the moves so far make {count:,} points (arcs read as pieces that sag "
                           f"{ARC_SAG_MM:g} mm), more than the limit of {max_points:,}; raise the limit (--max-moves)")


def move_points(text: str, source: str = "<program>") -> tuple[np.ndarray, np.ndarray]:
    """The tool-tip polyline of a program and which of its segments are rapids, for plotting.

    Returns
    -------
    points : ndarray, shape (N, 3)
        Tip positions in mm, from the first one the program states fully (its
        first move with a Z) to the end.
    rapid : ndarray of bool, shape (N - 1,)
        ``rapid[k]`` is True when the move from ``points[k]`` to
        ``points[k + 1]`` is a ``G00``.

    Examples
    --------
    >>> pts, rapid = move_points("G00 X1. Y2.\\nZ5.\\nG01 Z0. F100.\\nX3.\\n")
    >>> pts.tolist(), rapid.tolist()
    ([[1.0, 2.0, 5.0], [1.0, 2.0, 0.0], [3.0, 2.0, 0.0]], [False, False])
    """
    m = parse_moves(text, source)
    known = np.flatnonzero(m.z_known)
    if not len(known):
        return np.zeros((0, 3)), np.zeros(0, dtype=bool)
    first = int(known[0])
    return np.array(m.points_mm[first:]), np.array(m.rapid[first + 1:])


def tool_changes(text: str, source: str = "<program>") -> list[tuple[int, int]]:
    """``(line, tool number)`` of every tool change (``M06``, with the ``T`` of its block or the last one before).

    Examples
    --------
    >>> tool_changes("T1 M06\\nG00 X0 Y0\\nT2\\nM6\\n")
    [(1, 1), (4, 2)]
    """
    ascii_program(text, source)
    out, tool = [], None
    for no, raw, block in program_blocks(text):
        try:
            words = numeric_words(block)
        except WordError as e:
            raise ProgramError(f"{source}, line {no}: {e} in {raw.strip()!r}") from None
        for letter, value in words:
            if letter == "T":
                tool = int(float(value))
        if any(letter == "M" and float(value) == 6 for letter, value in words):
            if tool is None:
                raise ProgramError(f"{source}, line {no}: a tool change (M06) before any T word")
            out.append((no, tool))
    return out
