"""A dry run of a macro program on the PC, with the control's arithmetic and the control's alarms.

:func:`simulate` executes the dialects lagsym writes -- Fanuc Custom Macro B,
LinuxCNC O-words, Heidenhain FN/Q parameters -- in decimal arithmetic of a
chosen number of significant digits (8 for a Fanuc 16/18-class control, 15
for IEEE double), rounding after every operation and on reading every
constant.  It returns the moves the control would make, or raises
:class:`ControlAlarm` where the control would stop:

* unbalanced ``WHILE .. DOm`` / ``ENDm`` or ``o.. while`` / ``o.. endwhile``, ``DO`` beyond 3 levels;
* ``[ ]`` nested deeper than 5 (Fanuc alarm 118);
* a constant with more digits than the control reads (Fanuc alarm 003);
* a constant on an axis word without a decimal point (a Fanuc reads ``X12`` as
  0.012 mm; lagsym refuses it rather than guess);
* a variable outside the range the dialect allows;
* a block longer than the control reads; division by zero, the square root of
  a negative number, a jump to a missing sequence number or label;
* a runaway loop (:mod:`~lagsym.simulate.runaway`): back at a block with
  nothing changed, too many blocks without a move, or too many blocks in all.

A probing move (Fanuc/Haas ``G31``, LinuxCNC ``G38.2``) runs against a
surface given as ``target`` (:mod:`~lagsym.simulate.probing`): it stops
where the probe's ball tip touches, sets ``#5061``-``#5063``, and what the
program prints (``POPEN``/``DPRNT``/``PCLOS``, LinuxCNC's
``(LOGOPEN,..)``/``(LOG,..)``/``(LOGCLOSE)``) is the run's ``output``.
Without a target a probing move is refused, as every code it does not run.

The simulator covers what lagsym emits plus the common core of each language
(``IF [..] GOTO n``, ``IF [..] THEN``, ``GOTO``, the functions every Macro B
control has); it is not a full interpreter of any control.

The steps, one module each: :mod:`~lagsym.simulate.reader` turns the text
into typed :mod:`~lagsym.simulate.blocks` with one parser per dialect
(:mod:`~lagsym.simulate.fanuc`, :mod:`~lagsym.simulate.linuxcnc`,
:mod:`~lagsym.simulate.heidenhain`) and the expressions of
:mod:`~lagsym.simulate.expressions` (trees, and closures over the control);
:mod:`~lagsym.simulate.compiler` turns each straight run of blocks into one
Python function, read once; :mod:`~lagsym.simulate.executor` links the loops
and runs those functions on the arithmetic and variables of
:mod:`~lagsym.simulate.control`;
:mod:`~lagsym.simulate.runaway` stops a program that would never end;
:mod:`~lagsym.simulate.result` holds what comes back.
"""

from __future__ import annotations

from .alarms import ControlAlarm
from .executor import MAX_DO, simulate
from .expressions import MAX_BRACKETS
from .reader import SIM_DIALECTS, detect_dialect
from .result import BYTES_PER_MOVE, SimMove, SimMoves, Simulation, moves_csv
from .runaway import MAX_BLOCKS, MAX_IDLE_BLOCKS, MAX_PROGRAM_LINES

__all__ = ["ControlAlarm", "SimMove", "SimMoves", "Simulation", "simulate", "detect_dialect", "moves_csv",
           "SIM_DIALECTS", "MAX_BRACKETS", "MAX_DO",
           "MAX_BLOCKS", "MAX_IDLE_BLOCKS", "MAX_PROGRAM_LINES", "BYTES_PER_MOVE"]
