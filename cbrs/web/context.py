"""What a page handler may use: the library objects the app was built over, from Flask's app context."""

from __future__ import annotations

import threading
from collections import Counter, deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeVar

from flask import current_app

from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.matchmakers import Matchmakers
from cbrs.sparql_service import BUSY_RETRY_AFTER, SparqlService
from cbrs.tasks import TaskRunner

if TYPE_CHECKING:
    from cbrs.bridge_services import Composers


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


T = TypeVar("T")


class GenerationCache:
    """Values computed from the whole store (the taxonomy, usage counts), kept until the store changes.

    An embedded store counts the writes made through it (``generation``), so a value is current until
    the next write. A remote store does not (another robot may write to it), so there a value is
    computed every time it is asked for.
    """

    def __init__(self) -> None:
        self._kept: dict[str, tuple[object, Any]] = {}
        self._guards: dict[str, threading.Lock] = {}
        self._guard = threading.Lock()

    def get(self, kb: KnowledgeBase, key: str, compute: Callable[[], T]) -> T:
        generation = getattr(kb.store, "generation", None)
        if generation is None:
            return compute()
        with self._guard:
            guard = self._guards.setdefault(key, threading.Lock())
        with guard:  # two pages at once wait for one computation
            kept = self._kept.get(key)
            if kept is not None and kept[0] == generation:
                found: T = kept[1]
                return found
            # read before computing: a write meanwhile bumps it again, so this value is never taken for newer
            value = compute()
            self._kept[key] = (generation, value)
            return value

    def holds(self, kb: KnowledgeBase, key: str) -> bool:
        """Whether :meth:`get` would answer ``key`` without computing it."""
        kept = self._kept.get(key)
        generation = getattr(kb.store, "generation", None)
        return kept is not None and generation is not None and kept[0] == generation


class TooManyStreamsError(KnowledgeBaseError):
    """Every stream slot is taken, or this client holds as many streams as one client may."""

    http_status = 503
    kind = "busy"
    retry_after = BUSY_RETRY_AFTER


class StreamSlots:
    """How many event and camera streams are open: at most ``limit`` in all, ``per_client`` per address.

    Each open stream holds one of the HTTP server's threads; ``cbrs serve`` gives the streams their own
    ``limit`` threads on top of those that answer requests, so streams can never take those.
    """

    def __init__(self, limit: int = 8, per_client: int = 2) -> None:
        self.limit = limit
        self.per_client = per_client
        self._open: Counter[str] = Counter()
        self._guard = threading.Lock()

    @property
    def open(self) -> int:
        with self._guard:
            return sum(self._open.values())

    def take(self, client: str) -> Callable[[], None]:
        """Take a slot for ``client`` (an address); the call returned gives it back (once)."""
        with self._guard:
            if self._open[client] >= self.per_client:
                raise TooManyStreamsError(
                    f"{client} already has {self.per_client} open streams, the most one client may have "
                    "(setting streams_per_client); close one first"
                )
            if sum(self._open.values()) >= self.limit:
                raise TooManyStreamsError(
                    f"all {self.limit} stream slots are taken (setting stream_limit); retry shortly"
                )
            self._open[client] += 1
        done = threading.Event()

        def release() -> None:
            if done.is_set():
                return
            done.set()
            with self._guard:
                self._open[client] -= 1
                if self._open[client] <= 0:
                    del self._open[client]

        return release


def sparql() -> SparqlService:
    found: SparqlService = current_app.extensions["cbrs.sparql"]
    return found


def kb() -> KnowledgeBase:
    return sparql().kb


def lock() -> threading.RLock:
    """Held while reading through caches the knowledge base keeps (descriptions, matchmakers)."""
    return sparql().lock


def per_generation(key: str, compute: Callable[[], T]) -> T:
    """``compute()``, kept under ``key`` until the store is written (:class:`GenerationCache`)."""
    return _generation_cache().get(kb(), key, compute)


def kept(key: str) -> bool:
    """Whether :func:`per_generation` holds ``key`` for the store as it is now."""
    return _generation_cache().holds(kb(), key)


def _generation_cache() -> GenerationCache:
    found: GenerationCache = current_app.extensions.setdefault("cbrs.generation_cache", GenerationCache())
    return found


def matchmakers() -> Matchmakers:
    found: Matchmakers = current_app.extensions["cbrs.matchmakers"]
    return found


def composers() -> Composers:
    """The composers the plans page plans with, kept between requests as the bridge's /cbrs/plan keeps its
    own, sharing the matchmakers' taxonomy index: a new composer per request rebuilt the index, and on
    OWLS-TC that was 5.6 of the plans page's 11 s."""
    found: Composers | None = current_app.extensions.get("cbrs.composers")
    if found is None:
        from cbrs.bridge_services import Composers  # the bridge's cache of composers, not the bridge

        found = current_app.extensions.setdefault("cbrs.composers", Composers(sparql(), matchmakers()))
    return found


def tasks() -> TaskRunner:
    found: TaskRunner = current_app.extensions["cbrs.tasks"]
    return found


def events() -> EventLog:
    found: EventLog = current_app.extensions["cbrs.events"]
    return found


def streams() -> StreamSlots:
    found: StreamSlots = current_app.extensions["cbrs.streams"]
    return found


def closing() -> threading.Event:
    """Set when the server stops, so that long responses (event and camera streams) end promptly."""
    found: threading.Event = current_app.extensions["cbrs.closing"]
    return found
