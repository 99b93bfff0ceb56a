"""What each control reads: characters per block and the variable numbers a program may use.

The macro writers keep within these limits and the simulator raises the
control's alarm past them, so both read them from here.
"""

from __future__ import annotations

__all__ = ["MAX_BLOCK", "VARIABLE_RANGES", "MACRO_VARIABLES"]

MAX_BLOCK = {
    "fanuc": 128,  # characters per block the simulator accepts for a Fanuc
    "linuxcnc": 255,  # LinuxCNC reads at most 255 characters per line (LINELEN)
    "heidenhain": 128,
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
