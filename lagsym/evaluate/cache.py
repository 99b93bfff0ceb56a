"""What is computed once per surface or curve object, remembered while the object lives and never for another.

An entry is found by the object's ``id`` and kept only with a weak
reference to the object itself, checked on every look-up: a new object
that Python places at the address of a dead one cannot be handed the dead
one's value.  Nothing here keeps an object alive, and an object that cannot
be weakly referenced is not remembered at all (its value is computed again
each time).  Equal but distinct objects each get their own entry: the key is
the object, not its value, so no look-up hashes a surface.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from typing import Generic, TypeVar

__all__ = ["ObjectCache"]

T = TypeVar("T")


class ObjectCache(Generic[T]):
    """``make(obj)`` remembered per live object.

    Examples
    --------
    >>> class Thing:
    ...     pass
    >>> cache = ObjectCache(lambda thing: object())
    >>> a = Thing()
    >>> cache.get(a) is cache.get(a), len(cache)
    (True, 1)
    >>> del a
    >>> len(cache)
    0
    """

    def __init__(self, make: Callable[[object], T]):
        self._make = make
        self._entries: dict[int, tuple[weakref.ref, T]] = {}

    def __len__(self) -> int:
        return len(self._entries)

    def get(self, obj) -> T:
        """The value for ``obj``: remembered, or made now (and remembered while ``obj`` lives)."""
        key = id(obj)
        found = self._entries.get(key)
        if found is not None and found[0]() is obj:
            return found[1]
        value = self._make(obj)
        entries = self._entries

        def forget(ref, key=key):
            if entries.get(key, (None,))[0] is ref:  # not an entry made since for a new object at this address
                entries.pop(key, None)

        try:
            ref = weakref.ref(obj, forget)
        except TypeError:  # no weak references to it: nothing to tell a new object at its address from it
            return value
        entries[key] = (ref, value)
        return value
