"""The exact surface file: a polynomial's coefficients and its values on a grid, every number an exact rational.

::

    {"format": "lagsym-surface", "version": 1, "units": "mm",
     "degree": [4, 4],
     "coefficients": [["12", "-3/50", ...], ...],
     "x": ["0", "2.9289", ...], "y": [...],
     "z": [["12.01", ...], ...],
     "fit": {"points": 144, "criterion": "gcv", "score": 0.00041, ...}}

``coefficients[a][b]`` multiplies ``x**a * y**b``.  ``x``, ``y`` and ``z``
are the polynomial's values on a grid of nodes (more nodes than its degree in
each direction), so the Lagrange surface through them is the polynomial
itself: every command that reads a points file reads this file as that
surface (:func:`lagsym.io.read_points` checks that every ``z`` is the
polynomial's value, exactly, and refuses a file where one is not).
``amplification`` is how much the surface can amplify errors in the points
it was fitted to (the fit's Lebesgue function, sampled); the commands that
machine or export a surface refuse it above their limit.  ``fit``
is the report of the fit that made it (:func:`lagsym.fit.fit_surface`), for
reading only; its figures are decimals.
"""

from __future__ import annotations

import json
from typing import IO

from ..polytext import fraction_text

__all__ = ["FORMAT", "surface_document", "write_surface_json"]

FORMAT = "lagsym-surface"


def surface_document(surface, coefficients=None, fit=None) -> dict:
    """The JSON document of ``surface`` (a :class:`~lagsym.lagrange.LagrangeSurface`) as a dict.

    ``coefficients`` (default: the surface's) may be of lower degree than the
    grid holds, as a fit of degree 0 in one direction is; ``fit`` (a
    :class:`~lagsym.fit.SurfaceFit`) adds its report.
    """
    g = surface.grid
    coeffs = coefficients if coefficients is not None else surface.coefficients
    doc = {"format": FORMAT, "version": 1}
    if g.units:
        doc["units"] = g.units
    doc["degree"] = [len(coeffs) - 1, len(coeffs[0]) - 1]
    doc["coefficients"] = [[fraction_text(c) for c in row] for row in coeffs]
    doc["x"] = [fraction_text(v) for v in g.x]
    doc["y"] = [fraction_text(v) for v in g.y]
    doc["z"] = [[fraction_text(v) for v in row] for row in g.z]
    if g.amplification is not None:
        doc["amplification"] = g.amplification
    if fit is not None:
        doc["fit"] = {
            "source": g.source, "points": len(fit.points), "weighted": fit.weights is not None,
            "method": "least squares, exact rationals",
            "criterion": fit.criterion, "score": fit.score,
            "max_residual": fit.max_residual, "rms_residual": fit.rms, "noise_estimate": fit.sigma,
            "outside_hull_share": fit.outside_hull,
        }
    return doc


def write_surface_json(stream: IO[str], surface, coefficients=None, fit=None) -> None:
    """Write ``surface`` to ``stream`` as a ``lagsym-surface`` JSON document, one row of numbers a line."""
    doc = surface_document(surface, coefficients, fit)
    lines = []
    for key, value in doc.items():
        if key in ("coefficients", "z"):
            rows = ",\n  ".join(json.dumps(row) for row in value)
            lines.append(f" {json.dumps(key)}: [\n  {rows}]")
        else:
            lines.append(f" {json.dumps(key)}: {json.dumps(value)}")
    stream.write("{\n" + ",\n".join(lines) + "\n}\n")
