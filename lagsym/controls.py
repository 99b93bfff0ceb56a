"""Controls as values: everything that differs between the machine controls lagsym writes programs for.

A :class:`Control` gathers one control family's number limits, program
framing, macro language and serial-line profile; :data:`CONTROLS` is the one
registry.  Every list of control names (the command line's ``--dialect``
choices, the job file's check, the simulator's parsers, the macro writers'
tables, the documentation's table) is derived from it, so adding a control is
adding one value here, plus its tests and its line in docs/controllers.md.

The figures are the documented ones of the smallest control of each family
lagsym writes for (sources in docs/controllers.md):

- a Fanuc (0i, 16/18/21) reads 8 digits in an axis word (``99999.999`` mm,
  ``9999.9999`` inch), up to 128 characters in a macro statement, ``T`` up to
  4 digits, ``H`` up to 400 (0i-MF), ``G54``-``G59`` and ``G54.1 P1``-``P48``;
  its common variables are ``#100-#199`` and ``#500-#999`` with the full macro
  option, ``#100-#149`` and ``#500-#531`` on the smaller ones (profile ``small``);
- a Haas mill (classic and NGC) reads Fanuc-compatible Custom Macro B with
  five-digit ``O`` numbers, ``G54``-``G59``, ``G110``-``G129`` and ``G154 P1``-``P99``,
  200 tools and length offsets; its general-purpose variables are
  ``#100-#149``, ``#500-#549``, ``#600-#699`` and ``#800-#999`` (``#150-#199`` and
  ``#550-#599`` hold probe data, ``#700-#799`` are the control's own);
- LinuxCNC reads 255 characters a line (LINELEN) and 9 digits here by choice;
- Grbl 1.1 buffers 80 characters a line and has no tool changer or length offsets;
- a Heidenhain TNC reads ``±99999.9999`` and Q parameters ``Q0``-``Q99``, and
  takes its datum from the active preset, not from a G-code work offset.

Examples
--------
>>> control("haas").framing.program_word.format(1000)
'O01000'
>>> [c.name for c in CONTROLS.values() if c.macro is not None]
['fanuc', 'haas', 'linuxcnc', 'heidenhain']
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping

from .errors import InputError
from .values import choice

__all__ = ["Control", "Framing", "MacroLanguage", "Probing", "CONTROLS", "control", "names", "VARIABLE_PROFILES",
           "WORK_OFFSET_WORDS", "work_offset"]

VARIABLE_PROFILES = ("full", "small")
"""The variable profiles of a macro option: the full one, and the smaller one of some Fanuc controls."""

Ranges = tuple[tuple[int, int], ...]


@dataclass(frozen=True)
class Framing:
    """The words around a program's moves.

    Attributes
    ----------
    percent : bool
        ``%`` on the first and last line (ISO tape framing).
    program_word : str or None
        The format of the program number word (``"O{:04d}"``); None where the
        control takes no program number (on LinuxCNC an ``O`` word is a
        subroutine label).
    safe_start : str
        The modal words after the units word at the start (cancel cutter
        compensation, length offset and canned cycles where the control has them).
    end : str
        The program-end word: ``M30`` (rewind) or ``M02``.
    tool_change : str or None
        The tool-change word after ``T``; None where the control has no changer:
        the program then stops (``M00``) for the operator to change the tool.
    comment_chars : int or None
        The longest comment text the control takes, where it is shorter than a block.
    """

    percent: bool
    program_word: str | None
    safe_start: str
    end: str
    tool_change: str | None
    comment_chars: int | None = None

    def comment(self, text: str) -> str:
        """A comment block of ``text`` (already ISO characters), cut to :attr:`comment_chars`."""
        return f"({text[:self.comment_chars] if self.comment_chars else text})"


@dataclass(frozen=True)
class MacroLanguage:
    """How a control's macro language writes and computes.

    Attributes
    ----------
    name : str
        The language: ``fanuc`` (Custom Macro B), ``linuxcnc`` (O-word
        subroutines and named parameters) or ``heidenhain`` (Q parameters, FN
        functions); the macro writer and the simulator's parser of that name are used.
    default_precision : int
        Significant digits of the control's arithmetic assumed when none is given.
    rounds : bool
        The language has ``ROUND[..]``, so positions are rounded on the control.
    fix_toward_zero : bool
        ``FIX`` drops the fraction toward zero and ``FUP`` raises the magnitude
        (Fanuc), rather than rounding down and up (LinuxCNC).
    vacant_zero : bool
        ``#0`` is always vacant and reads as 0.
    counts_digits : bool
        A constant with more digits than the arithmetic keeps is an alarm.
    integer_increments : bool
        An axis word without a decimal point counts least input increments.
    table_base : int or None
        First variable of a roughing macro's clearance tables; None: the
        macro keeps one clearance for the whole block.
    table_tiles : int
        Tiles a side of those tables (1 with no table).
    """

    name: str
    default_precision: int
    rounds: bool
    fix_toward_zero: bool = False
    vacant_zero: bool = False
    counts_digits: bool = False
    integer_increments: bool = False
    table_base: int | None = None
    table_tiles: int = 1


@dataclass(frozen=True)
class Probing:
    """How a control probes with a touch probe and hands the results out.

    Attributes
    ----------
    move : str
        The probing move: ``G31`` (Fanuc, Haas: a skip move) or ``G38.2``
        (LinuxCNC: probe toward the workpiece, an error without contact).
    result_variables : tuple of int
        The variables holding the position where the probe tripped, X, Y, Z
        (#5061-#5063 on a Fanuc 0i/16/18/21, a Haas and LinuxCNC).
    output : str
        How the results leave the control: ``dprnt`` (``POPEN``, ``DPRNT[..]``,
        ``PCLOS`` to the serial port) or ``log`` (LinuxCNC's ``(LOGOPEN,..)``,
        ``(LOG,..)``, ``(LOGCLOSE)`` to a file).
    alarm_variable : int or None
        The variable a program writes to raise an alarm (Fanuc ``#3000``);
        None where the probing move stops the program on its own.
    checks_contact : bool
        The control stops with an error when the probing move ends without contact.
    """

    move: str
    result_variables: tuple[int, int, int]
    output: str
    alarm_variable: int | None = None
    checks_contact: bool = False


_SKIP_PROBING = Probing(move="G31", result_variables=(5061, 5062, 5063), output="dprnt", alarm_variable=3000)


@dataclass(frozen=True)
class Control:
    """One control family: its limits, its program framing, its macro language and its serial-line profile.

    Attributes
    ----------
    name : str
        The name the command line and job files use (``--dialect haas``).
    title : str
        The controls it stands for, for help texts and docs.
    max_block : int
        Characters in one block.
    axis_digits : int
        Digits an axis word may hold, integer and decimal digits together.
    tools, length_offsets : int
        Highest ``T`` and ``H`` number (0: the control has no length offsets).
    work_offsets : str
        A regular expression of the work offset words it reads ('' for none:
        the datum comes from the control's active preset).
    work_offset_text : str
        The same in words, for messages.
    program_numbers : tuple of int
        The lowest and highest program number.
    variables : tuple of (int, int)
        Variable numbers (inclusive ranges) a program may read and write.
    macro_variables : mapping
        Variable ranges a generated macro may take for its own values, by
        profile (``full``, ``small``); empty where the macro uses named parameters.
    framing : Framing
        The words around the moves.
    macro : MacroLanguage or None
        The macro language; None for a control lagsym writes point lists only for.
    point_lists : bool
        lagsym writes point-list programs for it.
    chord_mm : float
        How far inside its arcs the control's chords may lie, in mm (Grbl's
        default ``$12``); 0 where it interpolates arcs exactly.
    dnc_profile : str or None
        The serial-line profile (:data:`lagsym.dnc.PROFILES`) that pairs with it.
    probing : Probing or None
        How it probes and hands out the results; None where lagsym writes no probing program for it.
    """

    name: str
    title: str
    max_block: int
    axis_digits: int
    tools: int
    length_offsets: int
    work_offsets: str
    work_offset_text: str
    program_numbers: tuple[int, int]
    variables: Ranges
    framing: Framing
    macro: MacroLanguage | None = None
    macro_variables: Mapping[str, Ranges] = field(default_factory=dict)
    point_lists: bool = True
    chord_mm: float = 0.0
    dnc_profile: str | None = None
    probing: Probing | None = None

    def __post_init__(self):
        object.__setattr__(self, "macro_variables", MappingProxyType(dict(self.macro_variables)))

    def variable_ranges(self, profile: str = "full") -> Ranges:
        """The variable ranges a generated macro may use on this control's macro option ``profile``."""
        choice(profile, VARIABLE_PROFILES, "variable profile")
        if profile not in self.macro_variables:
            raise InputError(f"a {self.name} macro uses named parameters: it has no variable profile {profile!r}")
        return self.macro_variables[profile]

    def reads_work_offset(self, word: str) -> bool:
        """Whether the control reads the work offset word ``word``."""
        return bool(self.work_offsets) and re.fullmatch(self.work_offsets, word) is not None


_FANUC_FRAMING = Framing(percent=True, program_word="O{:04d}", safe_start="G17 G40 G49 G80 G90 G94", end="M30",
                         tool_change="M06")

CONTROLS: Mapping[str, Control] = MappingProxyType({c.name: c for c in (
    Control(
        name="fanuc", title="Fanuc 0i/16/18/21 and ISO-reading Bridgeport controls",
        max_block=128, axis_digits=8, tools=9999, length_offsets=400,
        work_offsets=r"G5[4-9]|G54\.1 P([1-9]|[1-3]\d|4[0-8])", work_offset_text="G54 to G59 or G54.1 P1 to P48",
        program_numbers=(1, 9999), variables=((1, 33), (100, 199), (500, 999)),
        macro_variables={"full": ((100, 199), (500, 999)), "small": ((100, 149), (500, 531))},
        framing=_FANUC_FRAMING,
        macro=MacroLanguage("fanuc", default_precision=8, rounds=True, fix_toward_zero=True, vacant_zero=True,
                            counts_digits=True, integer_increments=True, table_base=500, table_tiles=8),
        dnc_profile="fanuc", probing=_SKIP_PROBING),
    Control(
        name="haas", title="Haas mills (classic and NGC), Fanuc-compatible Custom Macro B",
        max_block=128, axis_digits=8, tools=200, length_offsets=200,
        work_offsets=r"G5[4-9]|G11\d|G12\d|G154 P([1-9]|[1-9]\d)",
        work_offset_text="G54 to G59, G110 to G129 or G154 P1 to P99",
        program_numbers=(1, 99999), variables=((1, 33), (100, 199), (500, 699), (800, 999)),
        macro_variables={"full": ((100, 149), (500, 549), (600, 699), (800, 999)),
                         "small": ((100, 149), (500, 549), (600, 699), (800, 999))},
        framing=Framing(percent=True, program_word="O{:05d}", safe_start="G17 G40 G49 G80 G90 G94", end="M30",
                        tool_change="M06"),
        macro=MacroLanguage("fanuc", default_precision=8, rounds=True, fix_toward_zero=True, vacant_zero=True,
                            counts_digits=True, integer_increments=True, table_base=800, table_tiles=8),
        dnc_profile="haas", probing=_SKIP_PROBING),
    Control(
        name="linuxcnc", title="LinuxCNC (rs274ngc)",
        max_block=255, axis_digits=9, tools=99999, length_offsets=99999,
        work_offsets=r"G5[4-9]|G59\.[1-3]", work_offset_text="G54 to G59 or G59.1 to G59.3",
        program_numbers=(1, 9999), variables=((1, 5602),),
        framing=Framing(percent=False, program_word=None, safe_start="G17 G40 G49 G80 G90 G94", end="M02",
                        tool_change="M06"),
        macro=MacroLanguage("linuxcnc", default_precision=15, rounds=True, table_base=1000, table_tiles=8),
        probing=Probing(move="G38.2", result_variables=(5061, 5062, 5063), output="log", checks_contact=True)),
    Control(
        name="heidenhain", title="Heidenhain TNC (Q parameters), as on Bridgeport mills",
        max_block=128, axis_digits=9, tools=32767, length_offsets=0,
        work_offsets="", work_offset_text="the active preset",
        program_numbers=(1, 9999), variables=((0, 99),),
        macro_variables={"full": ((0, 99),), "small": ((0, 99),)},
        framing=Framing(percent=False, program_word=None, safe_start="", end="", tool_change=None),
        macro=MacroLanguage("heidenhain", default_precision=8, rounds=False),
        point_lists=False, dnc_profile="heidenhain"),
    Control(
        name="grbl", title="Grbl 1.1",
        max_block=80, axis_digits=8, tools=0, length_offsets=0,
        work_offsets=r"G5[4-9]", work_offset_text="G54 to G59",
        program_numbers=(1, 9999), variables=(),
        framing=Framing(percent=False, program_word=None, safe_start="G17 G90 G94", end="M02", tool_change=None,
                        comment_chars=70),
        chord_mm=0.002),
)})
"""Every control lagsym writes programs for, by name."""

WORK_OFFSET_WORDS = "|".join(f"(?:{c.work_offsets})" for c in CONTROLS.values() if c.work_offsets)
"""A regular expression of every work offset word any registered control reads."""


def work_offset(text, what: str = "work offset", exact: bool = False) -> str:
    """A work offset word written as a block of its own, one some registered control reads, and nothing else.

    The word goes into the program as it is, so anything else (a second
    block, a comment, an M word) is refused; whether the chosen control reads
    it is checked with the program (:meth:`Control.reads_work_offset`).
    Given ``exact``, the text must be the word as written (upper case, no
    spaces around it); else it is read as typed (``g55`` is ``G55``).

    Examples
    --------
    >>> work_offset("g55"), work_offset("G54.1 P12"), work_offset("G154 P20")
    ('G55', 'G54.1 P12', 'G154 P20')
    >>> work_offset("G54 M30")
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: work offset 'G54 M30' is not a work offset word of any control: fanuc G54 to G59 or G54.1 P1 to P48; haas G54 to G59, G110 to G129 or G154 P1 to P99; linuxcnc G54 to G59 or G59.1 to G59.3; grbl G54 to G59
    """
    word = text if exact or not isinstance(text, str) else text.strip().upper()
    if not isinstance(word, str) or re.fullmatch(WORK_OFFSET_WORDS, word) is None:
        known = "; ".join(f"{c.name} {c.work_offset_text}" for c in CONTROLS.values() if c.work_offsets)
        raise InputError(f"{what} {text!r} is not a work offset word of any control: {known}")
    return word


def names(*, point_lists: bool = False, macros: bool = False, probing: bool = False) -> tuple[str, ...]:
    """The names of the registered controls: all, or those lagsym writes point lists, macros or probing programs for.

    Examples
    --------
    >>> names(point_lists=True)
    ('fanuc', 'haas', 'linuxcnc', 'grbl')
    >>> names(probing=True)
    ('fanuc', 'haas', 'linuxcnc')
    """
    return tuple(c.name for c in CONTROLS.values()
                 if (c.point_lists or not point_lists) and (c.macro is not None or not macros)
                 and (c.probing is not None or not probing))


def control(name, what: str = "dialect", options: tuple[str, ...] | None = None) -> Control:
    """The registered :class:`Control` named ``name`` (a Control is returned as it is).

    ``options`` narrows the choice (say, to the controls with a macro
    language); the message names the valid ones.

    Examples
    --------
    >>> control("grbl").chord_mm
    0.002
    >>> control("acme")
    Traceback (most recent call last):
    ...
    lagsym.errors.InputError: dialect 'acme' is not one of fanuc, haas, linuxcnc, heidenhain, grbl
    """
    if isinstance(name, Control):
        name = name.name
    return CONTROLS[choice(name, names() if options is None else options, what)]
