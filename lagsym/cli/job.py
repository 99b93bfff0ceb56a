"""``lagsym job JOB.toml``: one program for a whole job (roughing, finishing, tool changes) and its cycle time."""

from __future__ import annotations

from ..io import write_text
from ._common import add_conditioning_argument, conditioning_notes, cusp_note

DESCRIPTION = """Plan every operation of the job file JOB.toml (points file, units, stock
block, work offset, tools, operations) and write them as one point-list
program, in order, with a tool change, spindle speed, feeds and coolant for
each.  Every key of the job file is checked.  The cycle-time estimate of
each operation and of the whole job is printed and written in the program's
header.  See docs/roughing.md for the job file.

On a terminal, a progress bar on standard error shows the planning of each operation.

examples:
  lagsym job examples/example-4-job.toml -o job.ngc"""


def add_arguments(p) -> None:
    p.add_argument("job", help="job file (TOML)")
    add_conditioning_argument(p)
    p.add_argument("-o", "--output", metavar="FILE", help="write the program to FILE instead of standard output")
    add_max_points(p)


def add_max_points(p) -> None:
    """``--max-points`` (as ``toolpath`` has it) and ``--max-samples``: each operation is estimated first."""
    from ..toolpath.plan import MAX_PLAN_POINTS
    from ..toolpath.rough import MAX_ROUGH_SAMPLES
    from ._common import count

    p.add_argument("--max-points", type=count(1, 10**12), default=MAX_PLAN_POINTS, metavar="N",
                   help=f"refuse an operation of more than N points, estimated before it is planned "
                        f"(default {MAX_PLAN_POINTS:.0e})")
    p.add_argument("--max-samples", type=count(1, 10**12), default=MAX_ROUGH_SAMPLES, metavar="N",
                   help=f"refuse a roughing level of more than N drop-cutter samples, each checked exactly "
                        f"(default {MAX_ROUGH_SAMPLES:.0e}, a few minutes)")


def run(args, out, err) -> int:
    from ..job import job_program, plan_job, read_job
    from ._progress import progress_bar

    spec = guard_job(read_job(args.job), args, err)
    with progress_bar(err) as progress:
        planned = plan_job(spec, args.max_points, args.max_samples, progress=progress)
    prog = job_program(planned)
    if args.output and args.output != "-":
        write_text(args.output, prog.text, newline="")
    else:
        out.write(prog.text)
    report(planned, prog, err)
    return 0


def guard_job(spec, args, err):
    """The job, refused if its surface amplifies data errors beyond the limit (unless accepted, then noted)."""
    from dataclasses import replace

    from ..io import read_points

    return replace(spec, notes=conditioning_notes(read_points(spec.points), args, err))


def report(planned, prog, err) -> None:
    """One line per operation (moves and minutes, for a ball's raster the cusp it leaves) and the total."""
    for op, m in zip(planned.operations, prog.minutes):
        cusp = cusp_note(op.path) if getattr(op.path, "cusp_mm", None) is not None else ""
        err.write(f"{op.label}: {len(op.points_mm)} moves, about {m:.1f} min{cusp}\n")
    err.write(f"cycle time about {prog.total_minutes:.1f} min (rapids at {planned.spec.rapid_mm_min:g} mm/min)\n")
