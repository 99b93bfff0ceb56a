"""What a dry run returns: the moves the control makes, and those moves as CSV."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["SimMove", "Simulation", "moves_csv"]


@dataclass(frozen=True)
class SimMove:
    """One motion the control would make: ``motion`` is ``G0`` or ``G1``, coordinates in program units."""

    line: int
    motion: str
    x: float
    y: float
    z: float
    feed: float


@dataclass(frozen=True)
class Simulation:
    """The result of a dry run: the moves in order and how many blocks were executed."""

    dialect: str
    precision: int
    moves: tuple[SimMove, ...]
    blocks: int

    def feed_points(self):
        """The end points of the feed (``G1``) moves as an (N, 3) float array."""
        import numpy as np

        return np.array([(m.x, m.y, m.z) for m in self.moves if m.motion == "G1"], dtype=float).reshape(-1, 3)


def moves_csv(sim: Simulation, decimals: int = 6) -> str:
    """The moves as CSV: ``line,motion,x,y,z,feed``."""
    rows = ["line,motion,x,y,z,feed"]
    for mv in sim.moves:
        rows.append(f"{mv.line},{mv.motion},{mv.x:.{decimals}f},{mv.y:.{decimals}f},{mv.z:.{decimals}f},{mv.feed:g}")
    return "\n".join(rows) + "\n"
