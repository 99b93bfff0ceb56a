"""Running generated programs through LinuxCNC's ``rs274`` and reading back what it would do."""

from __future__ import annotations

import re
import tempfile
from pathlib import Path

import numpy as np

_CANON = re.compile(r"^\s*\d+\s+N\S*\s+(STRAIGHT_FEED|STRAIGHT_TRAVERSE|USE_LENGTH_UNITS)\((.*)\)\s*$")


def interpret(rs274, text: str, suffix: str = ".ngc"):
    """Run ``text`` through ``rs274 -g``; return (feeds, traverses) as (N, 3) arrays in mm, in program order.

    rs274 exits non-zero and names the block on any error (an unknown word, a
    bad number, a missing end); that is turned into an AssertionError showing it.
    rs274 reads ``%`` framing and a bare ``O`` number, so the Fanuc programs go
    through unchanged.
    """
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / f"program{suffix}"
        path.write_bytes(text.encode("ascii"))
        r = rs274.run(path)
    assert r.returncode == 0, f"rs274 refused the program: {r.stderr.strip()[-600:]}"
    assert "PROGRAM_END" in r.stdout, "rs274 did not reach the end of the program"
    feeds, travs = [], []
    inch = False
    for line in r.stdout.splitlines():
        m = _CANON.match(line)
        if not m:
            continue
        kind, args = m.groups()
        if kind == "USE_LENGTH_UNITS":
            inch = "INCHES" in args
            continue
        xyz = [float(v) * (25.4 if inch else 1.0) for v in args.split(",")[:3]]
        (feeds if kind == "STRAIGHT_FEED" else travs).append(xyz)
    return np.array(feeds).reshape(-1, 3), np.array(travs).reshape(-1, 3)


def resolution_mm(settings) -> float:
    """Largest difference between a planned point and what rs274 prints: one unit of the program's last
    decimal (Z is rounded up) plus half of rs274's fourth decimal (in the program's units)."""
    unit = 1.0 if settings.units == "mm" else 25.4
    return (10.0 ** -settings.digits + 0.5e-4) * unit * (1 + 1e-9) + 1e-12


def check_feeds(feeds, planned, settings) -> None:
    """rs274's feed moves are the planned points: X, Y to the nearest, Z at or above (never below) the plan."""
    unit = 1.0 if settings.units == "mm" else 25.4
    half = (0.5 * 10.0 ** -settings.digits + 0.5e-4) * unit + 1e-9
    assert feeds.shape == planned.shape, (feeds.shape, planned.shape)
    assert np.abs(feeds[:, :2] - planned[:, :2]).max() <= half
    dz = feeds[:, 2] - planned[:, 2]
    assert dz.min() >= -0.5e-4 * unit - 1e-9, "a written Z lies below its cutter location"
    assert dz.max() <= resolution_mm(settings)
