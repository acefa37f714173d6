"""Whether a thing's footprint (a rectangle) fits on a top (an axis-aligned rectangle) at some turn.

A rectangle turned by yaw theta covers, along x and y, ``l |cos theta| + w |sin theta|`` and
``l |sin theta| + w |cos theta|`` (:func:`turned_extent`); it fits inside a top when both are within the
top's sides, wherever on the top it then stands. Whether some turn does has a closed form
(:func:`fits_some_turn`): a footprint no longer than the top's longer side and no wider than its shorter
fits unturned; a longer one fits only turned, and best at the least turn that brings its extent along the
longer side down to that side (past it the extent across grows); it fits if, there, its extent across is
within the shorter side. The map's check (``semantic_map._check_fits``) uses it, docs/tasks.md gives the
rule.
"""

from __future__ import annotations

import math

EPSILON = 1e-9
"""Metres of rounding allowed in every comparison (a thing exactly as long as the top fits)."""


def turned_extent(length: float, width: float, yaw: float) -> tuple[float, float]:
    """What a ``length`` by ``width`` rectangle turned by ``yaw`` (radians) covers along x and along y."""
    c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
    return (length * c + width * s, length * s + width * c)


def fits_at(length: float, width: float, yaw: float, top: tuple[float, float]) -> bool:
    """Whether the rectangle turned by ``yaw`` fits inside a top of sides ``top`` (along x, along y)."""
    ex, ey = turned_extent(length, width, yaw)
    return ex <= top[0] + EPSILON and ey <= top[1] + EPSILON


def fits_unturned(length: float, width: float, top: tuple[float, float]) -> bool:
    """Whether the rectangle fits along the top's sides, either way round."""
    p, q = sorted((length, width), reverse=True)
    a, b = sorted(top, reverse=True)
    return p <= a + EPSILON and q <= b + EPSILON


def fits_some_turn(length: float, width: float, top: tuple[float, float]) -> bool:
    """Whether some turn fits the rectangle inside the top. With p >= q its sides and a >= b the top's:
    unturned when p <= a and q <= b; else, for p > a, at theta = atan2(q, p) + acos(a / hypot(p, q)), the
    least turn whose extent along a is a, provided theta <= pi / 2, where its extent along b,
    (2 p q a + (p^2 - q^2) sqrt(p^2 + q^2 - a^2)) / (p^2 + q^2), is at most b. A larger turn only widens
    it across until the extent comes down to p (at a quarter turn), which is more than b."""
    p, q = sorted((length, width), reverse=True)
    a, b = sorted(top, reverse=True)
    if p <= a + EPSILON:
        return q <= b + EPSILON
    squared = p * p + q * q
    turn = math.atan2(q, p) + math.acos(min(a / math.sqrt(squared), 1.0))
    if turn > math.pi / 2:
        return False
    across = (2.0 * p * q * a + (p * p - q * q) * math.sqrt(max(squared - a * a, 0.0))) / squared
    return across <= b + EPSILON


def fitting_turns(
    length: float, width: float, top: tuple[float, float], step: float = 0.001
) -> list[tuple[float, float]]:
    """The ranges of yaw in [0, pi/2] (radians, to ``step``) at which the rectangle fits inside the top, for
    an error's words; a yaw fits as its negative and a half turn from either do."""
    found: list[tuple[float, float]] = []
    start: float | None = None
    end = 0.0
    n = int(math.pi / 2 / step)
    for k in range(n + 1):
        yaw = min(k * step, math.pi / 2)
        if fits_at(length, width, yaw, top):
            start = yaw if start is None else start
            end = yaw
        elif start is not None:
            found.append((start, end))
            start = None
    if start is not None:
        found.append((start, end))
    return found
