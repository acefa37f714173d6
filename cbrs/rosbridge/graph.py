"""The topics, services and actions the bridge knows: who publishes, subscribes and provides what.

Server-side entries are added from any thread, client-side ones on the bridge's loop; one lock guards
the tables so that rosapi, ``Bridge.publish`` and registration all see a consistent view.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from cbrs.rosbridge.goals import ActionHandler
from cbrs.rosbridge.session import Session

Handler = Callable[[dict[str, Any]], dict[str, Any]]


@dataclass(eq=False)
class Topic:
    """A topic: its type ('' until someone names it), its publishers and subscribers."""

    name: str
    type: str
    server: bool = False
    latch: bool = False
    latched: str | None = None
    latched_values: Any = None  # its values for CBOR subscribers (None: read back from ``latched``)
    publishers: set[Session] = field(default_factory=set)
    subscribers: set[Session] = field(default_factory=set)

    @property
    def unused(self) -> bool:
        return not (self.server or self.publishers or self.subscribers)


@dataclass(eq=False)
class Service:
    """A service, answered by a handler on the server (``inline`` ones on the loop) or by a client."""

    name: str
    type: str
    handler: Handler | None = None
    inline: bool = False
    provider: Session | None = None


@dataclass(eq=False)
class Action:
    """An action, run by a handler on the server or by the client that advertised it."""

    name: str
    type: str
    handler: ActionHandler | None = None
    provider: Session | None = None
    spelling: str = ""  # the name as its provider wrote it (goals go to it under that name)


class Graph:
    """Topics, services and actions by global name."""

    def __init__(self) -> None:
        self.lock = threading.RLock()
        self.topics: dict[str, Topic] = {}
        self.services: dict[str, Service] = {}
        self.actions: dict[str, Action] = {}

    def topic_list(self) -> list[tuple[str, str]]:
        """(name, type) of every topic, sorted by name."""
        with self.lock:
            return sorted((topic.name, topic.type) for topic in self.topics.values())

    def service_list(self) -> list[tuple[str, str]]:
        """(name, type) of every service, sorted by name."""
        with self.lock:
            return sorted((service.name, service.type) for service in self.services.values())

    def action_list(self) -> list[tuple[str, str]]:
        """(name, type) of every action, sorted by name."""
        with self.lock:
            return sorted((action.name, action.type) for action in self.actions.values())

    def prune(self, name: str) -> None:
        """Forget a topic nobody publishes or subscribes to any more (as ROS forgets it)."""
        with self.lock:
            topic = self.topics.get(name)
            if topic is not None and topic.unused:
                del self.topics[name]
