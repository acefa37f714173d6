"""Event ports: topics with priorities, delivered to subscribers in priority order.

Components and the executor publish; ``dispatch`` delivers what is queued, high-priority events (a
fall-down alarm, a component error) before normal ones, each priority in publishing order. Delivery is
explicit (the executor dispatches once per tick), so tests see exactly when an event arrives.
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import IntEnum
from typing import Any


class Priority(IntEnum):
    HIGH = 0
    NORMAL = 1


@dataclass(frozen=True)
class Event:
    topic: str
    message: dict[str, Any]
    priority: Priority = Priority.NORMAL


Subscriber = Callable[[Event], None]


@dataclass
class EventBus:
    _queue: list[tuple[int, int, Event]] = field(default_factory=list)
    _subscribers: dict[str, list[Subscriber]] = field(default_factory=dict)
    _counter: itertools.count[int] = field(default_factory=itertools.count)
    delivered: int = 0

    def subscribe(self, topic: str, subscriber: Subscriber) -> Callable[[], None]:
        """Deliver events of ``topic`` ("*" for all) to ``subscriber``; returns the unsubscribe call."""
        self._subscribers.setdefault(topic, []).append(subscriber)
        return lambda: self._subscribers[topic].remove(subscriber)

    def publish(self, topic: str, message: dict[str, Any], priority: Priority = Priority.NORMAL) -> None:
        heapq.heappush(self._queue, (int(priority), next(self._counter), Event(topic, message, priority)))

    def dispatch(self) -> int:
        """Deliver every queued event, high priority first; returns how many were delivered."""
        count = 0
        while self._queue:
            _, _, event = heapq.heappop(self._queue)
            for subscriber in [*self._subscribers.get(event.topic, ()), *self._subscribers.get("*", ())]:
                subscriber(event)
            count += 1
        self.delivered += count
        return count
