"""Leak checks for tests that start servers: their threads must end soon after a stop."""

from __future__ import annotations

import threading
import time


def assert_threads_end(before: int, wait: float) -> None:
    """Wait up to ``wait`` seconds for the thread count to fall back to ``before``, then insist on it.

    Client and server threads end just after their close returns, so a bounded wait comes first."""
    deadline = time.monotonic() + wait
    while threading.active_count() > before and time.monotonic() < deadline:
        time.sleep(0.01)
    assert threading.active_count() <= before, [t.name for t in threading.enumerate()]
