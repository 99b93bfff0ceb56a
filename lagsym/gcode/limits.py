"""What each control reads: characters per block, digits of an axis word, tool and offset numbers, variables.

The point-list writers and the macro writers keep within these limits and the
simulator raises the control's alarm past them, so all read them from here.
:data:`LIMITS` gathers one row a dialect; the figures are the documented ones
of the smallest control lagsym writes a dialect for (docs/controllers.md):

- a Fanuc reads 8 digits in an axis word (``99999.999`` mm, ``9999.9999``
  inch), a block of up to 128 characters in a macro statement, ``T`` up to
  4 digits, ``H`` up to 400 (0i-MF), ``G54``-``G59`` and ``G54.1 P1``-``P48``;
  its common variables are ``#100-#199`` and ``#500-#999`` with the full macro
  option, ``#100-#149`` and ``#500-#531`` on the smaller ones (profile ``small``);
- LinuxCNC reads 255 characters a line (LINELEN) and 9 digits here by choice;
- Grbl 1.1 buffers 80 characters a line and has no tool length offsets;
- a Heidenhain TNC reads ``±99999.9999`` and Q parameters ``Q0``-``Q99``, and
  takes its datum from the active preset, not from a G-code work offset.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from ..errors import ProgramError
from ..machine import MachineSettings

__all__ = ["MAX_BLOCK", "VARIABLE_RANGES", "MACRO_VARIABLES", "ControlLimits", "LIMITS", "VARIABLE_PROFILES",
           "limits", "check_settings", "check_axis", "check_blocks", "variable_ranges", "resolution"]

MAX_BLOCK = {
    "fanuc": 128,  # characters per block the simulator accepts for a Fanuc
    "linuxcnc": 255,  # LinuxCNC reads at most 255 characters per line (LINELEN)
    "heidenhain": 128,
    "grbl": 80,  # Grbl 1.1's line buffer
}
"""Characters per block (one line) each dialect's control reads."""

VARIABLE_RANGES = {
    "fanuc": ((1, 33), (100, 199), (500, 999)),  # local, common, common kept at power-off
    "linuxcnc": ((1, 5602),),
    "heidenhain": ((0, 99),),
}
"""Variable numbers (inclusive ranges) a program may read and write on each control."""

MACRO_VARIABLES = {
    "fanuc": ((100, 199), (500, 999)),  # common variables: the locals #1-#33 belong to a macro call
    "heidenhain": ((0, 99),),
}
"""Variable numbers a generated macro may take for its own values (LinuxCNC's use named parameters)."""


@dataclass(frozen=True)
class ControlLimits:
    """The limits of one dialect's control.

    Attributes
    ----------
    max_block : int
        Characters in one block.
    axis_digits : int
        Digits an axis word may hold, integer and decimal digits together.
    tools, length_offsets : int
        Highest ``T`` and ``H`` number (0: the control has no length offsets).
    work_offsets : str
        A regular expression of the work offset words it reads ('' for none).
    variables : dict
        Variable ranges by profile name (``full``, ``small``), for macros.
    """

    max_block: int
    axis_digits: int
    tools: int
    length_offsets: int
    work_offsets: str
    variables: dict


LIMITS: dict[str, ControlLimits] = {
    "fanuc": ControlLimits(MAX_BLOCK["fanuc"], 8, 9999, 400, r"G5[4-9]|G54\.1 P([1-9]|[1-3]\d|4[0-8])",
                           {"full": MACRO_VARIABLES["fanuc"], "small": ((100, 149), (500, 531))}),
    "linuxcnc": ControlLimits(MAX_BLOCK["linuxcnc"], 9, 99999, 99999, r"G5[4-9]|G59\.[1-3]", {}),
    "grbl": ControlLimits(80, 8, 0, 0, r"G5[4-9]", {}),
    "heidenhain": ControlLimits(MAX_BLOCK["heidenhain"], 9, 32767, 0, "",
                                {"full": MACRO_VARIABLES["heidenhain"], "small": MACRO_VARIABLES["heidenhain"]}),
}
VARIABLE_PROFILES = ("full", "small")


def limits(dialect: str) -> ControlLimits:
    """The row of :data:`LIMITS` for ``dialect``."""
    return LIMITS[dialect]


def resolution(settings: MachineSettings) -> float:
    """One unit of the last decimal written, in program units."""
    return 10.0 ** -settings.digits


def variable_ranges(dialect: str, profile: str = "full") -> tuple[tuple[int, int], ...]:
    """The variable ranges a macro may use on ``dialect``'s control of this ``profile``."""
    if profile not in VARIABLE_PROFILES:
        raise ProgramError(f"variable profile {profile!r} is not one of {', '.join(VARIABLE_PROFILES)}")
    return limits(dialect).variables[profile]


def check_settings(settings: MachineSettings) -> None:
    """Refuse a tool, length offset or work offset number the dialect's control does not have."""
    lim, d = limits(settings.dialect), settings.dialect
    if lim.tools and settings.tool_number > lim.tools:
        raise ProgramError(f"tool number {settings.tool_number} is above {lim.tools}, the highest a {d} control reads")
    if settings.length_offset is not None and not lim.length_offsets:
        raise ProgramError(f"a {d} program has no tool length offset: leave out the length offset number")
    if lim.length_offsets and settings.length_offset_number > lim.length_offsets:
        raise ProgramError(f"length offset H{settings.length_offset_number} is above H{lim.length_offsets}, "
                           f"the highest a {d} control has")
    if not lim.work_offsets:
        if settings.work_offset != "G54":
            raise ProgramError(f"a {d} program takes its datum from the active preset: set it on the control, "
                               f"not with work offset {settings.work_offset}")
    elif not re.fullmatch(lim.work_offsets, settings.work_offset):
        raise ProgramError(f"work offset {settings.work_offset} is not one a {d} control has "
                           f"({lim.work_offsets.replace(chr(92), '')})")


def check_axis(values, settings: MachineSettings, what: str = "an axis word") -> None:
    """Refuse positions (program units) the control cannot write in its axis words, naming the largest."""
    lim = limits(settings.dialect)
    top = 10.0 ** (lim.axis_digits - settings.digits) - 10.0 ** -settings.digits
    v = np.abs(np.asarray(values, dtype=float))
    if v.size and float(v.max()) > top:
        unit = "mm" if settings.units == "mm" else "inch"
        raise ProgramError(f"{what} reaches {float(v.max()):.{settings.digits}f} {unit}, beyond the "
                           f"{top:.{settings.digits}f} a {settings.dialect} control reads with "
                           f"{settings.digits} decimals ({lim.axis_digits} digits)")


def check_blocks(lines, dialect: str) -> None:
    """Refuse a block longer than the control reads, naming the block and the limit."""
    lim = limits(dialect).max_block
    for n, line in enumerate(lines, start=1):
        if len(line) > lim:
            raise ProgramError(f"block {n} ({line[:30]!r}...) has {len(line)} characters, more than the {lim} "
                               f"a {dialect} control reads")
