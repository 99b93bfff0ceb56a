"""One program for a whole job: the header, each operation with its tool change, spindle and coolant, the end.

Moves are written by :func:`lagsym.post.format_moves` (Z rounded up, modal
words left out), rapids as ``G00``.  The framing is the control's
(:class:`~lagsym.controls.Framing`): a control with a tool changer changes
tools with ``T M06`` and takes each tool's length with ``G43 H``; one without
(Grbl) stops the program (``M00``) for the operator to change the tool and set
its length.  After every tool change the spindle starts, the length offset is
taken with the move up to the safe height, and only then does the tool move
sideways over the operation's first point.  The cycle-time estimate counts feed moves at their
feeds and rapids at the job's rapid rate, along straight lines.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..machine import MachineSettings
from ..macro.roughing import RoughMacro, rough_macro_blocks
from ..post.model import iso_comment, units_word
from ..post.moves import format_moves
from ..gcode.numbers import fixed
from ..toolpath.rough import PLUNGE, RAPID, ramp_note
from .operations import PlannedJob, _settings
from .spec import COOLANTS

__all__ = ["job_program", "cycle_minutes", "JobProgram"]


@dataclass(frozen=True)
class JobProgram:
    """The program text and the cycle-time estimate of each operation (minutes, in order) and in total."""

    text: str
    minutes: tuple[float, ...]

    @property
    def total_minutes(self) -> float:
        """The whole job's estimate."""
        return float(sum(self.minutes))


def cycle_minutes(points_mm: np.ndarray, kinds: np.ndarray, feed_mm_min: float, plunge_mm_min: float,
                  rapid_mm_min: float, safe_z_mm: float) -> float:
    """Minutes for one operation: down from safe Z to the first point, along the moves, back up to safe Z.

    Examples
    --------
    >>> pts = np.array([[0.0, 0.0, 10.0], [0.0, 0.0, 0.0], [100.0, 0.0, 0.0]])
    >>> cycle_minutes(pts, np.array([1, 2, 0]), 100.0, 10.0, 1000.0, 10.0)  # 1 min plunge, 1 min feed, 0.01 up
    2.01
    """
    p = np.asarray(points_mm, dtype=float)
    steps = np.linalg.norm(np.diff(p, axis=0), axis=1)
    rate = np.select([kinds[1:] == RAPID, kinds[1:] == PLUNGE], [rapid_mm_min, plunge_mm_min], feed_mm_min)
    approach = (abs(safe_z_mm - p[0, 2]) + abs(safe_z_mm - p[-1, 2])) / rapid_mm_min
    return round(float((steps / rate).sum() + approach), 10)


def job_program(job: PlannedJob) -> JobProgram:
    """The program text of a planned job, and its cycle-time estimate."""
    spec = job.spec
    base = _settings(spec)
    minutes = tuple(cycle_minutes(op.points_mm, op.kinds, op.spec.feed_mm_min, op.spec.plunge_feed_mm_min,
                                  spec.rapid_mm_min, spec.safe_z_mm) for op in job.operations)
    lines = _header(job, base, minutes)
    current = None
    for op, m in zip(job.operations, minutes):
        lines += _operation(op, _settings(spec, op.spec), spec, changed=op.tool.number != current)
        current = op.tool.number
    f = base.control.framing
    lines += ["M05", f.end] + (["%"] if f.percent else [])
    return JobProgram(base.eol.join(lines) + base.eol, minutes)


def _header(job: PlannedJob, s: MachineSettings, minutes) -> list[str]:
    spec, f = job.spec, s.control.framing
    out = ["%"] if f.percent else []
    title = iso_comment(spec.title)
    if f.program_word:
        out.append(f.program_word.format(spec.program_number) + (f" ({title})" if title else ""))
    elif title:
        out.append(f.comment(title))
    st = job.stock
    out += [f.comment(iso_comment(n)) for n in spec.notes]
    out.append(f.comment(iso_comment(f"STOCK X{st.x0:g}/{st.x1:g} Y{st.y0:g}/{st.y1:g} TOP Z{st.top_mm:g} MM")))
    for i, (op, m) in enumerate(zip(job.operations, minutes), 1):
        t = op.tool
        kind = op.spec.kind + (" MACRO" if isinstance(op.path, RoughMacro) else "") + (
            " REST" if op.spec.options.get("rest") else "")
        out.append(f.comment(iso_comment(f"{i} {kind} T{t.number} {t.tool.label} {m:.1f} MIN")))
        if op.spec.kind == "rough":  # a point list or a macro alike
            out.append(f.comment(iso_comment(f"{i} {ramp_note(t.tool)}")))
        if op.engagement is not None:
            out.append(f.comment(iso_comment(f"{i} TAKES AT MOST {op.engagement.stated} MM NORMAL TO THE SURFACE")))
    out.append(f.comment(iso_comment(f"CYCLE TIME ABOUT {sum(minutes):.1f} MIN AT RAPID {spec.rapid_mm_min:g} MM/MIN")))
    out.append(f"{units_word(s)} {f.safe_start}")
    out.append(spec.work_offset)
    return out


def _operation(op, s: MachineSettings, spec, changed: bool) -> list[str]:
    """The blocks of one operation: tool change (when the tool changes), spindle, coolant, moves, retract."""
    t, p = op.tool, op.points_mm
    num = lambda v: fixed(float(v) * s.unit_factor, s.digits)  # noqa: E731 - one length format for this operation
    c = s.control
    f = c.framing
    out = [f.comment(iso_comment(f"{op.spec.kind} {t.name} T{t.number} {t.tool.label}"))]
    if changed:
        if f.tool_change:
            out.append(f"T{t.number} {f.tool_change}")
        else:
            out += ["M05", f"G00 Z{num(spec.safe_z_mm)}", f.comment(iso_comment(f"LOAD T{t.number} AND SET ITS LENGTH")),
                    "M00"]
    out.append(f"S{int(round(op.spec.spindle_rpm))} M03")
    coolant = COOLANTS[op.spec.coolant]
    if coolant:
        out.append(coolant)
    # The tool's length and the safe height before any sideways move: a control whose M06 leaves the spindle
    # low would otherwise cross the block with the new, perhaps longer, tool.
    out.append(f"G00 G43 H{t.number} Z{num(spec.safe_z_mm)}" if c.length_offsets else f"G00 Z{num(spec.safe_z_mm)}")
    out.append(f"G00 X{num(p[0, 0])} Y{num(p[0, 1])}")
    if isinstance(op.path, RoughMacro):
        out += rough_macro_blocks(op.path, s, variables=spec.variables)
    else:
        out += _moves(op, s, (p[0, 0], p[0, 1], spec.safe_z_mm))
    out.append(f"G00 Z{num(spec.safe_z_mm)}")
    if coolant:
        out.append("M09")
    return out


def _moves(op, s: MachineSettings, previous) -> list[str]:
    """The operation's moves in runs of one kind: G00 for rapids, G01 at the plunge or cutting feed."""
    p, kinds = op.points_mm, op.kinds
    cut = np.flatnonzero(np.diff(kinds)) + 1
    out, feed = [], None
    for lo, hi in zip(np.concatenate([[0], cut]), np.concatenate([cut, [len(p)]])):
        k = kinds[lo]
        if k == RAPID:
            out += format_moves(p[lo:hi], s, previous=previous, motion="G00")
        else:
            want = op.spec.plunge_feed_mm_min if k == PLUNGE else op.spec.feed_mm_min
            out += format_moves(p[lo:hi], s, previous=previous, first_feed=None if want == feed else want)
            feed = want
        previous = p[hi - 1]
    return out
