"""What the paper's section 4 warns about, measured for a given grid (``lagsym check``).

* degree in each direction: above 6 the paper sees the deviation grow greatly;
* the spacing ratio between the directions (limitation 2);
* the Lebesgue constant of each node set: how much the interpolant can amplify
  an error in the data (and floating-point rounding);
* the overshoot of the surface between the nodes compared with the data range
  (Runge's phenomenon).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .evaluate import evaluate_grid, lebesgue_constant
from .lagrange import LagrangeSurface

__all__ = ["Finding", "CheckReport", "check_surface", "check_curve", "DEGREE_LIMIT", "SPACING_LIMIT", "LEBESGUE_LIMIT", "OVERSHOOT_LIMIT"]

DEGREE_LIMIT = 6  # the paper's danger line (section 4, item 4)
SPACING_LIMIT = 5.0  # mean dx / mean dy beyond 5 (or below 1/5) is "too large" (item 2)
LEBESGUE_LIMIT = 10.0  # data errors amplified more than tenfold
OVERSHOOT_LIMIT = 0.10  # the surface leaves the data range by more than 10 % of it
EPS = float(np.finfo(float).eps)


@dataclass(frozen=True)
class Finding:
    """One measured quantity, its limit and whether it crosses it."""

    name: str
    value: float
    limit: float
    warning: bool
    message: str


@dataclass(frozen=True)
class CheckReport:
    """All findings for one surface."""

    source: str
    findings: tuple[Finding, ...]

    @property
    def warnings(self) -> tuple[Finding, ...]:
        """The findings that cross their limit."""
        return tuple(f for f in self.findings if f.warning)

    def text(self) -> str:
        """The report as lines of text, one a finding."""
        lines = [f"{self.source}:"]
        for f in self.findings:
            lines.append(f"  {'WARNING' if f.warning else 'ok     '} {f.message}")
        lines.append(f"  {len(self.warnings)} warning(s)")
        return "\n".join(lines)


def _spacing(nodes: np.ndarray) -> float:
    return float(np.mean(np.diff(nodes)))


def float_error_bound(surface: LagrangeSurface) -> float:
    """A bound on the floating-point error of the stable evaluator, relative to the data range.

    Barycentric evaluation is forward stable: its error is a few units of
    rounding times the Lebesgue constants of the two node sets.
    """
    g = surface.grid
    lam = lebesgue_constant(g.x_array) * lebesgue_constant(g.y_array)
    zmax = float(np.abs(g.z_array).max())
    zr = float(np.ptp(g.z_array)) or max(zmax, 1.0)
    n, m = g.shape
    return EPS * lam * (n + m) * zmax / zr


def check_surface(surface: LagrangeSurface, samples_per_interval: int = 24) -> CheckReport:
    """Measure what the paper's limitations warn about for ``surface``."""
    g = surface.grid
    dx, dy = g.degree
    findings = []
    for axis, d in (("x", dx), ("y", dy)):
        findings.append(
            Finding(
                f"degree_{axis}", d, DEGREE_LIMIT, d > DEGREE_LIMIT,
                f"degree in {axis}: {d}" + (f" (above {DEGREE_LIMIT}, the paper's danger line)" if d > DEGREE_LIMIT else f" (limit {DEGREE_LIMIT})"),
            )
        )
    ratio = _spacing(g.x_array) / _spacing(g.y_array)
    bad = ratio > SPACING_LIMIT or ratio < 1 / SPACING_LIMIT
    findings.append(
        Finding("spacing_ratio", ratio, SPACING_LIMIT, bad,
                f"spacing ratio mean dx / mean dy: {ratio:.4g}" + (f" (outside 1/{SPACING_LIMIT:g}..{SPACING_LIMIT:g})" if bad else ""))
    )
    for axis, nodes in (("x", g.x_array), ("y", g.y_array)):
        lam = lebesgue_constant(nodes)
        findings.append(
            Finding(f"lebesgue_{axis}", lam, LEBESGUE_LIMIT, lam > LEBESGUE_LIMIT,
                    f"Lebesgue constant of the {axis} nodes: {lam:.4g}"
                    + (f" (data errors can be amplified {lam:.3g} times)" if lam > LEBESGUE_LIMIT else ""))
        )
    xs = np.linspace(g.x_array[0], g.x_array[-1], dx * samples_per_interval + 1)
    ys = np.linspace(g.y_array[0], g.y_array[-1], dy * samples_per_interval + 1)
    zs = evaluate_grid(surface, xs, ys)
    zmin, zmax = float(g.z_array.min()), float(g.z_array.max())
    zrange = zmax - zmin
    over = max(float(zs.max()) - zmax, zmin - float(zs.min()), 0.0)
    rel = over / zrange if zrange > 0 else (0.0 if over <= 1e-12 * max(abs(zmax), 1.0) else float("inf"))
    i, j = np.unravel_index(np.argmax(np.maximum(zs - zmax, zmin - zs)), zs.shape)
    findings.append(
        Finding("overshoot", rel, OVERSHOOT_LIMIT, rel > OVERSHOOT_LIMIT,
                f"overshoot between nodes: {over:.4g} ({100 * rel:.3g}% of the data range {zrange:.4g}) "
                f"worst near (x, y) = ({xs[i]:.4g}, {ys[j]:.4g})")
    )
    err = float_error_bound(surface)
    findings.append(
        Finding("float_error", err, 1e-12, err > 1e-12,
                f"floating-point evaluation error bound: {err:.2g} of the data range"
                + (" (numeric samples cannot be trusted to 1e-12; use exact evaluation or fewer nodes)" if err > 1e-12 else ""))
    )
    return CheckReport(source=g.source, findings=tuple(findings))


def check_curve(curve, samples_per_interval: int = 48) -> CheckReport:
    """The same measures for a 1-D Lagrange curve: degree, Lebesgue constant, overshoot."""
    from .evaluate import evaluate_curve

    p = curve.points
    d = curve.degree
    lam = lebesgue_constant(p.x_array)
    xs = np.linspace(p.x_array[0], p.x_array[-1], d * samples_per_interval + 1)
    ys = evaluate_curve(curve, xs)
    lo, hi = float(p.y_array.min()), float(p.y_array.max())
    over = max(float(ys.max()) - hi, lo - float(ys.min()), 0.0)
    rel = over / (hi - lo) if hi > lo else (0.0 if over <= 1e-12 * max(abs(hi), 1.0) else float("inf"))
    findings = (
        Finding("degree_x", d, DEGREE_LIMIT, d > DEGREE_LIMIT,
                f"degree: {d}" + (f" (above {DEGREE_LIMIT}, the paper's danger line)" if d > DEGREE_LIMIT else f" (limit {DEGREE_LIMIT})")),
        Finding("lebesgue_x", lam, LEBESGUE_LIMIT, lam > LEBESGUE_LIMIT,
                f"Lebesgue constant of the nodes: {lam:.4g}"
                + (f" (data errors can be amplified {lam:.3g} times)" if lam > LEBESGUE_LIMIT else "")),
        Finding("overshoot", rel, OVERSHOOT_LIMIT, rel > OVERSHOOT_LIMIT,
                f"overshoot between nodes: {over:.4g} ({100 * rel:.3g}% of the data range {hi - lo:.4g})"),
    )
    return CheckReport(source=p.source, findings=findings)
