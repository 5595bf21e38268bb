"""Answers remembered by the identity of the frozen objects they were computed from (a prescription, its
surfaces tuple, its media): the object is kept with the answer, so its ``id`` in the key is not reused while
the entry lives; the oldest entry goes past ``size``. Zoom tables, focus searches and the Blender extension's
builds ask the paraxial engine the same questions thousands of times (docs/performance.md, round 16)."""

from __future__ import annotations

import threading


def same_items(a: tuple, b: tuple) -> bool:
    """Two tuples of the same objects (each by identity)."""
    return len(a) == len(b) and all(x is y for x, y in zip(a, b))


class IdentityMemo:
    """``get(key, owner)`` the answer remembered for ``key`` while it was ``owner``'s (the ``same`` test:
    identity, or :func:`same_items` for a tuple of objects), else None; ``put`` remembers one, ``clear`` forgets all."""

    def __init__(self, size: int, same=None):
        self._store: dict = {}
        self._size = size
        self._same = same
        self._lock = threading.Lock()  # (physcam serve solves in threads)

    def get(self, key, owner):
        hit = self._store.get(key)
        if hit is None:
            return None
        if hit[0] is owner if self._same is None else self._same(hit[0], owner):
            return hit[1]
        return None

    def clear(self) -> None:
        """Forget every answer."""
        with self._lock:
            self._store.clear()

    def put(self, key, owner, value):
        with self._lock:
            self._store[key] = (owner, value)
            if len(self._store) > self._size:
                del self._store[next(iter(self._store))]  # the oldest (dicts keep insertion order)
        return value
