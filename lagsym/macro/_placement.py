"""Where the surface sits in a macro program: surface units to program units, exactly.

A surface point ``(x, y, z)`` is programmed at ``(x * scale + ox, y * scale + oy,
z * scale + oz)``, with ``scale`` the machine's millimetres per surface unit
and the origin its work offset, both turned into program units (millimetres,
or inches for ``G20``).  The raster, the row form and the points computed on
the PC all read the placement here, so they cannot disagree.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from ..machine import MachineSettings, program_units_per_mm
from ..values import as_exact

__all__ = ["ProgramPlacement", "placement"]


@dataclass(frozen=True)
class ProgramPlacement:
    """The machine's :class:`~lagsym.machine.Placement` in program units, exact, with the stock to leave.

    Attributes
    ----------
    per_mm : Fraction
        Program units per millimetre (1, or exactly 5/127 for inches).
    scale : Fraction
        Program units per surface unit.
    origin : tuple of Fraction
        The work offset (X, Y, Z) in program units.
    stock : Fraction
        The stock to leave, in program units.
    """

    per_mm: Fraction
    scale: Fraction
    origin: tuple[Fraction, Fraction, Fraction]
    stock: Fraction


def placement(settings: MachineSettings) -> ProgramPlacement:
    """The placement ``settings`` describe.

    Examples
    --------
    >>> p = placement(MachineSettings(mm_per_unit=2.5, origin_mm=(1.0, 0.0, -0.1)))
    >>> p.scale, p.origin[2]
    (Fraction(5, 2), Fraction(-1, 10))
    """
    per_mm = program_units_per_mm(settings.units)
    scale, origin = settings.placement.exact(settings.units)
    return ProgramPlacement(per_mm=per_mm, scale=scale, origin=origin,
                            stock=as_exact(settings.stock_to_leave_mm, "stock to leave") * per_mm)
