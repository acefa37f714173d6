"""A bounded, thread-safe memory of keys seen lately (least recently used first out).

The query guard and the store both remember digests of query texts that passed their checks, so that a
text asked again skips them; this is the one place that keeps such a memory.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Hashable


class RecentKeys:
    """Keys remembered until ``limit`` newer ones push them out; ``limit`` is read at each ``add``, so an
    owner can change its bound at any time."""

    def __init__(self) -> None:
        self._keys: OrderedDict[Hashable, None] = OrderedDict()
        self._lock = threading.Lock()

    def seen(self, key: Hashable) -> bool:
        """Whether ``key`` is remembered (and, if it is, now the most recent)."""
        with self._lock:
            if key in self._keys:
                self._keys.move_to_end(key)
                return True
            return False

    def add(self, key: Hashable, limit: int) -> None:
        """Remember ``key``, forgetting the oldest keys past ``limit``."""
        with self._lock:
            self._keys[key] = None
            self._keys.move_to_end(key)
            while len(self._keys) > limit:
                self._keys.popitem(last=False)
