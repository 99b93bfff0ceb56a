"""What the benchmarks that time lagsym's plans share: their options, Example 4 ready to plan, runs taken in turn."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import results as recorded

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from lagsym.allocator import keep_freed_memory  # noqa: E402
from lagsym.evaluate import surface_evaluator  # noqa: E402
from lagsym.io import read_points  # noqa: E402
from lagsym.lagrange import lagrange_surface  # noqa: E402
from lagsym.toolpath import drop_cutter  # noqa: E402

EXAMPLE4 = ROOT / "examples" / "paper-example-4.json"


def arguments(doc: str, argv=None, parser: argparse.ArgumentParser | None = None) -> argparse.Namespace:
    """``--runs`` and ``--results`` parsed (with ``parser``'s own options, if given), the description ``doc``'s
    first line; then glibc is asked to keep freed memory, as the ``lagsym`` command does."""
    ap = parser or argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3, help="runs of each (default 3)")
    recorded.add_option(ap)
    args = ap.parse_args(argv)
    keep_freed_memory()
    return args


def example4(scale: float, diameter: float):
    """Example 4's surface and its evaluator, the compiled drop-cutter loaded (untimed) with a ball of
    ``diameter`` mm at ``scale`` mm per unit."""
    surface = lagrange_surface(read_points(EXAMPLE4))
    ev = surface_evaluator(surface)
    drop_cutter(surface, 3.0, 3.0, diameter / 2 / scale, evaluator=ev)
    return surface, ev


def alternate(runs: int, plans: dict):
    """Wall seconds of each of ``plans`` (name: a callable) in ``runs`` rounds, taken in turn so a busy spell of a
    shared machine falls on all alike, and each one's last result."""
    walls, last = {name: [] for name in plans}, {}
    for _ in range(runs):
        for name, plan in plans.items():
            t = time.perf_counter()
            last[name] = plan()
            walls[name].append(time.perf_counter() - t)
    return walls, last
