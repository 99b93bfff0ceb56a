"""Read-only NumPy arrays for the frozen values lagsym passes around."""

from __future__ import annotations

import numpy as np

__all__ = ["readonly", "freeze_fields"]


def readonly(values, dtype=float) -> np.ndarray:
    """A read-only copy of ``values`` (never the caller's own array, which stays writable).

    Examples
    --------
    >>> a = np.zeros(2)
    >>> b = readonly(a)
    >>> b.flags.writeable, a.flags.writeable
    (False, True)
    """
    a = np.array(values, dtype=dtype)
    a.setflags(write=False)
    return a


def freeze_fields(obj, names, dtype=None) -> None:
    """Replace the array fields ``names`` of a frozen dataclass instance by read-only copies (in ``__post_init__``)."""
    for name in names:
        object.__setattr__(obj, name, readonly(getattr(obj, name), dtype))
