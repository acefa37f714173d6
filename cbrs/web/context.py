"""What a page handler may use: the library objects the app was built over, from Flask's app context."""

from __future__ import annotations

import threading
from collections import deque
from typing import Any

from flask import current_app

from cbrs.matchmakers import Matchmakers
from cbrs.sparql_service import SparqlService
from cbrs.tasks import TaskRunner
from kb import KnowledgeBase


class EventLog:
    """The most recent events (task runs, steps, store updates), newest last, for the overview page."""

    def __init__(self, keep: int = 50) -> None:
        self._events: deque[dict[str, Any]] = deque(maxlen=keep)
        self._guard = threading.Lock()

    def add(self, topic: str, message: dict[str, Any]) -> None:
        with self._guard:
            self._events.append({"topic": topic, **message})

    def recent(self, count: int = 20) -> list[dict[str, Any]]:
        with self._guard:
            return list(self._events)[-count:]


def sparql() -> SparqlService:
    found: SparqlService = current_app.extensions["cbrs.sparql"]
    return found


def kb() -> KnowledgeBase:
    return sparql().kb


def lock() -> threading.RLock:
    """Held while reading through caches the knowledge base keeps (descriptions, matchmakers)."""
    return sparql().lock


def matchmakers() -> Matchmakers:
    found: Matchmakers = current_app.extensions["cbrs.matchmakers"]
    return found


def tasks() -> TaskRunner:
    found: TaskRunner = current_app.extensions["cbrs.tasks"]
    return found


def events() -> EventLog:
    found: EventLog = current_app.extensions["cbrs.events"]
    return found


def closing() -> threading.Event:
    """Set when the server stops, so that long responses (event and camera streams) end promptly."""
    found: threading.Event = current_app.extensions["cbrs.closing"]
    return found
