"""Checks of a program against its control's limits: block length, axis digits, tool, offset and variable numbers.

The figures live on the :class:`~lagsym.controls.Control` values
(:data:`lagsym.controls.CONTROLS`); the point-list writers and the macro
writers keep within them through these checks, and the simulator raises the
control's alarm past them.
"""

from __future__ import annotations

import numpy as np

from ..controls import VARIABLE_PROFILES, Control, control
from ..errors import ProgramError
from ..machine import MachineSettings

__all__ = ["VARIABLE_PROFILES", "check_settings", "check_axis", "check_blocks", "variable_ranges", "resolution"]


def resolution(settings: MachineSettings) -> float:
    """One unit of the last decimal written, in program units."""
    return 10.0 ** -settings.digits


def variable_ranges(dialect: str | Control, profile: str = "full") -> tuple[tuple[int, int], ...]:
    """The variable ranges a macro may use on ``dialect``'s control of this ``profile``."""
    if profile not in VARIABLE_PROFILES:
        raise ProgramError(f"variable profile {profile!r} is not one of {', '.join(VARIABLE_PROFILES)}")
    return control(dialect).variable_ranges(profile)


def check_settings(settings: MachineSettings) -> None:
    """Refuse a tool, length offset or work offset number the dialect's control does not have."""
    lim = settings.control
    d = lim.name
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
    elif not lim.reads_work_offset(settings.work_offset):
        raise ProgramError(f"work offset {settings.work_offset} is not one a {d} control has "
                           f"({lim.work_offset_text})")


def check_axis(values, settings: MachineSettings, what: str = "an axis word") -> None:
    """Refuse positions (program units) the control cannot write in its axis words, naming the largest."""
    lim = settings.control
    top = 10.0 ** (lim.axis_digits - settings.digits) - 10.0 ** -settings.digits
    v = np.abs(np.asarray(values, dtype=float))
    if v.size and float(v.max()) > top:
        unit = "mm" if settings.units == "mm" else "inch"
        raise ProgramError(f"{what} reaches {float(v.max()):.{settings.digits}f} {unit}, beyond the "
                           f"{top:.{settings.digits}f} a {settings.dialect} control reads with "
                           f"{settings.digits} decimals ({lim.axis_digits} digits)")


def check_blocks(lines, dialect: str | Control) -> None:
    """Refuse a block longer than the control reads, naming the block and the limit."""
    c = control(dialect)
    lim, dialect = c.max_block, c.name
    for n, line in enumerate(lines, start=1):
        if len(line) > lim:
            raise ProgramError(f"block {n} ({line[:30]!r}...) has {len(line)} characters, more than the {lim} "
                               f"a {dialect} control reads")
