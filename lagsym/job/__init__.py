"""Whole jobs: a job file names the points, stock, tools and operations; one program runs them all.

:mod:`.spec` reads and checks the job file (TOML), :mod:`.operations` plans
each operation (roughing, semi-finishing, finishing, cross-finishing) as
moves with their tool, feeds and spindle, and :mod:`.program` writes them as
one point-list program with tool changes and a cycle-time estimate.
"""

from __future__ import annotations

from .operations import Operation, plan_job
from .program import cycle_minutes, job_program
from .spec import JobSpec, OperationSpec, ToolSpec, read_job

__all__ = ["JobSpec", "OperationSpec", "ToolSpec", "read_job", "Operation", "plan_job", "job_program",
           "cycle_minutes"]
