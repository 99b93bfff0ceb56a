"""What a dry run returns: the moves the control makes, and those moves as CSV.

The moves are kept in a :class:`SimMoves` table of plain arrays, 37 bytes a
move (a block number, a rapid flag and four doubles) rather than an object
each, so the longest run the block limit allows has a memory bound known
before it starts (:data:`BYTES_PER_MOVE` times ``max_blocks``).
"""

from __future__ import annotations

import math
from array import array
from collections.abc import Sequence
from dataclasses import FrozenInstanceError, dataclass

__all__ = ["SimMove", "SimMoves", "Simulation", "moves_csv", "BYTES_PER_MOVE"]

BYTES_PER_MOVE = 37  # array('i') line, array('b') rapid flag, four array('d') columns


@dataclass(frozen=True)
class SimMove:
    """One motion the control would make: ``motion`` is ``G0`` or ``G1``, coordinates in program units."""

    line: int
    motion: str
    x: float
    y: float
    z: float
    feed: float


class SimMoves(Sequence):
    """The moves of a run as columns; indexing and iterating give :class:`SimMove` values.

    Only the executor appends (while the run lasts); the table it hands back
    in a :class:`Simulation` is not changed again.
    """

    __slots__ = ("_line", "_rapid", "_x", "_y", "_z", "_feed", "_sealed")

    def __init__(self):
        self._line, self._rapid = array("i"), array("b")
        self._x, self._y, self._z, self._feed = array("d"), array("d"), array("d"), array("d")
        self._sealed = False

    def seal(self) -> None:
        """End the run: from now on the table is read-only (a :class:`Simulation` seals its moves)."""
        self._sealed = True

    def _check_open(self) -> None:
        if self._sealed:
            raise FrozenInstanceError("the moves of a finished run are read-only")

    def append(self, line: int, rapid: bool, x: float, y: float, z: float, feed: float) -> None:
        """Add one move (the executor's use only)."""
        self._check_open()
        self._line.append(line)
        self._rapid.append(rapid)
        self._x.append(x)
        self._y.append(y)
        self._z.append(z)
        self._feed.append(feed)

    def appenders(self) -> tuple:
        """The ``append`` of each column, in the order of :meth:`append` (the executor's use only)."""
        self._check_open()
        return (self._line.append, self._rapid.append, self._x.append, self._y.append, self._z.append,
                self._feed.append)

    def __len__(self) -> int:
        return len(self._line)

    def _move(self, i: int) -> SimMove:
        return SimMove(self._line[i], "G0" if self._rapid[i] else "G1", self._x[i], self._y[i], self._z[i],
                       self._feed[i])

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self._move(k) for k in range(*i.indices(len(self)))]
        if i < 0:
            i += len(self)
        if not 0 <= i < len(self):
            raise IndexError("move index out of range")
        return self._move(i)

    def __iter__(self):
        return (self._move(i) for i in range(len(self)))

    def __eq__(self, other) -> bool:
        return isinstance(other, SimMoves) and list(self) == list(other)

    __hash__ = None

    def __repr__(self) -> str:
        return f"SimMoves({len(self)} moves)"

    def feeds(self) -> int:
        """How many of the moves are feed (``G1``) moves."""
        return len(self) - sum(self._rapid)

    def feed_points(self):
        """The end points of the feed moves as an (N, 3) float array."""
        import numpy as np

        keep = np.frombuffer(self._rapid, dtype=np.int8) == 0 if len(self) else np.zeros(0, bool)
        cols = [np.frombuffer(c, dtype=float) if len(self) else np.zeros(0) for c in (self._x, self._y, self._z)]
        return np.column_stack(cols)[keep].reshape(-1, 3).copy()

    def to_moves(self, mm_per_unit: float = 1.0, first_z_line: int | None = 1):
        """The moves as the one :class:`lagsym.gcode.Moves` type, in mm, for a reader of any program's moves.

        Parameters
        ----------
        mm_per_unit : float
            Millimetres per program unit (25.4 for a ``G20`` program).
        first_z_line : int or None
            The line from which the program has given a Z (:func:`lagsym.gcode.first_line_with`):
            moves on earlier lines have ``z_known`` False.  None: no move has.

        Examples
        --------
        >>> from lagsym.simulate import simulate
        >>> m = simulate("G0 X1. Y2.\\nG1 Z-1. F100.\\n", "fanuc", 8).moves.to_moves(25.4, first_z_line=2)
        >>> m.points_mm.tolist(), m.rapid.tolist(), m.feed_mm_min.tolist(), m.line.tolist(), m.z_known.tolist()
        ([[25.4, 50.8, 0.0], [25.4, 50.8, -25.4]], [True, False], [0.0, 2540.0], [1, 2], [False, True])
        """
        import numpy as np

        from ..gcode.moves import Moves

        n = len(self)

        def column(c, dtype):
            return np.frombuffer(c, dtype=dtype) if n else np.zeros(0, dtype=dtype)

        line = column(self._line, np.intc).astype(int)
        pts = np.column_stack([column(c, float) for c in (self._x, self._y, self._z)]).reshape(-1, 3)
        return Moves(points_mm=pts * mm_per_unit, start_mm=np.zeros(3), rapid=column(self._rapid, np.int8).astype(bool),
                     feed_mm_min=column(self._feed, float) * mm_per_unit, line=line,
                     z_known=line >= (math.inf if first_z_line is None else first_z_line))


@dataclass(frozen=True)
class Simulation:
    """The result of a dry run: the moves in order, how many blocks were executed, and the text it sent out.

    ``output`` holds the lines a program printed (Fanuc ``DPRNT``, LinuxCNC
    ``(LOG,..)``), each without its line end; ``probes`` counts its probing moves.
    """

    dialect: str
    precision: int
    moves: SimMoves
    blocks: int
    output: tuple[str, ...] = ()
    probes: int = 0

    def __post_init__(self):
        self.moves.seal()

    def feed_points(self):
        """The end points of the feed (``G1``) moves as an (N, 3) float array."""
        return self.moves.feed_points()


def moves_csv(sim: Simulation, decimals: int = 6) -> str:
    """The moves as CSV: ``line,motion,x,y,z,feed``."""
    mv = sim.moves
    row = f"{{}},{{}},{{:.{int(decimals)}f}},{{:.{int(decimals)}f}},{{:.{int(decimals)}f}},{{:g}}".format
    motion = ("G1", "G0")
    rows = ["line,motion,x,y,z,feed"]
    rows += [row(line, motion[rapid], x, y, z, feed)
             for line, rapid, x, y, z, feed in zip(mv._line, mv._rapid, mv._x, mv._y, mv._z, mv._feed)]
    return "\n".join(rows) + "\n"
