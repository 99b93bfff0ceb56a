"""``lagsym job JOB.toml``: one program for a whole job (roughing, finishing, tool changes) and its cycle time."""

from __future__ import annotations

from ..io import check_not_input, write_text
from ._lines import say
from ._common import add_file_points_limit, add_conditioning_argument, guarded_surface, cusp_note, exact_limit

DESCRIPTION = """Plan every operation of the job file JOB.toml (points file, units, stock
block, work offset, tools, operations) and write them as one point-list
program, in order, with a tool change, spindle speed, feeds and coolant for
each.  Every key of the job file is checked.  Lengths and feeds are in the
job's units: in an inch job (units = "inch") safe_z = 2 is 2 inches and
feed = 24 is 24 inches a minute; text with a unit ("50 mm", "600 mm/min")
is read in that unit.  The cycle-time estimate of
each operation and of the whole job is printed and written in the program's
header.  See docs/roughing.md for the job file.  The points file may be a
piecewise surface ('lagsym piecewise'); a roughing macro (macro = true) is
refused for it.

On a terminal, a progress bar on standard error shows the planning of each operation.

A job whose surface is measured on the machine has a [probe] table instead
of points (docs/probing.md): then 'lagsym job JOB.toml' writes the probing
program, and after the measurement 'lagsym job JOB.toml --measured RESULTS'
reads the results (DPRNT text or a LinuxCNC log, as 'lagsym read-probe'),
takes the tip radius off, fits the exact surface and writes the machining
program, whose header names the results file and the fit's residuals.

examples:
  lagsym job examples/example-4-job.toml -o job.ngc
  lagsym job examples/probe-job.toml -o probe-job.nc
  lagsym job examples/probe-job.toml --measured examples/probe-results.txt -o probed-job.nc"""


def add_arguments(p) -> None:
    p.add_argument("job", help="job file (TOML)")
    add_file_points_limit(p)
    p.add_argument("--measured", metavar="RESULTS",
                   help="a job with a [probe] table: the probing program's results, fitted into the job's surface")
    add_conditioning_argument(p)
    p.add_argument("-o", "--output", metavar="FILE", help="write the program to FILE instead of standard output")
    add_max_points(p)


def add_max_points(p) -> None:
    """``--max-points`` (as ``toolpath`` has it) and ``--max-samples``: each operation is estimated first."""
    from ..toolpath.plan import MAX_PLAN_POINTS
    from ..toolpath.rough import MAX_ROUGH_SAMPLES
    from ._common import add_exact_limit, count

    add_exact_limit(p)
    p.add_argument("--max-points", type=count(1, 10**12), default=MAX_PLAN_POINTS, metavar="N",
                   help=f"refuse an operation of more than N points, estimated before it is planned "
                        f"(default {MAX_PLAN_POINTS:.0e})")
    p.add_argument("--max-samples", type=count(1, 10**12), default=MAX_ROUGH_SAMPLES, metavar="N",
                   help=f"refuse a roughing level of more than N drop-cutter samples, each checked exactly "
                        f"(default {MAX_ROUGH_SAMPLES:.0e}, a few minutes)")


def run(args, out, err) -> int:
    from ..job import job_program, plan_job, read_job
    from ._progress import progress_bar

    spec = read_job(args.job)
    if args.output and args.output != "-" and spec.points is not None:
        check_not_input(args.output, [spec.points])  # the job file's points are an input too
    if spec.probe is not None and not args.measured:
        return _probe_program(spec, args, out, err)
    if args.measured:
        spec = measured_job(spec, args.measured, err)
    spec, surface = guard_job(spec, args, err)
    with progress_bar(err) as progress:
        planned = plan_job(spec, args.max_points, args.max_samples, progress=progress,
                           max_exact_mb=exact_limit(args), surface=surface)
    prog = job_program(planned)
    if args.output and args.output != "-":
        write_text(args.output, prog.text, newline="")
    else:
        out.write(prog.text)
    report(planned, prog, err)
    return 0


def guard_job(spec, args, err):
    """The job, refused if its surface amplifies data errors beyond the limit (unless accepted, then noted),
    and its exact surface."""
    from dataclasses import replace

    from ..export.piecewisejson import read_piecewise_file
    from ..io import read_points

    pieces = read_piecewise_file(spec.points) if spec.grid is None else None
    if pieces is not None:
        return spec, pieces  # local pieces: each point moves the surface near it only, so no guard rail
    grid = spec.grid if spec.grid is not None else read_points(spec.points)
    surface, notes = guarded_surface(grid, args, err)
    return replace(spec, notes=spec.notes + notes), surface


def _probe_program(spec, args, out, err) -> int:
    """The job's probe stage: its probing program."""
    from ..probe import probe_program
    from ._common import emit

    stage = spec.probe
    text = probe_program(stage.plan, stage.settings, spec.dialect, program_number=spec.program_number,
                         work_offset=spec.work_offset)
    emit(text, args.output, out)
    say(err, f"{spec.source}: probe stage: {stage.plan.describe()}, {len(stage.plan)} probing moves on "
             f"{spec.dialect}; run it, then: lagsym job {args.job} --measured RESULTS")
    return 0


def measured_job(spec, results_path: str, err):
    """The job with its surface fitted to the probe results at ``results_path``, the header naming both."""
    from dataclasses import replace

    from ..errors import InputError
    from ..fit import fit_surface
    from ..io import read_text
    from ..probe import read_results, surface_points

    if spec.probe is None:
        raise InputError(f"--measured: {spec.source} has no [probe] table; its surface is {spec.points}")
    name, text = read_text(results_path)
    results = read_results(text, name)
    if len(results.points) != len(spec.probe.plan):
        raise InputError(f"{name}: {len(results.points)} nodes, but the job's probe stage has "
                         f"{len(spec.probe.plan)}: results of another program?")
    sp = surface_points(results, spec.probe.fit_degree)
    fit = fit_surface(sp.points, spec.probe.fit_degree, source=name, units=results.units)
    say(err, f"{name}: {len(sp.points)} nodes; {sp.describe()}; fit degree {fit.degree[0]}x{fit.degree[1]}: "
             f"residuals max {fit.max_residual:.4g} mm, RMS {fit.rms:.4g} mm")
    from pathlib import Path

    notes = (f"MEASURED {Path(name).name} SHA256 {results.sha256[:16]}",
             f"TIP RADIUS {float(results.tip_radius):g} MM TAKEN OFF, WITHIN {sp.bound:.2g} MM",
             f"FIT DEGREE {fit.degree[0]}X{fit.degree[1]} OF {len(sp.points)} POINTS: RESIDUALS MAX "
             f"{fit.max_residual:.4g} MM RMS {fit.rms:.4g} MM")
    return replace(spec, grid=fit.surface.grid, notes=spec.notes + notes)


def report(planned, prog, err) -> None:
    """One line per operation (moves and minutes, for a ball's raster the cusp it leaves) and the total."""
    for op, m in zip(planned.operations, prog.minutes):
        cusp = cusp_note(op.path) if getattr(op.path, "cusp_mm", None) is not None else ""
        if getattr(op.path, "runs", None) is not None:  # a rest finish
            cusp = f", in {op.path.runs} runs over {100 * op.path.share:.1f} % of its raster"
        if op.engagement is not None:
            cusp += (f", takes at most {op.engagement.stated} mm normal to the surface (max_engagement "
                     f"{op.spec.options['max_engagement']:g} mm)")
        say(err, f"{op.label}: {len(op.points_mm)} moves, about {m:.1f} min{cusp}")
    err.write(f"cycle time about {prog.total_minutes:.1f} min (rapids at {planned.spec.rapid_mm_min:g} mm/min)\n")
