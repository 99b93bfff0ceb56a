"""Checks at the edge of the figures: every bad argument raises InputError naming it."""

from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["check_window_size", "check_samples", "check_axis", "check_heights", "check_points"]


def check_window_size(size) -> tuple[int, int]:
    """``(width, height)`` in pixels, each 16 to 8192."""
    try:
        w, h = (int(v) for v in size)
    except (TypeError, ValueError):
        raise InputError(f"window size {size!r} should be two integers (width, height)") from None
    if not (16 <= w <= 8192 and 16 <= h <= 8192):
        raise InputError(f"window size {w}x{h} is out of range: width and height must be 16 to 8192 pixels")
    return w, h


def check_samples(n, name: str = "samples") -> int:
    """A count of samples along an axis, at least 2."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2:
        raise InputError(f"{name} = {n!r} should be an integer of at least 2")
    return int(n)


def check_axis(values, name: str) -> np.ndarray:
    """A strictly increasing 1-D array of at least 2 finite values."""
    a = np.asarray(values, dtype=float)
    if a.ndim != 1 or a.size < 2:
        raise InputError(f"{name} should be a 1-D array of at least 2 values, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name} holds a value that is not finite")
    if not np.all(np.diff(a) > 0):
        k = int(np.argmin(np.diff(a) > 0))
        raise InputError(f"{name} must increase strictly, but {name}[{k}] = {a[k]} and {name}[{k + 1}] = {a[k + 1]}")
    return a


def check_heights(z, shape: tuple[int, int], name: str) -> np.ndarray:
    """Finite heights of the ``shape`` the sample axes give."""
    a = np.asarray(z, dtype=float)
    if a.shape != shape:
        raise InputError(f"{name} has shape {a.shape}, but the axes x and y give {shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name} holds a value that is not finite")
    return a


def check_points(a, name: str) -> np.ndarray:
    """A non-empty ``(N, 3)`` array of finite x, y, z."""
    pts = np.asarray(a, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) == 0:
        raise InputError(f"{name} should be an (N, 3) array of x, y, z, got shape {pts.shape}")
    if not np.all(np.isfinite(pts)):
        k = int(np.argmin(np.all(np.isfinite(pts), axis=1)))
        raise InputError(f"{name}[{k}] = {pts[k].tolist()} is not finite")
    return pts
