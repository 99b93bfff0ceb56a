"""Program text every control reads: comments in ISO characters, and the header that says the surface's units."""

from __future__ import annotations

import re
import unicodedata

from ..machine import MachineSettings

__all__ = ["iso_comment", "surface_comment", "COOLANT_ON"]

# The characters every control lagsym writes for reads in a comment: a Fanuc 0 alarms (TH) on a comma.
_NOT_ISO = re.compile(r"[^A-Z0-9 .+\-/]")

COOLANT_ON = {"off": "", "flood": "M08", "mist": "M07"}
"""The coolant word of each ``MachineSettings.coolant``; ``M09`` turns either off."""


def iso_comment(text: str) -> str:
    """Comment text a control accepts: upper-case letters, digits, space and ``. + - /``; no parentheses.

    Examples
    --------
    >>> iso_comment("Paper example 4 (5x5), scale 1:20 – Ø6 ball")
    'PAPER EXAMPLE 4 5X5 SCALE 1 20 - 6 BALL'
    >>> iso_comment("pièce façonnée")  # an accent is dropped, its letter kept
    'PIECE FACONNEE'
    """
    t = unicodedata.normalize("NFKD", text)
    t = "".join(c for c in t if not unicodedata.combining(c))
    t = t.upper().replace("\u2013", "-").replace("\u2014", "-")
    t = _NOT_ISO.sub(" ", t)
    return re.sub(r"\s+", " ", t).strip()


def surface_comment(settings: MachineSettings) -> str:
    """The header comment saying which units the surface was in and how it was scaled (ISO characters)."""
    return iso_comment(f"surface in {settings.surface_units} {settings.mm_per_unit:g} mm per unit "
                       f"program in {settings.units}")
