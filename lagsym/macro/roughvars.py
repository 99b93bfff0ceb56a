"""The numbered variables a roughing macro takes, checked against the control's variable profile.

A roughing macro (:mod:`.roughing`) numbers its loops' variables from a
base, as a finishing macro does, and keeps its clearance tables at the
language's ``table_base``: on a Fanuc ``#100``-``#149`` and ``#500``-``#627``
for Example 4, 178 variables, which a small Fanuc (``#100``-``#149``,
``#500``-``#531``) cannot hold.  :func:`check_rough_variables` refuses such a
program with the figures, as :func:`lagsym.macro.macro_program` does a
finishing macro.
"""

from __future__ import annotations

from ..controls import control, names
from ..errors import ProgramError
from ..values import choice
from .model import SetItem, variables as variables_of

__all__ = ["rough_macro_variables", "check_rough_variables"]


def rough_macro_variables(rm, dialect: str, variable_base: int | None = None) -> tuple[tuple[int, int], ...]:
    """The numbered variables a roughing macro takes on ``dialect``'s control: its loops', then its tables' ranges.

    The loops' variables are numbered from ``variable_base`` (a Fanuc's and
    a Haas's default ``#100``, a Heidenhain's ``Q1``); the clearance tables
    sit at the language's ``table_base`` (Fanuc ``#500``, Haas ``#800``,
    LinuxCNC ``#1000``), two tables of tiles x tiles entries.  A LinuxCNC
    macro's loops use named parameters, so only its tables are numbered.

    Examples
    --------
    >>> from lagsym.grid import grid_from_points
    >>> from lagsym.lagrange import lagrange_surface
    >>> from lagsym.machine import MachineSettings, Tool
    >>> from lagsym.macro.roughing import rough_macro
    >>> from lagsym.toolpath.rough import RoughSpec, Stock
    >>> s = lagrange_surface(grid_from_points([(0, 0, 1), (0, 4, 1), (4, 0, 1), (4, 4, 1)]))
    >>> rm = rough_macro(s, Tool("flat", 2.0), Stock(0, 4, 0, 4, 4.0), RoughSpec(1.5, 1.5, 1.0, 0.5),
    ...                  MachineSettings(dialect="fanuc"), precision=8)
    >>> rough_macro_variables(rm, "fanuc")
    ((100, 134), (500, 627))
    """
    from . import fanuc, heidenhain

    c = control(dialect, "macro dialect", names(macros=True))
    out = []
    if c.macro.name != "linuxcnc":
        default = heidenhain.DEFAULT_BASE if c.macro.name == "heidenhain" else fanuc.DEFAULT_BASE
        base = default if variable_base is None else int(variable_base)
        count = len(variables_of(rm.loops.body)) + (heidenhain.SCRATCH if c.macro.name == "heidenhain" else 0)
        out.append((base, base + count - 1))
    table = sorted(s.number for s in rm.loops.body if isinstance(s, SetItem))
    if table:
        out.append((table[0], table[-1]))
    return tuple(out)


def check_rough_variables(rm, dialect: str, variables: str = "full",
                          variable_base: int | None = None) -> None:
    """Refuse a roughing macro whose variables do not fit the control's ``variables`` profile, with the figures.

    As :func:`lagsym.macro.macro_program` refuses a finishing macro: the
    loops' variables and the clearance tables (:func:`rough_macro_variables`)
    must each lie within one range the profile allows
    (:meth:`lagsym.controls.Control.variable_ranges`; LinuxCNC's numbered
    parameters, :attr:`~lagsym.controls.Control.variables`), and apart.

    Raises
    ------
    ProgramError
        Naming the variables needed, how many, and the ranges the profile has.
    """
    from ..gcode.limits import VARIABLE_PROFILES

    c = control(dialect, "macro dialect", names(macros=True))
    choice(variables, VARIABLE_PROFILES, "variable profile")
    need = rough_macro_variables(rm, c.name, variable_base)
    letter = "Q" if c.macro.name == "heidenhain" else "#"
    if c.macro_variables:
        allowed, where = c.variable_ranges(variables), f"the {variables} variable profile of a {c.name} control"
    elif variables != "full":
        raise ProgramError(f"variables {variables!r}: a {c.name} macro uses named parameters and numbered ones "
                           f"only for its tables; it has no {variables} profile")
    else:
        allowed, where = c.variables, f"a {c.name} control"
    text = " and ".join(f"{letter}{lo}-{letter}{hi}" for lo, hi in need)
    total = sum(hi - lo + 1 for lo, hi in need)
    ranges = ", ".join(f"{letter}{lo}-{letter}{hi}" for lo, hi in allowed)
    for lo, hi in need:
        if not any(a <= lo and hi <= b for a, b in allowed):
            raise ProgramError(f"the roughing macro needs {text} ({total} variables); {letter}{lo}-{letter}{hi} "
                               f"is outside {where} ({ranges}): use a control with more variables, or rough "
                               "with a point list (no macro)")
    if len(need) == 2 and need[0][0] <= need[1][1] and need[1][0] <= need[0][1]:
        raise ProgramError(f"the roughing macro needs {text}: its loops' variables overlap its clearance tables; "
                           "choose another variable base")
