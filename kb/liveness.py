"""Whether the components that run outside the process can be invoked now: leases in the store.

A component registered live (over the bridge or HTTP) is available while the session it registered
through stays open and it renews its lease. Its state lives in the ``liveness`` graph, apart from its
description, so a component that goes away keeps its six-tuple (for the browser and SPARQL) but is
no longer matched or planned. The lease's end is written as a time, so a component whose server died
without a word lapses for every other process on the store as well.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import pyoxigraph as ox

from cbrs.kb.namespaces import GraphName
from cbrs.kb.store import Store
from cbrs.kb.vocab import CBRS

__all__ = ["RESTORED_REASON", "ComponentState", "Liveness", "Restored"]

_XSD = "http://www.w3.org/2001/XMLSchema#"
_PROPERTIES = (CBRS.available, CBRS.leaseUntil, CBRS.unavailableBecause, CBRS.registeredBy)


@dataclass(frozen=True)
class ComponentState:
    """A live component's state: available now (its lease unexpired), until when, and why not."""

    component: str
    live: bool
    lease_until: dt.datetime | None
    reason: str | None
    registered_by: str | None


class Liveness:
    """Reads and writes live components' states in the store's liveness graph."""

    def __init__(self, store: Store, clock: Callable[[], dt.datetime] | None = None) -> None:
        self._store = store
        self._clock = clock or (lambda: dt.datetime.now(dt.UTC))

    def renew(self, component: str, ttl: float, registered_by: str | None = None) -> dt.datetime:
        """Mark ``component`` available for ``ttl`` seconds from now; returns when the lease ends."""
        until = self._clock() + dt.timedelta(seconds=ttl)
        facts = [(CBRS.available, _boolean(True)), (CBRS.leaseUntil, _time(until))]
        if registered_by is not None:
            facts.append((CBRS.registeredBy, ox.Literal(registered_by)))
        else:
            facts += [(CBRS.registeredBy, term) for term in self._values(component, CBRS.registeredBy)]
        self._write(component, facts)
        return until

    def expire(self, component: str, reason: str) -> None:
        """Mark ``component`` unavailable, saying why; its description stays."""
        kept = [(CBRS.registeredBy, term) for term in self._values(component, CBRS.registeredBy)]
        self._write(
            component, [(CBRS.available, _boolean(False)), (CBRS.unavailableBecause, ox.Literal(reason)), *kept]
        )

    def forget(self, component: str) -> None:
        """Remove every liveness statement about ``component`` (it was deregistered)."""
        self._write(component, [])

    def states(self) -> dict[str, ComponentState]:
        """Every live component's state, by IRI."""
        return _states(self._store.quads(graph=GraphName.LIVENESS.node), self._clock())

    def unavailable(self) -> set[str]:
        """The components registered live that cannot be invoked now."""
        return {iri for iri, state in self.states().items() if not state.live}

    def restored(self, restored: Iterable[ox.Quad], described: Callable[[str], bool]) -> Restored:
        """What graph:liveness holds after a restore puts ``restored`` (a backup's graph:liveness) in place of
        it: the liveness of a component is this store's present state, which no backup holds.

        - A component live now (its lease unexpired), whose description the store holds after the restore
          (``described``), keeps the facts it has now: the session that holds it, its lease. The backup's
          facts about it were of a session that registered it then, which may be gone (docs/backup.md).
        - Any other component keeps the backup's facts, but one the backup holds as available is written
          unavailable (:data:`RESTORED_REASON`), its ``cbrs:registeredBy`` kept: no session holds its
          lease now. Facts of a component live now that the restored store does not describe are left
          out: the server that holds it ends its lease at its next renewal, as after ``cbrs deregister``.
        """
        now = self._clock()
        present = list(self._store.quads(graph=GraphName.LIVENESS.node))
        live = {iri for iri, state in _states(present, now).items() if state.live}
        kept = sorted(iri for iri in live if described(iri))
        graph = GraphName.LIVENESS.node
        carried = [quad for quad in present if _about(quad, set(kept))]
        from_file = [quad for quad in restored if not _about(quad, live)]
        stale = {iri for iri, state in _states(from_file, now).items() if state.live}
        written = [quad for quad in from_file if not _about(quad, stale) or quad.predicate.value == CBRS.registeredBy]
        for iri in sorted(stale):
            subject = ox.NamedNode(iri)
            written.append(ox.Quad(subject, ox.NamedNode(CBRS.available), _boolean(False), graph))
            written.append(ox.Quad(subject, ox.NamedNode(CBRS.unavailableBecause), ox.Literal(RESTORED_REASON), graph))
        return Restored(written + carried, tuple(kept), tuple(sorted(stale)))

    def _values(self, component: str, predicate: str) -> list[ox.Literal]:
        quads = self._store.quads(ox.NamedNode(component), ox.NamedNode(predicate), graph=GraphName.LIVENESS.node)
        return [quad.object for quad in quads if isinstance(quad.object, ox.Literal)]

    def _write(self, component: str, facts: list[tuple[str, ox.Literal]]) -> None:
        graph, subject = GraphName.LIVENESS.node, ox.NamedNode(component)
        old = list(self._store.quads(subject, graph=graph))
        new = [ox.Quad(subject, ox.NamedNode(predicate), value, graph) for predicate, value in facts]
        self._store.replace(old, new)


RESTORED_REASON = "no session has held it since the store was restored from a backup"
"""Why a component a restored backup held as available is not: its lease was of a session then."""


@dataclass(frozen=True)
class Restored:
    """graph:liveness as a restore writes it (:meth:`Liveness.restored`)."""

    quads: list[ox.Quad]
    kept: tuple[str, ...]
    """The components live now whose present facts stay."""
    ended: tuple[str, ...]
    """The components the backup held as available, written unavailable."""


def _about(quad: ox.Quad, components: set[str]) -> bool:
    return isinstance(quad.subject, ox.NamedNode) and quad.subject.value in components


def _states(quads: Iterable[ox.Quad], now: dt.datetime) -> dict[str, ComponentState]:
    """The states the liveness facts ``quads`` say, read at ``now``."""
    found: dict[str, ComponentState] = {}
    values: dict[str, dict[str, ox.NamedNode | ox.BlankNode | ox.Literal | ox.Triple]] = {}
    for quad in quads:
        if isinstance(quad.subject, ox.NamedNode) and quad.predicate.value in _PROPERTIES:
            values.setdefault(quad.subject.value, {})[quad.predicate.value] = quad.object
    for component, props in values.items():
        available = _as_bool(props.get(CBRS.available))
        until = _as_time(props.get(CBRS.leaseUntil))
        reason = props.get(CBRS.unavailableBecause)
        registered = props.get(CBRS.registeredBy)
        live = available and (until is None or until >= now)
        if available and not live:
            reason = ox.Literal("its lease lapsed")
        found[component] = ComponentState(
            component,
            live,
            until,
            reason.value if isinstance(reason, ox.Literal) else None,
            registered.value if isinstance(registered, ox.Literal) else None,
        )
    return found


def _boolean(value: bool) -> ox.Literal:
    return ox.Literal("true" if value else "false", datatype=ox.NamedNode(_XSD + "boolean"))


def _time(value: dt.datetime) -> ox.Literal:
    return ox.Literal(value.astimezone(dt.UTC).isoformat(), datatype=ox.NamedNode(_XSD + "dateTime"))


def _as_bool(term: object) -> bool:
    return isinstance(term, ox.Literal) and term.value in ("true", "1")


def _as_time(term: object) -> dt.datetime | None:
    if not isinstance(term, ox.Literal):
        return None
    try:
        parsed = dt.datetime.fromisoformat(term.value)
    except ValueError:
        return None
    return parsed if parsed.tzinfo is not None else parsed.replace(tzinfo=dt.UTC)
