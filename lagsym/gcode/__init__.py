"""Word-address G-code read back: the one word tokenizer, and the moves of a point-list program.

:mod:`lagsym.gcode.words` splits blocks into words for every reader in
lagsym; :mod:`lagsym.gcode.moves` reads the straight moves of a point-list
program on top of it; :mod:`lagsym.gcode.program` reads a whole program
block by block (the lines a control reads, its units, what in it is a macro);
:mod:`lagsym.gcode.limits` holds what each control reads (block length,
variable numbers).
"""

from __future__ import annotations

from .moves import Moves, move_points, parse_moves, tool_changes
from .program import MACRO_USES, first_line_with, is_macro, macro_uses, program_blocks, program_units
from .words import FUNCTIONS, WordError, numeric_words, strip_comments, words

__all__ = ["Moves", "parse_moves", "move_points", "tool_changes", "WordError", "FUNCTIONS", "strip_comments",
           "numeric_words", "words", "MACRO_USES", "program_blocks", "program_units", "macro_uses", "is_macro",
           "first_line_with"]
