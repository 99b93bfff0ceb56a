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


_ARC = re.compile(r"^\s*\d+\s+N\S*\s+(STRAIGHT_FEED|STRAIGHT_TRAVERSE|ARC_FEED|SELECT_PLANE|USE_LENGTH_UNITS)\((.*)\)\s*$")
# rs274's canonical arc: ARC_FEED(first_end, second_end, first_axis, second_axis, rotation, axis_end_point, ...)
# with the plane's first and second axis: XY (X, Y), XZ (Z, X), YZ (Y, Z); the third axis is the other one.
_PLANE_AXES = {"XY": (0, 1, 2), "XZ": (2, 0, 1), "YZ": (1, 2, 0)}


def arc_feeds(stdout: str):
    """The arcs in rs274's output, each ``(start, end, centre, plane, rotation)`` in mm (centre in 3-D, the
    third axis at the start's), and the number of straight feeds."""
    pos, plane, inch, out, straight = None, "XY", False, [], 0
    for line in stdout.splitlines():
        m = _ARC.match(line)
        if not m:
            continue
        kind, args = m.groups()
        if kind == "USE_LENGTH_UNITS":
            inch = "INCHES" in args
            continue
        if kind == "SELECT_PLANE":
            plane = args.split("_")[-1]
            continue
        raw = [float(t) for t in args.split(",")]
        v = [t * (25.4 if inch else 1.0) for t in raw]
        if kind != "ARC_FEED":
            pos = np.array(v[:3])
            straight += kind == "STRAIGHT_FEED"
            continue
        a, b, n = _PLANE_AXES[plane]
        end, centre = np.empty(3), pos.copy()
        end[a], end[b], end[n] = v[0], v[1], v[5]
        centre[a], centre[b] = v[2], v[3]
        out.append((pos.copy(), end, centre, plane, int(raw[4])))
        pos = end
    return out, straight


def tessellate(start, end, centre, plane, rotation, n=400):
    """``n + 1`` points along an arc as LinuxCNC moves it: the angle and the radius change evenly (a spiral when
    the start and end radii differ), a positive rotation turning the plane's first axis towards its second."""
    a, b, _ = _PLANE_AXES[plane]
    u0, v0 = start[a] - centre[a], start[b] - centre[b]
    u1, v1 = end[a] - centre[a], end[b] - centre[b]
    t0, t1 = np.arctan2(v0, u0), np.arctan2(v1, u1)
    sweep = (t1 - t0) % (2 * np.pi) if rotation > 0 else -((t0 - t1) % (2 * np.pi))
    t = np.linspace(0.0, 1.0, n + 1)
    r = np.hypot(u0, v0) + (np.hypot(u1, v1) - np.hypot(u0, v0)) * t
    out = start[None, :] + (end - start)[None, :] * t[:, None]
    out[:, a] = centre[a] + r * np.cos(t0 + sweep * t)
    out[:, b] = centre[b] + r * np.sin(t0 + sweep * t)
    return out


def grbl_chords(start, end, centre, plane, rotation, tolerance=0.002):
    """The corners of the chords Grbl 1.1 cuts an arc into (mc_arc): ``floor(sweep r / sqrt(t (2 r - t)))``
    equal turns on the start's radius ``r``, then straight to the end; ``t`` is ``$12``, the arc tolerance."""
    a, b, _ = _PLANE_AXES[plane]
    u0, v0 = start[a] - centre[a], start[b] - centre[b]
    u1, v1 = end[a] - centre[a], end[b] - centre[b]
    t0, t1 = np.arctan2(v0, u0), np.arctan2(v1, u1)
    sweep = (t1 - t0) % (2 * np.pi) if rotation > 0 else -((t0 - t1) % (2 * np.pi))
    r = np.hypot(u0, v0)
    n = int(np.floor(abs(sweep) * r / np.sqrt(tolerance * (2 * r - tolerance))))
    k = np.arange(n + 1)
    out = start[None, :] + (end - start)[None, :] * (k / max(n, 1))[:, None]
    out[:, a] = centre[a] + r * np.cos(t0 + sweep * k / max(n, 1))
    out[:, b] = centre[b] + r * np.sin(t0 + sweep * k / max(n, 1))
    return np.vstack([out[:-1] if n else out[:1], end[None, :]])
