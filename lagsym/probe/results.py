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
takes the tip radius off vertically: the centres lie on the surface offset
by ``r`` along its normal, and the surface below a centre ``(x, y, z_c)`` is
``z_c - r * sqrt(1 + |grad g|**2)``, with ``g`` the fitted offset surface
(whose normal at the centre is the surface's normal at the contact).  That
is exact for a plane; on a curved surface it is off by at most
``r**2 / 2 * sin(theta)**2 * kappa``, ``theta`` the slope and ``kappa`` the
largest curvature between the contact and the point below the centre, which
:func:`surface_points` estimates from the fit's second derivatives and states.
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
    missing = [n for n in range(1, count + 1) if n not in found]
    if not ended:
        nxt = f"; node {missing[0]} and after never came" if missing else ""
        raise InputError(f"{source}: the results stop after node {last} without END (the control stopped with an "
                         f"alarm, or the line was cut){nxt}")
    if missing:
        more = f" and {len(missing) - 1} more" if len(missing) > 1 else ""
        raise InputError(f"{source}: node {missing[0]}{more} of {count} missing")
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
        return (f"tip radius {r:g} {self.results.units} taken off vertically along the normal of a degree "
                f"{self.degree[0]}x{self.degree[1]} fit of the tip centres (largest shift {self.largest_shift:.4f}, "
                f"approximation within about {self.bound:.2g} {self.results.units})")


def surface_points(results: ProbeResults, degree=None) -> SurfacePoints:
    """The surface points below the tip centres (see the module's notes); ``degree`` of the normals' fit
    (default: chosen by cross-validation)."""
    from ..fit import fit_surface

    r = results.tip_radius
    if r == 0:
        return SurfacePoints(results.points, results, None, 0.0, 0.0)
    fit = fit_surface(results.points, degree, source=results.source, units=results.units)
    c = fit.coefficients
    scale = 10 ** DECIMALS
    out, bound, largest = [], 0.0, 0.0
    for x, y, z in results.points:
        gx = sum(a * c[a][b] * x ** (a - 1) * y ** b for a in range(1, len(c)) for b in range(len(c[a])))
        gy = sum(b * c[a][b] * x ** a * y ** (b - 1) for a in range(len(c)) for b in range(1, len(c[a])))
        hxx = sum(a * (a - 1) * c[a][b] * x ** (a - 2) * y ** b for a in range(2, len(c)) for b in range(len(c[a])))
        hyy = sum(b * (b - 1) * c[a][b] * x ** a * y ** (b - 2) for a in range(len(c)) for b in range(2, len(c[a])))
        hxy = sum(a * b * c[a][b] * x ** (a - 1) * y ** (b - 1) for a in range(1, len(c)) for b in range(1, len(c[a])))
        slope2 = float(gx) ** 2 + float(gy) ** 2
        shift = float(r) * math.sqrt(1 + slope2)
        mean, half = (float(hxx) + float(hyy)) / 2, math.hypot((float(hxx) - float(hyy)) / 2, float(hxy))
        kappa = abs(mean) + half  # the largest second derivative in any direction
        bound = max(bound, float(r) ** 2 / 2 * slope2 / (1 + slope2) * kappa)
        largest = max(largest, shift)
        out.append((x, y, Fraction(round((z - Fraction(shift)) * scale), scale)))
    return SurfacePoints(tuple(out), results, fit.degree, bound, largest)


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
