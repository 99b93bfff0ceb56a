"""The probing program: one probing move at each node of a plan, the results sent out as text.

Per control (:attr:`lagsym.controls.Control.probing`):

* Fanuc and Haas: ``G31`` skip moves; the position where the probe tripped
  is read from ``#5061``-``#5063`` and sent out of the serial port with
  ``POPEN`` / ``DPRNT[..]`` / ``PCLOS``; a probe that does not trip within
  the probing distance raises ``#3000`` (the skip move then ends at its end
  point, so ``#5063`` holds that point).
* LinuxCNC: ``G38.2`` probing moves (LinuxCNC itself stops with an error when
  the move ends without contact), results written to a log file with
  ``(LOGOPEN,..)`` / ``(LOG,..)`` / ``(LOGCLOSE)``.

Every node is approached the same way: up to the retract height, across to
above the node, down at rapid to the approach height (the part's highest
point, plus the tip radius and a clearance), then the probing move at the
probing feed, at most the probing distance (down to the part's lowest point,
plus the tip radius, less an overtravel), and back up.  The text the program
sends has one header line, one line a node and an ``END`` line::

    LAGSYM PROBE MM N 49 R 1.000
    P 1 X 0.0000 Y 0.0000 Z 3.2601 OK
    ...
    END

:mod:`lagsym.probe.results` reads it back.  The positions are those of the
tip's centre: the probe's length offset must be set to the tip centre.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from ..controls import control, names
from ..errors import InputError
from ..gcode.limits import check_blocks
from ..gcode.numbers import fixed
from ..values import as_exact
from .plan import ProbePlan

__all__ = ["ProbeSettings", "probe_program", "PROBE_DIALECTS", "HEADER", "END"]

PROBE_DIALECTS = names(probing=True)
HEADER = "LAGSYM PROBE"
END = "END"
MAX_COORDINATE = Fraction(9999)  # DPRNT [44] prints four digits before the point


@dataclass(frozen=True)
class ProbeSettings:
    """The probe and how it approaches, in millimetres (exact numbers).

    Attributes
    ----------
    tip_radius_mm : Fraction
        The radius of the probe's ball tip (stated in the program and its output).
    top_mm, bottom_mm : Fraction
        The highest and lowest the part's surface may be over the box.
    clearance_mm : Fraction
        How far above the highest point the tip's lowest point starts each probing move.
    overtravel_mm : Fraction
        How far below the lowest point the probing move may go before the probe is taken as not tripped.
    retract_mm : Fraction or None
        The height of the moves between nodes (default 10 mm above the approach height).
    feed_mm_min : Fraction
        The probing feed.
    """

    tip_radius_mm: Fraction
    top_mm: Fraction
    bottom_mm: Fraction
    clearance_mm: Fraction = Fraction(2)
    overtravel_mm: Fraction = Fraction(2)
    retract_mm: Fraction | None = None
    feed_mm_min: Fraction = Fraction(100)

    def __post_init__(self):
        for name in ("tip_radius_mm", "top_mm", "bottom_mm", "clearance_mm", "overtravel_mm", "feed_mm_min"):
            object.__setattr__(self, name, as_exact(getattr(self, name), name))
        if self.retract_mm is not None:
            object.__setattr__(self, "retract_mm", as_exact(self.retract_mm, "retract_mm"))
        if self.tip_radius_mm < 0 or self.tip_radius_mm >= 50:
            raise InputError(f"probe tip radius {float(self.tip_radius_mm):g} mm: 0 to under 50 mm")
        if not self.top_mm > self.bottom_mm:
            raise InputError(f"top {float(self.top_mm):g} mm must be above bottom {float(self.bottom_mm):g} mm")
        if self.clearance_mm <= 0 or self.overtravel_mm <= 0:
            raise InputError("clearance and overtravel must be above 0 mm")
        if not 0 < self.feed_mm_min <= 5000:
            raise InputError(f"probing feed {float(self.feed_mm_min):g} mm/min: above 0, at most 5000")
        if self.retract_mm is not None and self.retract_mm < self.approach_mm:
            raise InputError(f"retract height {float(self.retract_mm):g} mm is below the approach height "
                             f"{float(self.approach_mm):g} mm (top + tip radius + clearance)")

    @property
    def approach_mm(self) -> Fraction:
        """Where each probing move starts: the tip's centre this far up."""
        return self.top_mm + self.tip_radius_mm + self.clearance_mm

    @property
    def end_mm(self) -> Fraction:
        """Where a probing move that never trips ends."""
        return self.bottom_mm + self.tip_radius_mm - self.overtravel_mm

    @property
    def distance_mm(self) -> Fraction:
        """The maximum probing distance."""
        return self.approach_mm - self.end_mm

    @property
    def safe_mm(self) -> Fraction:
        """The retract height."""
        return self.retract_mm if self.retract_mm is not None else self.approach_mm + 10


def probe_program(plan: ProbePlan, settings: ProbeSettings, dialect: str = "fanuc", *, program_number: int = 1000,
                  work_offset: str = "G54", log_name: str = "probe-results.txt", decimals: int = 3) -> str:
    """The probing program for ``plan`` on the control ``dialect`` (one of :data:`PROBE_DIALECTS`), in mm.

    Examples
    --------
    >>> from lagsym.probe.plan import node_plan
    >>> text = probe_program(node_plan((0, 10, 0, 10), 0, margin=1), ProbeSettings(1, 5, 0), "linuxcnc")
    >>> [line for line in text.splitlines() if "G38.2" in line]
    ['G38.2 Z-1.000 F100.', 'G38.2 Z-1.000 F100.', 'G38.2 Z-1.000 F100.', 'G38.2 Z-1.000 F100.']
    """
    c = control(dialect, "dialect", PROBE_DIALECTS)
    if not c.reads_work_offset(work_offset):
        raise InputError(f"work offset {work_offset!r}: a {c.name} control reads {c.work_offset_text}")
    lo, hi = c.program_numbers
    if not lo <= program_number <= hi:
        raise InputError(f"program number {program_number}: a {c.name} control takes {lo} to {hi}")
    for v in (*plan.xs, *plan.ys, settings.safe_mm, settings.end_mm):
        if abs(v) > MAX_COORDINATE:
            raise InputError(f"coordinate {float(v):g} mm: the results print at most {MAX_COORDINATE} mm")
    if not log_name or any(ch in log_name for ch in "(),\n\r"):
        raise InputError(f"log file name {log_name!r}: no brackets, commas or line ends")
    f = lambda v: fixed(v, decimals)  # noqa: E731 - one formatting rule for every coordinate
    s, fanuc = settings, c.probing.output == "dprnt"
    r = f(s.tip_radius_mm)
    lines = ["%"] if c.framing.percent else []
    title = f"LAGSYM PROBE {plan.describe().upper()}"
    lines.append(f"{c.framing.program_word.format(program_number)} ({title})" if c.framing.program_word
                 else f"({title})")
    x0, x1, y0, y1 = plan.xs[0], plan.xs[-1], plan.ys[0], plan.ys[-1]
    lines += [f"(BOX X{f(x0)} TO X{f(x1)} Y{f(y0)} TO Y{f(y1)})",
              f"(TIP RADIUS {r} MM: THE RESULTS ARE THE TIP CENTRE)",
              "(THE PROBE IN THE SPINDLE, ITS LENGTH OFFSET TO THE TIP CENTRE, ACTIVE)",
              f"(APPROACH Z{f(s.approach_mm)}, PROBE TO Z{f(s.end_mm)} AT F{fixed(s.feed_mm_min, 0)}, "
              f"AT MOST {f(s.distance_mm)} MM, RETRACT Z{f(s.safe_mm)})",
              "G21", "G17 G40 G80 G90 G94", work_offset, f"G0 Z{f(s.safe_mm)}"]
    if fanuc:
        lines += ["POPEN", f"#100={len(plan)}", f"#101={r}", "DPRNT[LAGSYM*PROBE*MM*N#100[40]*R#101[24]]"]
    else:
        lines += [f"(LOGOPEN,{log_name})", f"(LOG,{HEADER} MM N{len(plan)} R{r})"]
    # A skip move that does not trip ends at its end point: a result within half the last digit of it is a miss.
    miss = fixed(s.end_mm + Fraction(1, 2 * 10 ** decimals), decimals + 1)
    for number, x, y in plan.nodes():
        lines += [f"(NODE {number})", f"G0 X{f(x)} Y{f(y)}", f"G0 Z{f(s.approach_mm)}",
                  f"{c.probing.move} Z{f(s.end_mm)} F{fixed(s.feed_mm_min, 0)}"]
        if fanuc:
            lines += [f"IF [#5063 LE {miss}] THEN #{c.probing.alarm_variable}=1 (PROBE NOT TRIPPED)",
                      f"#100={number}", "DPRNT[P#100[40]*X#5061[44]*Y#5062[44]*Z#5063[44]*OK]"]
        else:
            lines.append(f"(LOG,P{number} X#5061 Y#5062 Z#5063 OK)")
        lines.append(f"G0 Z{f(s.safe_mm)}")
    lines += ["DPRNT[END]", "PCLOS"] if fanuc else [f"(LOG,{END})", "(LOGCLOSE)"]
    lines.append(c.framing.end)
    if c.framing.percent:
        lines.append("%")
    check_blocks(lines, c)
    return "\n".join(lines) + "\n"
