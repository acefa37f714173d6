"""Wall-clock samples for the benches: each a ratio's numerator or denominator measured in one run."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable


def samples_ms(action: Callable[[], object], repeat: int, warm: bool = False) -> list[float]:
    """``repeat`` wall times of ``action()`` in milliseconds, in the order taken; ``warm``: call it once
    first, untimed (a store's caches, a lazy import)."""
    if warm:
        action()
    samples = []
    for _ in range(repeat):
        start = time.perf_counter()
        action()
        samples.append((time.perf_counter() - start) * 1000)
    return samples


def median_ms(action: Callable[[], object], repeat: int) -> float:
    """The median of :func:`samples_ms`."""
    return statistics.median(samples_ms(action, repeat))
