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

from ..machine import MachineSettings
from ..values import as_exact

__all__ = ["Placement", "placement"]


@dataclass(frozen=True)
class Placement:
    """The surface's placement in program units, exact.

    Attributes
    ----------
    per_mm : Fraction
        Program units per millimetre (1, or 1/25.4 as the float prints it).
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


def placement(settings: MachineSettings) -> Placement:
    """The placement ``settings`` describe.

    Examples
    --------
    >>> p = placement(MachineSettings(scale=2.5, origin_mm=(1.0, 0.0, -0.1)))
    >>> p.scale, p.origin[2]
    (Fraction(5, 2), Fraction(-1, 10))
    """
    per_mm = as_exact(settings.unit_factor, "program units per mm")
    origin = tuple(as_exact(v, "origin") * per_mm for v in settings.origin_mm)
    return Placement(per_mm=per_mm, scale=as_exact(settings.scale, "scale") * per_mm, origin=origin,
                     stock=as_exact(settings.stock_to_leave_mm, "stock to leave") * per_mm)
