"""Helpers the sub-commands share: writing results to a file or stdout."""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from fractions import Fraction
from typing import IO

from ..errors import InputError
from ..io import write_text
from ._lines import say
from ..controls import CONTROLS, work_offset
from ..machine import FEED_UNITS, LENGTH_UNITS, MM_PER, split_unit
from ..values import as_exact, finite, in_range, whole


# The options that name a file a command writes, by argparse name: each is checked against the command's inputs
# and against the other outputs before any work.  ``--log`` is appended to, and checked as it opens.
OUTPUT_OPTIONS = {"output": "-o", "print_output": "--print-output", "plot": "--plot", "log": "--log"}


def check_paths(args) -> None:
    """Before any work: every output (``-o``, ``--print-output``, ``--plot``, ``--log``) must be a path that can
    be written, not one of the command's input files, and not the file of another output."""
    from ..io import check_apart, check_not_input, check_output

    outputs = [(option, value) for name, option in OUTPUT_OPTIONS.items()
               if isinstance(value := getattr(args, name, None), str) and value and value != "-"]
    if not outputs:
        return
    inputs = []
    for name, value in vars(args).items():
        if name in OUTPUT_OPTIONS:
            continue
        for v in value if isinstance(value, (list, tuple)) else (value,):
            if isinstance(v, str) and v and v != "-" and "\x00" not in v:
                inputs.append(v)
    for option, path in outputs:
        if option != "--log":
            check_output(path)
        check_not_input(path, inputs, "" if option == "-o" else option)
    check_apart(outputs)


def emit(text: str, output: str | None, out: IO[str]) -> None:
    """Write ``text`` (plus a final newline) to the file ``output``, atomically, or to ``out``."""
    if not text.endswith("\n"):
        text += "\n"
    if output and output != "-":
        write_text(output, text)
    else:
        out.write(text)


def origin(text: str) -> tuple[float, float, float]:
    """``X,Y,Z`` in millimetres."""
    parts = text.split(",")
    if len(parts) != 3:
        raise InputError(f"--origin {text!r} must be three numbers X,Y,Z in mm")
    return tuple(in_range(v, f"--origin {'XYZ'[i]}", -LENGTH_MM, LENGTH_MM, unit="mm") for i, v in enumerate(parts))


COLUMNS_HELP = ("which columns of a table are x, y, z: every column named in order (id,x,y,z) "
                "or the 1-based numbers of x, y, z (2,3,4); default: from the header, or the only columns")
SNAP_HELP = ("take node coordinates that differ by at most TOL as one node (measured grids, CMM jitter); "
             "says how many points moved and by how much")


def add_points_arguments(p) -> None:
    """The options of every command that reads a points file: ``--columns`` and ``--snap``."""
    p.add_argument("--columns", metavar="LIST", help=COLUMNS_HELP)
    p.add_argument("--snap", metavar="TOL", help=SNAP_HELP)
    add_file_points_limit(p)


def add_file_points_limit(p) -> None:
    """``--max-file-points``: the points a points file may hold, estimated from its lines before any is read."""
    from ..io.files import MAX_FILE_POINTS

    p.add_argument("--max-file-points", type=count(1, 10**9), default=MAX_FILE_POINTS, metavar="N",
                   help=f"refuse a points file that holds more than about N points, counted from its lines before "
                        f"any is read (default {MAX_FILE_POINTS:,})")


def add_exact_limit(p) -> None:
    """``--max-exact-mb`` and ``--max-exact-s``: the limits on an exact polynomial's size and time, checked before
    it is made and as its first rows show their pace."""
    from ..exactsize import MAX_EXACT_MB

    p.add_argument("--max-exact-mb", type=number(0.001, 1e9), default=MAX_EXACT_MB, metavar="MB",
                   help=f"refuse an exact polynomial whose rationals are estimated at more than MB megabytes, "
                        f"before computing it (default {MAX_EXACT_MB})")
    add_exact_time_limit(p)


def add_exact_time_limit(p) -> None:
    """``--max-exact-s``: the limit on the time of the command's exact computations, foreseen from the pace of their
    first rows."""
    from ..exactsize import MAX_EXACT_S

    p.add_argument("--max-exact-s", type=number(0.001, 1e9), default=MAX_EXACT_S, metavar="S",
                   help=f"refuse an exact computation (the polynomial, or the change of basis its evaluation uses) "
                        f"that its first rows show would end more than S seconds after the command began "
                        f"(default {MAX_EXACT_S:g})")


def exact_limit(args) -> float:
    """The command's ``--max-exact-mb``, or the default for a command without it."""
    from ..exactsize import MAX_EXACT_MB

    return getattr(args, "max_exact_mb", MAX_EXACT_MB)


def load_points(path: str, args, err: IO[str], what: str = "surface"):
    """Read the points file ``path`` with the command's ``--columns`` and ``--snap``.

    How a table was read is said on ``err`` unless it is the plain x,y,z
    layout, and so is what ``--snap`` moved: a number read from the wrong
    column or a node moved too far should never pass unseen.  A command
    without the two options reads the file the same way.
    """
    from ..io import read_point_file

    f = read_point_file(path, what, getattr(args, "columns", None), getattr(args, "snap", None))
    if not f.plain:
        say(err, f"{path}: read as {f.layout}")
    if f.snapped is not None:
        say(err, f.snapped.text(str(path)))
    return f.points


def read_piecewise(path: str):
    """The surface of ``path`` when it is a ``lagsym-piecewise`` file, else None (a points file)."""
    from ..export.piecewisejson import read_piecewise_file

    return read_piecewise_file(path)


ACCEPT_CONDITIONING_HELP = ("use a surface that amplifies errors in its points, or leaves their heights between "
                            "them, more than lagsym's limits (see 'lagsym check'); the program header records it")


def measured_points(path: str, columns=None):
    """Measured points: a probing program's results (read as ``lagsym read-probe`` reads them) or a points file."""
    from ..io import read_scattered_points, read_text
    from ..io.points import ScatteredPoints
    from ..probe import is_probe_results, read_results, surface_points

    if path != "-":
        name, text = read_text(path)
        if is_probe_results(text):
            sp = surface_points(read_results(text, name))
            return ScatteredPoints(sp.points, name, sp.results.units, f"probe results: {sp.describe()}", plain=False)
    return read_scattered_points(path, columns)


def add_conditioning_argument(p) -> None:
    """``--accept-conditioning``, for the commands that turn a surface into something physical."""
    p.add_argument("--accept-conditioning", action="store_true", help=ACCEPT_CONDITIONING_HELP)


def conditioning_notes(grid, args, err: IO[str], surface=None) -> tuple[str, ...]:
    """Refuse ``grid`` if it amplifies data errors beyond the limit, or if its interpolant (``surface``, made
    here if not given) overshoots their heights by more than the limit, unless ``--accept-conditioning``.

    Returns the program header's notes when accepted above a limit (and says
    so on ``err``), else nothing.
    """
    return guarded_surface(grid, args, err, surface)[1]


def guarded_surface(grid, args, err: IO[str], surface=None) -> tuple[object, tuple[str, ...]]:
    """:func:`conditioning_notes`, and the exact surface through ``grid`` (made here if not given, after the
    refusals of its size and of the grid's amplification, which need no exact work)."""
    from ..conditioning import OVERSHOOT_REFUSED, require_conditioning, require_overshoot
    from ..exactsize import check_exact_size
    from ..lagrange import lagrange_surface

    accept = getattr(args, "accept_conditioning", False)
    interpolant = grid.amplification is None  # a fitted surface's file states its own figure
    if interpolant and surface is None:  # still to be made: its size is refused before its conditioning
        check_exact_size(f"surface through {grid.shape[0]} x {grid.shape[1]} nodes", grid.source, grid.x, grid.y,
                         [v for row in grid.z for v in row], exact_limit(args))
    a = require_conditioning(grid, accept=accept)
    notes = []
    if a.exceeds:
        say(err, f"lagsym: warning: {grid.source}: {a.text()}, above the limit of {a.limit:g}: "
                 f"accepted with --accept-conditioning")
        notes.append(a.header_note())
    if surface is None:
        surface = lagrange_surface(grid, max_mb=exact_limit(args))
    if interpolant:
        o = require_overshoot(surface, accept=accept)
        if o.share > OVERSHOOT_REFUSED:
            say(err, f"lagsym: warning: {grid.source}: the surface leaves its points' heights by up to "
                     f"{o.most:.4g} ({100 * o.share:.3g}% of their range), above the limit of "
                     f"{100 * OVERSHOOT_REFUSED:g}%: accepted with --accept-conditioning")
            notes.append(f"overshoot {100 * o.share:.3g} percent of the data range, above {100 * OVERSHOOT_REFUSED:g} "
                         f"percent, accepted (--accept-conditioning)")
    return surface, tuple(notes)


# Every numeric option is checked here, once, as argparse reads it: finite and within a range that
# the message states, so no command sees NaN, an infinity or a figure no machine or file can hold.
def number(low: float, high: float, unit: str = "", *, above: bool = False):
    """An argparse ``type=`` for a float option from ``low`` (or above it) to ``high``."""
    def parse(text: str) -> float:
        try:
            return in_range(text, "", low, high, above=above, unit=unit)
        except InputError as e:
            raise argparse.ArgumentTypeError(str(e)) from None
    parse.__name__ = "number"
    return parse


# Lengths and feeds are read in the program's units (``--units``: a machinist with an inch control thinks
# in inches and inches a minute) unless the number carries its own: ``5mm``, ``0.2in``, ``600mm/min``,
# ``24in/min``.  The range is checked once the number is in millimetres.


@dataclass(frozen=True)
class Given:
    """A length or feed as the command line gave it: the number, and the factor to millimetres if it named a unit."""

    text: str
    value: float
    factor: float | None
    low: float
    high: float
    above: bool
    unit: str

    def mm(self, option: str, program_units: str) -> float:
        factor = self.factor if self.factor is not None else float(MM_PER[program_units])
        value = self.value if factor == 1.0 else self.value * factor
        try:
            return in_range(value, "", self.low, self.high, above=self.above, unit=self.unit)
        except InputError:
            span = f"above {self.low:g}, up to {self.high:g}" if self.above else f"from {self.low:g} to {self.high:g}"
            shown = f" ({value:g} mm)" if factor != 1.0 else ""
            raise InputError(f"{option} = {self.text!r}{shown} is out of range: give a number {span} {self.unit}") from None


def measure(low: float, high: float, unit: str, *, above: bool = False):
    """An argparse ``type=`` for a length (``unit`` "mm") or feed ("mm/min"): a :class:`Given`, in range once in mm."""
    units = FEED_UNITS if unit == "mm/min" else LENGTH_UNITS

    def parse(text: str) -> Given:
        s, named = split_unit(text, units)
        factor = None if named is None else float(named)
        try:
            value = finite(s, "")
        except InputError:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not a number: give one, in the program's units or with {' or '.join(units)}") from None
        return Given(text, value, factor, low, high, above, unit)
    parse.__name__ = "number"
    return parse


def in_program_units(args) -> None:
    """Every :class:`Given` of ``args`` into millimetres: in the program's units where the command writes a
    program (``--units``), else in millimetres, unless it named its own unit."""
    units = getattr(args, "units", "mm") if getattr(args, "_program_units", False) else "mm"
    for name, value in vars(args).items():
        if isinstance(value, Given):
            setattr(args, name, value.mm("--" + name.replace("_", "-"), units))


def count(low: int, high: int):
    """An argparse ``type=`` for a whole-number option from ``low`` to ``high``."""
    def parse(text: str) -> int:
        try:
            return whole(text, "", low, high)
        except InputError as e:
            raise argparse.ArgumentTypeError(str(e)) from None
    parse.__name__ = "count"
    return parse


def exact(low: float | None = None, high: float | None = None, *, above: bool = False):
    """An argparse ``type=`` for an exact decimal or rational (``0.05``, ``1/3``), within the range if given."""
    def parse(text: str) -> Fraction:
        try:
            v = as_exact(text, "")
        except InputError as e:
            raise argparse.ArgumentTypeError(str(e).lstrip(": ")) from None
        if low is not None:
            try:
                in_range(float(v), "", low, high, above=above)
            except InputError:
                span = f"above {low:g}, up to {high:g}" if above else f"from {low:g} to {high:g}"
                raise argparse.ArgumentTypeError(f"{text!r} is out of range: give a number {span}") from None
        return v
    parse.__name__ = "exact"
    return parse


# The ranges, in the units the options are given in.  Wide enough for any real machine and part,
# narrow enough that every figure fits a program word and a float with room to spare.
LENGTH_MM = 100_000.0  # 100 m: no machine travels further
SCALE = number(1e-6, 1e6, "(a scale factor)", above=True)
STEP_MM = measure(1e-4, LENGTH_MM, "mm")
SMALL_MM = measure(1e-6, 1_000.0, "mm", above=True)  # tolerances and cusp heights
TOOL_MM = measure(0.0, 1_000.0, "mm")
CORNER_MM = measure(0.0, 500.0, "mm", above=True)
FEED_MM_MIN = measure(1.0, 100_000.0, "mm/min")
_RPM = number(1.0, 200_000.0, "rpm, or 0 for the spindle off")


def SPINDLE_RPM(text: str) -> float:  # noqa: N802 - named as the other option types
    """0 (spindle off) or a speed an S word can say: a fraction of a turn a minute would be written S0."""
    return 0.0 if text.strip() in ("0", "0.0", "0.") else _RPM(text)
HEIGHT_MM = measure(-LENGTH_MM, LENGTH_MM, "mm")
STOCK_MM = measure(0.0, 100.0, "mm")
DECIMALS = count(0, 6)
PROGRAM_NUMBER = count(1, max(c.program_numbers[1] for c in CONTROLS.values()))  # the control's own range is checked
TOOL_NUMBER = count(0, 9999)
DIGITS = count(1, 1000)


def dialect_help(choices) -> str:
    """The ``--dialect`` choices with the controls each stands for, the first the default."""
    return ", ".join(f"{n} ({'default; ' if i == 0 else ''}{CONTROLS[n].title})" for i, n in enumerate(choices))


def WORK_OFFSET(text: str) -> str:  # noqa: N802 - named as the other option types
    """An argparse ``type=`` for ``--work-offset``: the word goes into the program as a block, so only a work offset."""
    try:
        return work_offset(text, "")
    except InputError as e:
        raise argparse.ArgumentTypeError(str(e).strip()) from None


def add_program_arguments(g) -> None:
    """The program start and end options a point-list and a macro program share (argument group ``g``)."""
    from ..machine import COOLANTS, PROGRAM_LINE_ENDINGS

    g.add_argument("--scale", type=SCALE, default=1.0,
                   help="model scale: the part is SCALE times the size the points describe, in their units "
                        "(a file in inches is 25.4 mm per unit at scale 1; default 1)")
    g.add_argument("--work-offset", type=WORK_OFFSET, default="G54", metavar="G5x",
                   help="work offset: G54 (default) to G59, G54.1 Pn (Fanuc), G59.1-G59.3 (LinuxCNC)")
    g.add_argument("--tool-number", type=TOOL_NUMBER, default=1, metavar="N", help="tool number T (default 1)")
    g.add_argument("--length-offset", type=TOOL_NUMBER, metavar="H",
                   help="tool length offset number for G43 H (default: the tool number)")
    g.add_argument("--feed-height", type=STOCK_MM, default=2.0, metavar="MM",
                   help="height above the first point where the rapid down ends and the plunge feed begins "
                        "(default 2); --safe-z must be at least this far above the path")
    g.add_argument("--coolant", choices=COOLANTS, default="off",
                   help="off (default), flood (M08) or mist (M07); M09 at the end")
    g.add_argument("--line-ending", choices=PROGRAM_LINE_ENDINGS, default="lf", help="lf (default) or crlf")


def program_settings(args, grid, **kw):
    """The :class:`~lagsym.machine.MachineSettings` of the program options, for a surface read from ``grid``.

    The surface's units (from its file; millimetres if it names none) and
    ``--scale`` give the millimetres per surface unit.
    """
    from ..machine import MachineSettings, mm_per_surface_unit

    units = grid.units or "mm"
    return MachineSettings(
        mm_per_unit=mm_per_surface_unit(units, args.scale), surface_units=units, origin_mm=origin(args.origin),
        units=args.units, feed_mm_min=args.feed, plunge_feed_mm_min=args.plunge_feed, spindle_rpm=args.spindle,
        safe_z_mm=args.safe_z, program_number=args.program, work_offset=args.work_offset,
        line_ending=args.line_ending, decimals=args.decimals, tool_number=args.tool_number,
        length_offset=args.length_offset, feed_height_mm=args.feed_height, coolant=args.coolant, **kw)


def cusp_note(tp) -> str:
    """For a ball: the worst cusp the rows are predicted to leave, where, and the hollows it cannot reach."""
    if tp.cusp_mm is None:
        return ""
    x, y = tp.cusp_at_mm
    note = f", worst predicted cusp {tp.cusp_mm:.4f} mm normal to the surface at X{x:.3f} Y{y:.3f}"
    if tp.hollow_share:
        note += (f" outside hollows tighter than the ball ({100 * tp.hollow_share:.1f} % of the box), "
                 "whose bottom it cannot reach")
    return note
