"""The text a probing program sent back, read into points: every node checked, the tip radius taken off.

The text is what :mod:`lagsym.probe.program` makes the control print
(``DPRNT`` over the serial line, or LinuxCNC's log file): one header line
``LAGSYM PROBE MM N <nodes> R <tip radius>``, one line a node
``P <n> X <x> Y <y> Z <z> OK``, and ``END``.  Numbers may stand apart from
their letter (a Fanuc prints a space in a positive number's sign place).
Line ends, ``%`` lines, NUL and the DC2/DC4 the control sends around a punch
are ignored, and so are lines before the header.  Anything else is refused
with one line naming the node: a node missing or given twice, a line cut
mid-way, no ``END`` (the stream stopped: the control raised an alarm or the
line was cut), a line that is none of these.

The positions are those of the probe tip's centre.  :func:`surface_points`
takes the tip radius off in two steps.  The centres lie on the surface
offset by ``r`` along its normal, and the normal of that offset surface at a
centre is the part's normal at the contact: so a fit ``g`` of the centres
gives each contact point, ``c - r * n`` with ``n = (-g_x, -g_y, 1) / sqrt(1 +
|grad g|**2)``, exact but for ``g``'s slope.  The contacts lie up to
``r * sin(slope)`` beside their nodes; a fit ``f`` of the contacts carries
each contact's height back to its node (``z + f(node) - f(contact)``), so
the points keep the nodes' x and y (the grid and the box the program
probed).  The error of that step is about the distance times the error of
``f``'s slope, estimated from the disagreement of the two fits' slopes at
the contacts and stated with the result (plus the 0.000001 the numbers are
written to).
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from dataclasses import dataclass
from fractions import Fraction

from ..errors import InputError
from ..gcode.numbers import fixed
from ..io.files import check_point_count
from ..values import exact_number

__all__ = ["ProbeResults", "read_results", "is_probe_results", "surface_points", "SurfacePoints", "points_json"]

_NUM = r"([-+]?\s*(?:\d+\.?\d*|\.\d+))"
_HEADER = re.compile(rf"LAGSYM\s+PROBE\s+(MM|INCH)\s+N\s*(\d+)\.?\s+R\s*{_NUM}", re.I)
_RECORD = re.compile(rf"P\s*(\d+)\.?\s+X\s*{_NUM}\s+Y\s*{_NUM}\s+Z\s*{_NUM}\s+OK", re.I)
_NODE = re.compile(r"P\s*(\d+)", re.I)
_IGNORED = "\x00\x11\x12\x13\x14\x7f"
DECIMALS = 6  # the compensated heights are rounded to 0.000001 mm


@dataclass(frozen=True)
class ProbeResults:
    """The nodes a probing program measured: ``points[k] = (x, y, z)`` of the tip centre at node ``k + 1``."""

    points: tuple[tuple[Fraction, Fraction, Fraction], ...]
    tip_radius: Fraction
    units: str
    source: str
    sha256: str


def is_probe_results(text: str) -> bool:
    """Whether ``text`` holds a probing program's header line."""
    return re.search(r"^[\s\x00-\x1f]*" + _HEADER.pattern, text[:4096], re.I | re.M) is not None


def _number(text: str) -> Fraction:
    return exact_number(text.replace(" ", ""))


def read_results(text: str, source: str = "<results>") -> ProbeResults:
    """Read a probing program's output (``DPRNT`` text or a LinuxCNC log); refuse it whole if any node is amiss.

    Examples
    --------
    >>> r = read_results("LAGSYM PROBE MM N 1 R 1.0000\\nP 1 X 2.0000 Y 3.0000 Z-1.5000 OK\\nEND\\n")
    >>> r.points, r.tip_radius
    (((Fraction(2, 1), Fraction(3, 1), Fraction(-3, 2)),), Fraction(1, 1))
    """
    check_point_count(source, text)  # a node a line
    clean = text.translate({ord(ch): None for ch in _IGNORED})
    lines = clean.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    header, count, radius, units = None, 0, Fraction(0), "mm"
    found: dict[int, tuple[Fraction, Fraction, Fraction]] = {}
    ended, last = False, 0
    for lineno, raw in enumerate(lines, 1):
        t = raw.strip()
        if not t or t.startswith("%"):
            continue
        if header is None:
            m = _HEADER.fullmatch(t)
            if m:
                header, count, radius, units = lineno, int(m.group(2)), _number(m.group(3)), m.group(1).lower()
                if count < 1:
                    raise InputError(f"{source}: line {lineno}: a header of {count} nodes")
                check_point_count(f"{source}: line {lineno}", text, stated=count)
            continue
        where = f"{source}: line {lineno}"
        if ended:
            raise InputError(f"{where}: text after END: {t[:40]!r}")
        if t.upper() == "END":
            ended = True
            continue
        m = _RECORD.fullmatch(t)
        if not m:
            node = _NODE.match(t)
            if node:
                raise InputError(f"{where}: node {int(node.group(1))}: the line is cut mid-way: {t[:60]!r}")
            raise InputError(f"{where}: not a probe result (after node {last}): {t[:60]!r}")
        n = int(m.group(1))
        if not 1 <= n <= count:
            raise InputError(f"{where}: node {n} is not one of the {count} the header names")
        if n in found:
            raise InputError(f"{where}: node {n} given twice")
        found[n] = (_number(m.group(2)), _number(m.group(3)), _number(m.group(4)))
        last = n
    if header is None:
        raise InputError(f"{source}: no 'LAGSYM PROBE' header line: not the output of a lagsym probing program")
    missing = count - len(found)  # every node found is one of the header's
    first = next((n for n in range(1, count + 1) if n not in found), None) if missing else None
    if not ended:
        nxt = f"; node {first} and after never came" if missing else ""
        raise InputError(f"{source}: the results stop after node {last} without END (the control stopped with an "
                         f"alarm, or the line was cut){nxt}")
    if missing:
        more = f" and {missing - 1:,} more" if missing > 1 else ""
        raise InputError(f"{source}: node {first}{more} of {count:,} missing")
    return ProbeResults(points=tuple(found[n] for n in range(1, count + 1)), tip_radius=radius, units=units,
                        source=source, sha256=hashlib.sha256(text.encode("utf-8", "surrogateescape")).hexdigest())


@dataclass(frozen=True)
class SurfacePoints:
    """Surface points from probe results: the tip radius taken off, how, and the approximation's bound."""

    points: tuple[tuple[Fraction, Fraction, Fraction], ...]
    results: ProbeResults
    degree: tuple[int, int] | None
    bound: float
    largest_shift: float

    def describe(self) -> str:
        """One line on the compensation."""
        r = float(self.results.tip_radius)
        if r == 0:
            return "tip radius 0: the centres are the surface points"
        return (f"tip radius {r:g} {self.results.units} taken off along the normal of a fit of the tip centres, "
                f"the contact heights carried to the nodes along a degree {self.degree[0]}x{self.degree[1]} fit of "
                f"the contacts (largest shift {self.largest_shift:.4f}, approximation within about "
                f"{self.bound:.2g} {self.results.units})")


def _poly(c, x: float, y: float, dx: int = 0, dy: int = 0) -> float:
    """The fit's polynomial ``sum c[a][b] x**a y**b`` (or its ``dx``, ``dy`` derivative) at a point, in floats."""
    total = 0.0
    for a, row in enumerate(c):
        for b, v in enumerate(row):
            if a < dx or b < dy or v == 0:
                continue
            k = math.perm(a, dx) * math.perm(b, dy)
            total += k * float(v) * x ** (a - dx) * y ** (b - dy)
    return total


def surface_points(results: ProbeResults, degree=None) -> SurfacePoints:
    """The surface points below the tip centres (see the module's notes).

    ``degree`` of the two fits (default: chosen by cross-validation, up to one less than the nodes a side).
    """
    from ..fit import fit_surface

    r = float(results.tip_radius)
    if r == 0:
        return SurfacePoints(results.points, results, None, 0.0, 0.0)
    nx, ny = len({p[0] for p in results.points}), len({p[1] for p in results.points})
    top = None if degree is not None else (min(nx - 1, 8), min(ny - 1, 8))
    centres = fit_surface(results.points, degree, max_degree=top, source=results.source, units=results.units)
    scale = 10 ** DECIMALS
    contacts, shifts = [], []
    for x, y, z in results.points:
        cc = centres.coefficients
        gx, gy = _poly(cc, float(x), float(y), 1), _poly(cc, float(x), float(y), 0, 1)
        q = math.sqrt(1 + gx * gx + gy * gy)
        n = (-gx / q, -gy / q, 1 / q)  # the centres' surface's normal: the part's normal at the contact
        contacts.append(tuple(Fraction(round((float(v) - r * k) * scale), scale) for v, k in zip((x, y, z), n)))
        shifts.append((gx, gy, q))
    part = fit_surface(contacts, degree, max_degree=top, source=results.source, units=results.units)
    c = part.coefficients
    out, bound, largest = [], 0.0, 0.0
    for (x, y, z), (px, py, pz), (gx, gy, q) in zip(results.points, contacts, shifts):
        fx, fy, ux, uy = float(x), float(y), float(px), float(py)
        height = float(pz) + _poly(c, fx, fy) - _poly(c, ux, uy)  # the contact's height, carried to the node
        # the two fits' slopes at the contact disagree by this much: over the way back to the node, the error
        gap = math.hypot(_poly(c, ux, uy, 1) - gx, _poly(c, ux, uy, 0, 1) - gy)
        rounding = (1 + math.hypot(gx, gy)) * 10.0 ** -DECIMALS  # the contacts and the height written to 6 places
        bound = max(bound, math.hypot(fx - ux, fy - uy) * gap + rounding)
        largest = max(largest, abs(float(z) - height))
        out.append((x, y, Fraction(round(Fraction(height) * scale), scale)))
    return SurfacePoints(tuple(out), results, part.degree, bound, largest)


def points_json(sp: SurfacePoints) -> str:
    """The points file: ``units``, ``points`` and a ``probe`` record of where they came from."""
    res = sp.results
    rows = ",\n".join(f"    [{_json_number(x)}, {_json_number(y)}, {_json_number(z)}]" for x, y, z in sp.points)
    record = {"source": res.source, "sha256": res.sha256, "nodes": len(res.points),
              "tip_radius": float(res.tip_radius), "compensation": sp.describe(),
              "approximation_bound": sp.bound}
    return ("{\n  \"units\": " + json.dumps(res.units) + ",\n  \"probe\": " + json.dumps(record) +
            ",\n  \"points\": [\n" + rows + "\n  ]\n}\n")


def _json_number(v: Fraction) -> str:
    """An exact decimal as a JSON number (the points are decimals of at most 6 places)."""
    text = fixed(v, DECIMALS, trim=True)
    return text + "0" if text.endswith(".") else text
