"""Resuming a drip feed part way: the modal set-up a control needs to pick up a program at a block.

:func:`resume_setup` reads the blocks before a resume point and writes the
modal set-up a control needs to pick up the program there: units, plane,
distance mode, work offset, tool, tool length offset, spindle, coolant, a
retract to a safe Z and the approach to where the program was.  Blocks are
numbered as :mod:`lagsym.dnc.blocks` says.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from decimal import Decimal, InvalidOperation

from ..errors import InputError
from ..gcode.program import macro_uses
from ..gcode.words import numeric_words
from .blocks import Program

__all__ = ["resume_setup", "find_block", "first_resumable_block"]


@dataclass
class _Modal:
    units: str | None = None
    plane: str | None = None
    distance: str | None = None
    offset: str | None = None
    motion: str | None = None
    tool: str | None = None
    tool_changed: bool = False
    length_comp: str | None = None
    spindle: str | None = None
    speed: str | None = None
    coolant: str | None = None
    feed: str | None = None
    feed_mode: str | None = None
    css: str | None = None
    plunge_feed: str | None = None
    position: dict = field(default_factory=lambda: {"X": None, "Y": None, "Z": None})
    rapid_z: Decimal | None = None
    cycle: str | None = None
    cutter_comp: str | None = None
    transforms: set = field(default_factory=set)


def _words(block: str) -> list[tuple[str, str]]:
    return numeric_words(block, strict=False)  # macro blocks are refused before modal tracking


def _number(text: str) -> Decimal:
    return Decimal(text)


_TRANSFORMS = {"68": "G68 rotation", "51": "G51 scaling", "51.1": "G51.1 mirror image", "16": "G16 polar coordinates"}
_TRANSFORM_ENDS = {"69": "68", "50": "51", "50.1": "51.1", "15": "16"}


def _track(state: _Modal, block: str, where: str) -> None:
    """Update ``state`` with one block, as a control would.

    Long because it is one table of the modal groups a control keeps, read in the order the control reads them.
    """
    words = _words(block)
    gs = [_g(v) for k, v in words if k == "G"]
    ms = [v for k, v in words if k == "M"]
    homing = False
    for code in gs:
        if code in ("20", "21"):
            state.units = "G" + code
        elif code in ("17", "18", "19"):
            state.plane = "G" + code
        elif code in ("90", "91"):
            state.distance = "G" + code
        elif code in ("54", "55", "56", "57", "58", "59", "54.1"):
            state.offset = "G" + code
        elif code in ("0", "1", "2", "3"):
            state.motion = "G" + code
            state.cycle = None  # a motion code cancels a canned cycle
        elif code in ("43", "44"):
            h = next((v for k, v in words if k == "H"), None)
            state.length_comp = f"G{code}" + (f" H{h}" if h else "")
        elif code == "49":
            state.length_comp = None
        elif code in ("41", "42"):
            state.cutter_comp = "G" + code
        elif code == "40":
            state.cutter_comp = None
        elif code == "80":
            state.cycle = None
        elif len(code) == 2 and code.startswith("8"):
            state.cycle = "G" + code
        elif code in ("28", "30", "53"):
            homing = True
        elif code in ("93", "94", "95"):
            state.feed_mode = "G" + code
        elif code in ("96", "97"):
            state.css = "G" + code
        elif code in ("52", "92"):
            raise InputError(f"{where}: G{code} shifts the coordinate system in a way a resume cannot replay; "
                             "send the program from the start")
        elif code in _TRANSFORMS:
            state.transforms.add(code)
        elif code in _TRANSFORM_ENDS:
            state.transforms.discard(_TRANSFORM_ENDS[code])
    if state.offset == "G54.1":
        p = next((v for k, v in words if k == "P"), None)
        if p:
            state.offset = f"G54.1 P{p}"
    for m in ms:
        code = str(int(Decimal(m)))
        if code in ("3", "4", "5"):
            state.spindle = "M" + code
        elif code == "6":
            state.tool_changed = True
        elif code in ("7", "8", "9"):
            state.coolant = None if code == "9" else "M" + code
    for k, v in words:
        if k == "T":
            state.tool = v
        elif k == "S":
            state.speed = v
        elif k == "F":
            state.feed = v
    moves = {k: _number(v) for k, v in words if k in "XYZ"}
    old_z = state.position["Z"]
    if state.motion == "G1" and set(moves) == {"Z"} and not homing:
        new_z = moves["Z"] + (old_z or 0) if state.distance == "G91" else moves["Z"]
        if old_z is not None and new_z < old_z:
            state.plunge_feed = state.feed  # the feed the program plunges at, which the set-up's feed-down uses
    if homing:
        # G28/G30 go to a reference point and G53 moves in machine coordinates: the work position of
        # the named axes (all of them when none is named) is unknown until the program sets it again.
        for axis in moves or "XYZ":
            state.position[axis] = None
        return
    for axis, value in moves.items():
        if state.distance == "G91":
            old = state.position[axis]
            state.position[axis] = None if old is None else old + value
        else:
            state.position[axis] = value
    if state.cycle is not None and moves:
        state.position["Z"] = None  # a drilling cycle ends at its R or initial level
    elif state.motion == "G0" and "Z" in moves and state.position["Z"] is not None:
        z = state.position["Z"]
        state.rapid_z = z if state.rapid_z is None else max(state.rapid_z, z)


def _g(text: str) -> str:
    d = Decimal(text)
    return str(int(d)) if d == int(d) else str(d.normalize())


def _fmt(value: Decimal) -> str:
    text = format(value.normalize() if value != 0 else Decimal(0), "f")
    return text if "." in text else text + "."


def first_resumable_block(program: Program, within: int = 500) -> int:
    """The first block a resume can start at: the first :func:`resume_setup` accepts.

    Before it the program has not yet stated its units, the tool's X, Y and
    Z, a safe height and a feed, and a resume cannot approach the part; a
    fault earlier than that asks for the program from the start.  Looked for
    among the first ``within`` blocks; one more than the program's last block
    when none there will do.

    Examples
    --------
    >>> from lagsym.dnc import parse_program
    >>> first_resumable_block(parse_program("O1\\nG21 G90\\nG0 X0 Y0\\nG0 Z5.\\nG1 Z-1. F100.\\nX10."))
    6
    """
    for number in range(2, min(len(program), within) + 1):
        try:
            resume_setup(program, number)
        except InputError:
            continue
        return number
    return len(program) + 1


def resume_setup(program: Program, start_block: int, safe_z: str | None = None) -> tuple[str, ...]:
    """The blocks that put a control in the state block ``start_block`` expects.

    Long because each state a resume cannot trust is its own check with its own message, in the order a
    reader of the set-up would ask.

    The blocks before ``start_block`` are read for the modal state they leave:
    units, plane, distance mode, work offset, tool and tool length offset,
    spindle speed and direction, coolant, feed and motion mode, and the
    position, the feed mode (G93/G94/G95) and constant surface speed
    (G96/G97).  The set-up selects all of them, retracts to a safe Z, moves
    over the last position and feeds down to it at the feed the program
    last plunged at (then restores the cutting feed), so block
    ``start_block`` starts where it would have started in an uninterrupted
    run.

    Parameters
    ----------
    program : Program
        The whole program.
    start_block : int
        The block to resume at, 1-based (see :mod:`lagsym.dnc.blocks`).
    safe_z : str, optional
        Retract height in program units; by default the highest Z a rapid
        move reached before ``start_block``.

    Raises
    ------
    InputError
        If ``start_block`` is outside the program; if the program before it
        uses macro variables, jumps, subprogram calls, G52 or G92; if a
        canned cycle, cutter compensation, rotation, scaling, mirror image or
        polar coordinates is still on at ``start_block``; or if the position,
        the units, the feed or the safe Z is unknown.  A set-up could then not
        be trusted.

    Examples
    --------
    >>> from lagsym.dnc import parse_program
    >>> p = parse_program("O1\\nG21 G17 G90 G54\\nT1 M6\\nS3000 M3\\nG0 Z50.\\nG0 X0 Y0\\nG1 Z-1. F200.\\nX10.\\nX20.")
    >>> resume_setup(p, 9)
    ('(RESUME AT BLOCK 9)', 'G21 G17 G90 G54', 'T1 M6', 'S3000 M3', 'G0 Z50.', 'G0 X10. Y0.', 'G1 Z-1. F200.')
    """
    total = len(program)
    if not 2 <= start_block <= total:
        raise InputError(f"--start-block {start_block} is outside the program "
                         f"({program.source} has blocks 1 to {total}; "
                         "block 1 starts from the beginning)")
    state = _Modal()
    for number in range(1, start_block):
        block = program.block(number)
        where = f"{program.source}: block {number}"
        if macro_uses(block):
            raise InputError(f"{where} uses macro variables, jumps or subprogram calls; a resume cannot know the "
                             "state they leave, so send the program from the start")
        try:
            _track(state, block, where)
        except InvalidOperation:
            raise InputError(f"{where}: {block!r} holds a number lagsym cannot read") from None
    if state.units is None:
        raise InputError(f"{program.source}: no G20 or G21 before block {start_block}; the set-up cannot choose units")
    active = [v for v in (state.cycle and f"canned cycle {state.cycle}",
                          state.cutter_comp and f"cutter compensation {state.cutter_comp}") if v]
    active += sorted(_TRANSFORMS[t] for t in state.transforms)
    if active:
        raise InputError(f"{program.source}: {' and '.join(active)} is still on at block {start_block}; "
                         "a resume cannot re-enter it safely, so pick a block where it is off")
    pos = state.position
    if any(pos[a] is None for a in "XYZ"):
        missing = ", ".join(a for a in "XYZ" if pos[a] is None)
        raise InputError(f"{program.source}: the {missing} position before block {start_block} is unknown; "
                         "a resume cannot approach it safely")
    if safe_z is not None:
        try:
            z_safe = Decimal(safe_z)
        except InvalidOperation:
            raise InputError(f"--safe-z {safe_z!r} is not a number") from None
    elif state.rapid_z is not None:
        z_safe = state.rapid_z
    else:
        raise InputError(f"{program.source}: no rapid Z move before block {start_block} to take a safe height from; "
                         "give --safe-z")
    if z_safe < pos["Z"]:
        raise InputError(f"safe Z {_fmt(z_safe)} is below the resume height Z{_fmt(pos['Z'])}; give a higher --safe-z")
    if state.feed is None:
        raise InputError(f"{program.source}: no feed (F word) before block {start_block}; the set-up could not "
                         "feed down to the resume point")
    modal = " ".join(v for v in (state.units, state.plane or "G17", "G90", state.offset, state.feed_mode) if v)
    out = [f"(RESUME AT BLOCK {start_block})", modal]
    if state.tool is not None:
        out.append(f"T{state.tool} M6" if state.tool_changed else f"T{state.tool}")
    if state.speed is not None or state.spindle is not None:
        out.append(" ".join(v for v in (state.css, f"S{state.speed}" if state.speed else None, state.spindle) if v))
    retract = f"G0 Z{_fmt(z_safe)}"
    if state.length_comp:
        retract = f"G0 {state.length_comp} Z{_fmt(z_safe)}"
    out.append(retract)
    out.append(f"G0 X{_fmt(pos['X'])} Y{_fmt(pos['Y'])}")
    if state.coolant:
        out.append(state.coolant)
    plunge = state.plunge_feed or state.feed
    out.append(f"G1 Z{_fmt(pos['Z'])} F{plunge}")
    restore = [m for m in (state.motion if state.motion not in (None, "G1") else None,
                           "G91" if state.distance == "G91" else None,
                           f"F{state.feed}" if plunge != state.feed else None) if m]
    if restore:
        out.append(" ".join(restore))
    return tuple(out)


_N_WORD = re.compile(r"^\s*N\s*0*(\d+)\b")


def find_block(program: Program, spec: str) -> int:
    """The block number of what the control shows: an N number (``N1234``) or a block's text.

    Text matches ignoring case and spaces; either must name exactly one block.

    Examples
    --------
    >>> from lagsym.dnc import parse_program
    >>> p = parse_program("O1\\nN10 G21 G90\\nN20 G0 Z5.\\nN30 G1 X1. F100.")
    >>> find_block(p, "N20"), find_block(p, "n30 g1 x1. f100.")
    (3, 4)
    """
    key = spec.strip().upper()
    if re.fullmatch(r"N\s*\d+", key):
        wanted = int(re.sub(r"\D", "", key))
        hits = [i for i, b in enumerate(program.blocks, start=1)
                if (n := _N_WORD.match(b.upper())) and int(n.group(1)) == wanted]
        what = f"N{wanted}"
    else:
        flat = key.replace(" ", "")
        hits = [i for i, b in enumerate(program.blocks, start=1) if b.upper().replace(" ", "") == flat]
        what = repr(spec)
    if not hits:
        raise InputError(f"{program.source}: no block is {what}; give the N number or the text the control shows")
    if len(hits) > 1:
        shown = ", ".join(map(str, hits[:10]))
        raise InputError(f"{program.source}: {what} is blocks {shown}; give --start-block with the one you mean")
    return hits[0]
