"""Measuring the part on the machine: the probing program, and its results read back as points.

:mod:`~lagsym.probe.plan` chooses the nodes (Chebyshev-spaced by default),
:mod:`~lagsym.probe.program` writes the program that probes them (Fanuc and
Haas ``G31`` with ``DPRNT``; LinuxCNC ``G38.2`` with a log file), and
:mod:`~lagsym.probe.results` reads the text the control sent back into
points, the probe's tip radius taken off.  See docs/probing.md.
"""

from __future__ import annotations

from .plan import MAX_NODES, SPACINGS, ProbePlan, axis_nodes, node_plan
from .program import PROBE_DIALECTS, ProbeSettings, probe_program
from .results import ProbeResults, SurfacePoints, is_probe_results, points_json, read_results, surface_points

__all__ = ["MAX_NODES", "SPACINGS", "ProbePlan", "axis_nodes", "node_plan", "PROBE_DIALECTS", "ProbeSettings",
           "probe_program", "ProbeResults", "SurfacePoints", "is_probe_results", "points_json", "read_results",
           "surface_points"]
