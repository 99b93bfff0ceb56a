"""The job file: TOML naming the points file, units, stock, work offset, tools and operations, every key checked.

An unknown key, a missing one or a bad value is refused with the file, the
key and (for a choice) the valid values.  Example::

    points = "paper-example-4.json"     # relative to the job file
    dialect = "linuxcnc"                 # fanuc, haas, linuxcnc or grbl
    scale = 20                           # mm per surface unit
    safe_z = 80

    [stock]
    top_above = 2                        # above the surface's highest point, in the job's units (or: top = 73.6)

    [tools.rougher]
    number = 1
    shape = "flat"
    diameter = 10

    [[operations]]
    kind = "rough"
    tool = "rougher"
    stepdown = 2
    stepover = 5
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError, LagsymError
from ..io.files import read_bytes
from ..io.tomltext import check_toml_depth
from ..controls import VARIABLE_PROFILES, control, names
from ..machine import DIRECTIONS, TOOL_SHAPES, UNITS, Tool
from ..toolpath.rough import MILLING, PATTERNS
from ..values import FrozenMap, in_range
from .units import Given, in_mm

__all__ = ["JobSpec", "OperationSpec", "ToolSpec", "ProbeStage", "read_job", "parse_job", "KINDS", "COOLANTS",
           "MAX_OPERATIONS"]

KINDS = ("rough", "semi-finish", "finish", "cross-finish")
"""Operation kinds, in the order a machinist runs them."""
COOLANTS = {"off": None, "flood": "M08", "mist": "M07"}
JOB_DIALECTS = names(point_lists=True)
"""The controls a job is written for: those with point-list programs."""

_TOP = {"points": str, "dialect": str, "units": str, "scale": float, "origin": list, "work_offset": str,
        "program_number": int, "safe_z": float, "rapid": float, "title": str, "stock": dict, "tools": dict,
        "operations": list, "variables": str, "probe": dict}
_PROBE = {"box": list, "top": float, "bottom": float, "tip_radius": float, "degree": int, "margin": int,
          "spacing": str, "clearance": float, "overtravel": float, "feed": float, "fit_degree": int}
_REQUIRED_PROBE = ("box", "top", "bottom", "tip_radius")
_STOCK = {"top": float, "top_above": float, "margin": float, "block": list}
_TOOL = {"number": int, "shape": str, "diameter": float, "corner_radius": float, "flute_length": float,
         "reach": float, "centre_cutting": bool, "plunge_angle": float}
_OP = {"kind": str, "tool": str, "spindle": float, "feed": float, "plunge_feed": float, "coolant": str,
       "stepdown": float, "stepover": float, "step": float, "scallop": float, "tolerance": float,
       "stock_to_leave": float, "direction": str, "milling": str, "macro": bool, "precision": int,
       "pattern": str, "rest": bool, "rest_above": float, "max_engagement": float}
_REQUIRED_OP = ("kind", "tool")
MAX_OPERATIONS = 32
"""Operations in one job file: a real job has a handful, and each is planned in turn up to the point limit."""


@dataclass(frozen=True)
class ToolSpec:
    """A tool of the job: its pocket and length-offset number, its cutter and (optionally) its flute length and reach."""

    name: str
    number: int
    tool: Tool
    flute_length_mm: float | None = None
    reach_mm: float | None = None


@dataclass(frozen=True)
class OperationSpec:
    """One operation: its kind, tool, spindle, feeds, coolant and the raster or roughing options given."""

    kind: str
    tool: str
    spindle_rpm: float = 3000.0
    feed_mm_min: float = 600.0
    plunge_feed_mm_min: float = 200.0
    coolant: str = "off"
    options: Mapping = field(default_factory=FrozenMap)

    def __post_init__(self):
        object.__setattr__(self, "options", FrozenMap(self.options))


@dataclass(frozen=True)
class ProbeStage:
    """A job's probe stage: the node plan and the probe's settings, and the degree the measurement is fitted with
    (None: chosen by cross-validation)."""

    plan: object
    settings: object
    fit_degree: int | None = None


@dataclass(frozen=True)
class JobSpec:
    """A whole job as read from its file (lengths in mm).

    With a probe stage (``probe``), ``points`` is None until the measurement
    is fitted: ``grid`` then holds the fitted surface's grid.
    """

    source: str
    points: Path
    dialect: str
    units: str
    mm_per_unit: float
    origin_mm: tuple[float, float, float]
    work_offset: str
    program_number: int
    safe_z_mm: float
    rapid_mm_min: float
    title: str
    stock: Mapping
    tools: Mapping
    operations: tuple
    variables: str = "full"
    notes: tuple[str, ...] = ()  # header comments about the surface, such as an accepted conditioning
    probe: ProbeStage | None = None
    grid: object = None  # the surface's grid when it does not come from the points file (a fitted measurement)

    def __post_init__(self):
        # Read-only all the way down: a value that flows must not change under the code that holds it.
        object.__setattr__(self, "stock", FrozenMap(self.stock))
        object.__setattr__(self, "tools", FrozenMap(self.tools))
        object.__setattr__(self, "operations", tuple(self.operations))
        object.__setattr__(self, "notes", tuple(self.notes))


def read_job(path) -> JobSpec:
    """Read and check the job file at ``path``."""
    raw = read_bytes(path, "a job file")
    try:
        text = raw.decode("utf-8")
        check_toml_depth(text, str(path), "a job file")
        data = tomllib.loads(text)
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
        raise InputError(f"{path}: not a valid TOML job file: {e}") from None
    except RecursionError:
        raise InputError(f"{path}: not a job file: arrays or tables nested too deep to read") from None
    return parse_job(data, str(path), Path(path).parent)


def _keys(table: dict, allowed: dict, where: str, source: str) -> dict:
    """The table's values checked against ``allowed`` (key -> type): unknown keys and wrong types refused."""
    if not isinstance(table, dict):
        raise InputError(f"{source}: {where} must be a table")
    for key, value in table.items():
        if key not in allowed:
            raise InputError(f"{source}: unknown key {where}{key!r}; valid keys: {', '.join(allowed)}")
        want = allowed[key]
        ok = (isinstance(value, (int, float)) and not isinstance(value, bool)) if want is float else (
            isinstance(value, want) and not (want is int and isinstance(value, bool)))
        if not ok:
            raise InputError(f"{source}: {where}{key} = {value!r} must be {_NAMES[want]}")
    return table


_NAMES = {float: "a number", int: "a whole number", str: "a string", list: "a list", dict: "a table",
          bool: "true or false"}
MACRO_DIALECTS = names(point_lists=True, macros=True)
"""Of the job's controls, those with a macro language (a roughing operation may be a macro)."""
PRECISIONS = (8, 15)


def _choice(value, options, key: str, source: str):
    if value not in options:
        raise InputError(f"{source}: {key} = {value!r} is not one of {', '.join(str(o) for o in options)}")
    return value


# The ranges of the command line's options (lagsym.cli._common), by the last part of the key: every number
# of a job file is finite and one a program word and the planners can hold.
_RANGES = {"scale": (1e-6, 1e6), "rapid": (1.0, 1e5), "feed": (1.0, 1e5), "plunge_feed": (1.0, 1e5),
           "spindle": (1.0, 2e5), "diameter": (0.0, 1000.0), "corner_radius": (0.0, 500.0), "flute_length": (0.0, 1e4),
           "reach": (0.0, 1e4), "plunge_angle": (0.0, 90.0),
           "margin": (0.0, 1e5), "top_above": (0.0, 1e5), "stepdown": (1e-3, 1000.0), "stepover": (1e-4, 1000.0),
           "step": (1e-4, 1000.0), "stock_to_leave": (0.0, 100.0), "scallop": (1e-6, 1000.0),
           "tolerance": (1e-6, 1000.0), "rest_above": (0.0, 100.0), "max_engagement": (0.0, 100.0)}
_ABOVE = {"scallop", "tolerance"}  # above the low end, as --scallop and --tolerance
_LENGTH_MM = 1e5  # safe_z, origin and block coordinates: within 100 m


def _positive(value, key: str, source: str, allow_zero: bool = False) -> float:
    low, high = _RANGES[key.rsplit(".", 1)[-1]]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{source}: {key} = {value!r} must be a number")
    v = float(value)
    if not (v == v and abs(v) != float("inf")) or v < 0 or (v == 0 and not allow_zero):
        raise InputError(f"{source}: {key} = {value!r} must be a number {'0 or more' if allow_zero else 'above 0'}")
    above = (low == 0 and not allow_zero) or key.rsplit(".", 1)[-1] in _ABOVE
    return in_range(v, f"{source}: {key}", low, high, above=above)


def _length(value, key: str, source: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{source}: {key} = {value!r} must be a number (a length)")
    return in_range(value, f"{source}: {key}", -_LENGTH_MM, _LENGTH_MM, unit="mm")


def parse_job(data: dict, source: str = "<job>", base: Path = Path("."), *, lengths_in_mm: bool = False) -> JobSpec:
    """A :class:`JobSpec` from the parsed TOML ``data``; ``base`` is where a relative points path starts.

    Lengths and feeds are in the job's ``units`` (inches and inches a minute in an inch job) unless given as text
    with their unit (``"50 mm"``); with ``lengths_in_mm`` they are millimetres whatever ``units`` says (a caller
    that has converted them).
    """
    if not lengths_in_mm:
        data = in_mm(data, source)
    _keys(data, _TOP, "", source)
    for key in ("tools", "operations", "stock"):
        if key not in data:
            raise InputError(f"{source}: missing key {key!r}")
    if "\x00" in data.get("points", ""):
        raise InputError(f"{source}: points = {data['points']!r}: a file name cannot hold a NUL character")
    if ("points" in data) == ("probe" in data):
        raise InputError(f"{source}: give points (a points file) or a [probe] table (the surface measured on the "
                         f"machine), {'not both' if 'points' in data else 'one of them'}")
    origin = data.get("origin", [0.0, 0.0, 0.0])
    if len(origin) != 3 or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in origin):
        raise InputError(f"{source}: origin = {origin!r} must be three numbers [X, Y, Z]")
    tools = {name: _tool(name, t, source) for name, t in data["tools"].items()}
    numbers = [t.number for t in tools.values()]
    if len(set(numbers)) != len(numbers):
        raise InputError(f"{source}: two tools share a number ({sorted(numbers)})")
    if len(data["operations"]) > MAX_OPERATIONS:
        raise InputError(f"{source}: {len(data['operations']):,} operations, more than the {MAX_OPERATIONS} a job "
                         f"plans (each in turn, each up to the point limit): split the job into several files")
    ops = tuple(_operation(i, op, tools, source) for i, op in enumerate(data["operations"]))
    if not ops:
        raise InputError(f"{source}: operations is empty")
    if ops[0].options.get("rest"):
        raise InputError(f"{source}: operations[0].rest = true: no earlier operation leaves a stock to rest-rough; "
                         "rest = true goes on a later roughing or finishing")
    ranks = [KINDS.index(op.kind) for op in ops]
    for i in range(1, len(ops)):
        if ranks[i] < ranks[i - 1]:
            raise InputError(f"{source}: operations[{i}] ({ops[i].kind}) comes after {ops[i - 1].kind}; "
                             f"run them in the order {', '.join(KINDS)}")
    dialect = _choice(data.get("dialect", "fanuc"), JOB_DIALECTS, "dialect", source)
    for i, op in enumerate(ops):
        if op.options.get("macro") and control(dialect).macro is None:
            raise InputError(f"{source}: operations[{i}].macro: a roughing macro is written for "
                             f"{' or '.join(MACRO_DIALECTS)}, not {dialect!r}")
    variables = _choice(data.get("variables", "full"), VARIABLE_PROFILES, "variables", source)
    if "variables" in data and not any(op.options.get("macro") for op in ops):
        raise InputError(f"{source}: variables = {variables!r} applies to a roughing macro only "
                         "(an operation with macro = true)")
    program_number = data.get("program_number", 1000)
    low, high = control(dialect).program_numbers
    if not low <= program_number <= high:
        raise InputError(f"{source}: program_number = {program_number} must be {low} to {high}")
    probe = _probe(data["probe"], dialect, source) if "probe" in data else None
    title = data.get("title", Path(data["points"]).stem if "points" in data else "probed")
    _check_title(title, control(dialect), program_number, source)
    return JobSpec(
        source=source, points=base / data["points"] if "points" in data else None, probe=probe,
        dialect=dialect,
        units=_choice(data.get("units", "mm"), UNITS, "units", source),
        mm_per_unit=_positive(data.get("scale", 1.0), "scale", source),
        origin_mm=tuple(_length(v, f"origin[{k}]", source) for k, v in enumerate(origin)),
        work_offset=_choice(data.get("work_offset", "G54"), ("G54", "G55", "G56", "G57", "G58", "G59"),
                            "work_offset", source),
        program_number=program_number,
        safe_z_mm=_length(data.get("safe_z", 50.0), "safe_z", source),
        rapid_mm_min=_positive(data.get("rapid", 5000.0), "rapid", source),
        title=title,
        stock=_stock(data["stock"], source), tools=tools, operations=ops, variables=variables)


def _probe(table: dict, dialect: str, source: str) -> ProbeStage:
    """The ``[probe]`` table: the box, the part's top and bottom, the tip radius, the plan and the approach."""
    from ..probe import PROBE_DIALECTS, SPACINGS, ProbeSettings, node_plan

    _keys(table, _PROBE, "probe.", source)
    for key in _REQUIRED_PROBE:
        if key not in table:
            raise InputError(f"{source}: missing key probe.{key}")
    if control(dialect).probing is None:
        raise InputError(f"{source}: a probe stage is written for {', '.join(PROBE_DIALECTS)}, not {dialect!r}")
    box = table["box"]
    if len(box) != 4 or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in box):
        raise InputError(f"{source}: probe.box = {box!r} must be four numbers [x0, x1, y0, y1]")
    for key in ("top", "bottom"):
        _length(table[key], f"probe.{key}", source)
    for k, v in enumerate(box):
        _length(v, f"probe.box[{k}]", source)
    spacing = _choice(table.get("spacing", "chebyshev"), SPACINGS[:2], "probe.spacing", source)
    fit_degree = table.get("fit_degree")
    if fit_degree is not None and not 0 <= fit_degree <= 12:
        raise InputError(f"{source}: probe.fit_degree = {fit_degree} must be 0 to 12")
    try:
        plan = node_plan(tuple(v.exact if isinstance(v, Given) else v for v in box), table.get("degree", 4),
                         spacing=spacing, margin=table.get("margin", 2))
        settings = ProbeSettings(_exact(table["tip_radius"]), _exact(table["top"]), _exact(table["bottom"]),
                                 clearance_mm=_exact(table.get("clearance", 2)),
                                 overtravel_mm=_exact(table.get("overtravel", 2)),
                                 feed_mm_min=_exact(table.get("feed", 100)))
    except InputError as e:
        raise InputError(f"{source}: probe: {e}") from None
    return ProbeStage(plan, settings, fit_degree)


def _exact(value):
    """A probe setting as exact as the file gave it: a converted value's exact millimetres, else its text."""
    return value.exact if isinstance(value, Given) else str(value)


def _check_title(title: str, c, program_number: int, source: str) -> None:
    """The title goes into one block of the program's header: it must fit the control's block length."""
    from ..gcode.text import iso_comment

    text = iso_comment(title)
    if title.strip() and not text:
        raise InputError(f"{source}: title = {title!r} has no character a control prints in a comment (letters "
                         "A-Z, digits, space and . + - /): write it in those, or leave title out")
    f = c.framing
    block = f.program_word.format(program_number) + f" ({text})" if f.program_word else f.comment(text)
    if len(block) > c.max_block:
        raise InputError(f"{source}: title of {len(text):,} characters makes a block of {len(block):,}, more than "
                         f"the {c.max_block} a {c.name} control reads in one block; shorten it to "
                         f"{max(len(text) - (len(block) - c.max_block), 0)} characters")


def _stock(table: dict, source: str) -> dict:
    _keys(table, _STOCK, "stock.", source)
    if ("top" in table) == ("top_above" in table):
        raise InputError(f"{source}: stock needs exactly one of top (a height) or top_above (above the surface)")
    if "block" in table and "margin" in table:
        raise InputError(f"{source}: stock takes block = [x0, x1, y0, y1] or margin, not both")
    if "block" in table:
        b = table["block"]
        if len(b) != 4 or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in b):
            raise InputError(f"{source}: stock.block = {b!r} must be four numbers [x0, x1, y0, y1]")
        for k, v in enumerate(b):
            _length(v, f"stock.block[{k}]", source)
    if "top" in table:
        _length(table["top"], "stock.top", source)
    if "margin" in table:
        _positive(table["margin"], "stock.margin", source, allow_zero=True)
    if "top_above" in table:
        _positive(table["top_above"], "stock.top_above", source, allow_zero=True)
    return {k: [float(x) for x in v] if k == "block" else float(v) for k, v in table.items()}


def _tool(name: str, table: dict, source: str) -> ToolSpec:
    where = f"tools.{name}."
    _keys(table, _TOOL, where, source)
    for key in ("number", "shape", "diameter"):
        if key not in table:
            raise InputError(f"{source}: missing key {where}{key}")
    if not 1 <= table["number"] <= 99:
        raise InputError(f"{source}: {where}number = {table['number']} must be 1 to 99")
    shape = _choice(table["shape"], TOOL_SHAPES, where + "shape", source)
    corner = _positive(table["corner_radius"], where + "corner_radius", source) if "corner_radius" in table else None
    angle = _positive(table["plunge_angle"], where + "plunge_angle", source) if "plunge_angle" in table else None
    diameter = _positive(table["diameter"], where + "diameter", source)
    try:
        tool = Tool(shape, diameter, corner, centre_cutting=table.get("centre_cutting", True), ramp_angle_deg=angle)
    except LagsymError as e:
        raise InputError(f"{source}: {where}: {e}") from None
    opt = {k: _positive(table[k], where + k, source) for k in ("flute_length", "reach") if k in table}
    return ToolSpec(name, table["number"], tool, opt.get("flute_length"), opt.get("reach"))


def _operation(i: int, table: dict, tools: dict, source: str) -> OperationSpec:
    where = f"operations[{i}]."
    _keys(table, _OP, where, source)
    for key in _REQUIRED_OP:
        if key not in table:
            raise InputError(f"{source}: missing key {where}{key}")
    kind = _choice(table["kind"], KINDS, where + "kind", source)
    _choice(table["tool"], tuple(tools), where + "tool", source)
    allowed = {"stepdown", "stepover", "step", "stock_to_leave", "direction", "milling", "macro",
               "precision", "pattern", "rest"} if kind == "rough" else \
        {"stepover", "step", "scallop", "tolerance", "stock_to_leave", "direction", "rest", "rest_above",
         "max_engagement"}
    opts = {}
    for key, value in table.items():
        if key in ("kind", "tool", "spindle", "feed", "plunge_feed", "coolant"):
            continue
        if key not in allowed:
            raise InputError(f"{source}: {where}{key} does not apply to a {kind} operation; "
                             f"its options: {', '.join(sorted(allowed))}")
        if key == "direction":
            opts[key] = _choice(value, DIRECTIONS, where + key, source)
        elif key == "milling":
            opts[key] = _choice(value, MILLING, where + key, source)
        elif key in ("macro", "rest"):
            opts[key] = value
        elif key == "pattern":
            opts[key] = _choice(value, PATTERNS, where + key, source)
        elif key == "precision":
            opts[key] = _choice(value, PRECISIONS, where + key, source)
        else:
            opts[key] = _positive(value, where + key, source, allow_zero=key == "stock_to_leave")
    if opts.get("pattern") == "offset":
        for key, why in (("direction", "offset clearing has no row direction"),
                         ("macro", "a roughing macro runs raster rows")):
            if key in opts and (key != "macro" or opts[key]):
                raise InputError(f"{source}: {where}{key} does not apply with pattern = 'offset': {why}")
        if opts.get("milling") == "zigzag":
            raise InputError(f"{source}: {where}milling = 'zigzag': offset clearing cuts every rectangle one way, "
                             "climb or conventional")
    if opts.get("rest") and (opts.get("macro") or opts.get("pattern") == "offset"):
        raise InputError(f"{source}: {where}rest = true: rest roughing runs point-list raster rows, not "
                         f"{'a roughing macro (macro = true)' if opts.get('macro') else 'pattern = offset'}")
    if "rest_above" in opts and not opts.get("rest"):
        raise InputError(f"{source}: {where}rest_above applies to a rest finish (rest = true)")
    if "precision" in opts and not opts.get("macro"):
        raise InputError(f"{source}: {where}precision applies to a roughing macro only (macro = true)")
    return OperationSpec(
        kind=kind, tool=table["tool"],
        spindle_rpm=_positive(table.get("spindle", 3000.0), where + "spindle", source),
        feed_mm_min=_positive(table.get("feed", 600.0), where + "feed", source),
        plunge_feed_mm_min=_positive(table.get("plunge_feed", 200.0), where + "plunge_feed", source),
        coolant=_choice(table.get("coolant", "off"), tuple(COOLANTS), where + "coolant", source),
        options=opts)
