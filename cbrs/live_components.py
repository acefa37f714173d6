"""Components that run in other processes: they register while the server runs, keep a lease, and go.

A component connects to the bridge, authenticates with the update token (op ``auth``), advertises the
rosbridge service that does its work, and calls ``/cbrs/register`` with its six-tuple description
(Turtle or JSON-LD) in which a service port names that service and its message type
(``cbrs:topic``, ``cbrs:messageType``). The description is validated like any registration and
written at once, so every process on the store can match it; its lease (``ttl`` seconds) is then
renewed by ``/cbrs/heartbeat``. When its session closes or its lease lapses, the component is marked
unavailable in the store's liveness graph (:mod:`kb.liveness`): its description stays, matchmaking
and planning pass it over, a step waiting on it fails over. Registering again brings it back.
The same registration is offered over HTTP (``POST /components``, with the bearer token).

A registration holds the bridge service it is grounded on: a second registration naming a service a
live component of another session holds is refused (:class:`ServiceHeldError`), so a program started
twice, or a copy-pasted description, cannot take another device's calls; a service of the server's own
namespaces (``/cbrs/``, ``/rosapi/``) is refused as a grounding. A component deregistered while live
loses its lease within a watchdog period of the write that removed it, and its heartbeat says so
(:data:`DEREGISTERED`).

The leases a server holds are its present state; the liveness graph only publishes them. A write by
anyone else (a restore, whose copy of the liveness it read before its long write; an update of the
liveness graph) that leaves the store saying otherwise of a lease this server holds is corrected before
that write is answered (:meth:`LiveComponents.restate`).
"""

from __future__ import annotations

import datetime as dt
import difflib
import logging
import math
import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import pyoxigraph as ox

from cbrs.component_protocol import (
    DEFAULT_TTL,
    DEREGISTERED,
    FORMATS,
    NO_LIVE_COMPONENT,
    READ_ONLY,
    UNPROVIDED,
    grounding,
)
from cbrs.kb.errors import AlreadyRegisteredError, InvalidDescriptionError, KnowledgeBaseError
from cbrs.kb.liveness import ComponentState
from cbrs.kb.loader import parse_bytes
from cbrs.kb.namespaces import BASE, GraphName, shorten
from cbrs.kb.store import EmbeddedStore
from cbrs.kb.vocab import CBRS
from cbrs.rosbridge import ServiceError, current_caller
from cbrs.rosbridge.protocol import json_type
from cbrs.rosbridge.session import TOKEN_REFUSED
from cbrs.sparql_service import SparqlService

__all__ = [
    "DEFAULT_TTL",
    "DEREGISTERED",
    "MAX_DESCRIPTION_BYTES",
    "NO_LIVE_COMPONENT",
    "SERVER_NAMESPACES",
    "UNPROVIDED",
    "LiveComponents",
    "NotProvidedError",
    "ServerServiceError",
    "ServiceHeldError",
    "StoredComponentError",
    "grounding",
]

log = logging.getLogger("cbrs.live_components")

MAX_DESCRIPTION_BYTES = 256 << 10
"""A six-tuple description is a few kilobytes; anything near this is not one."""
SERVER_NAMESPACES = ("/cbrs/", "/rosapi/")
"""Service namespaces the server answers itself: no component is grounded on them."""
STALL_PERIODS = 4
"""A gap of more than this many watchdog periods (1 s at the default lease) between two moments this
server kept time means it stood still (stopped, suspended, starved): no lease is charged for it."""
SHARED_LOOK = 1.0
"""Seconds between a server's looks at the liveness graph of a store other servers write too (a remote
store), whose writes no listener of this one hears: a lease another server's restore put back stale is
stated again, and a component deregistered through another server ends, within this and a watchdog
period, rather than at the lease's next store write (half a lease and a beat). One look is one read of
the liveness graph, and none while this server holds no lease."""
ENDED_SESSIONS = 1024
"""Sessions whose ended components a heartbeat can still name (an HTTP lease never disconnects)."""


class ServiceHeldError(KnowledgeBaseError):
    """A registration names a bridge service another live component (of another session) holds."""

    http_status = 409

    def __init__(self, component: str, service: str, holder: str, holder_session: str) -> None:
        self.component, self.service, self.holder, self.holder_session = component, service, holder, holder_session
        if component == holder:
            text = (
                f"<{component}> is live already, in another session ({holder_session}) that provides {service}: "
                "is its program running twice? Stop that one, or wait for its lease to end"
            )
        else:
            text = (
                f"<{component}> names the bridge service {service}, which the live component <{holder}> "
                f"({holder_session}) holds: give each component a service of its own"
            )
        super().__init__(text)


class ServerServiceError(InvalidDescriptionError):
    """A registration is grounded on a service the server answers itself (``/cbrs/...``, ``/rosapi/...``)."""

    def __init__(self, component: str, service: str) -> None:
        self.service = service
        owned = ", ".join(SERVER_NAMESPACES)
        super().__init__(component, [f"its bridge service {service} is the server's own ({owned}): name one of yours"])


class StoredComponentError(AlreadyRegisteredError):
    """A registration names a component the store has as its own (a bundled one, or one registered with
    ``cbrs register``): a program may serve it only once it is removed, since its simulated or stored
    implementation would otherwise be replaced behind the store's back."""

    def __init__(self, iri: str) -> None:  # its own message, not the parent's
        self.iri = iri
        KnowledgeBaseError.__init__(
            self,
            f"<{iri}> is a component of the store, not a live one: to serve it from your program, remove it "
            f"first (cbrs deregister {shorten(iri)}), or give your component a name of its own",
        )


class NotProvidedError(KnowledgeBaseError):
    """A component registered other than over the bridge (``POST /components``) names a service no bridge
    client provides: nobody would answer its calls, so it is not made available."""

    http_status = 409

    def __init__(self, component: str, service: str) -> None:
        self.component, self.service = component, service
        super().__init__(
            f"<{component}>'s bridge service {service} is provided by no bridge client: start the program that "
            "answers it, then register (a component registered over HTTP is available while its service is provided)"
        )


@dataclass
class _Lease:
    session: str
    service: str  # the bridge service it is grounded on (resolved: a leading slash)
    bridge: bool  # registered through a bridge session (which provides the service), not over HTTP
    deadline: float  # monotonic seconds
    ttl: float
    written_until: float  # the monotonic time the stored leaseUntil corresponds to
    stored: dt.datetime | None = None  # the leaseUntil this server last wrote (restate compares the store's)


class LiveComponents:
    """The live registrations of one server, with a watchdog that ends lapsed leases."""

    def __init__(
        self,
        sparql: SparqlService,
        ttl: float = DEFAULT_TTL,
        name: str = "cbrs",
        clock: Callable[[], float] = time.monotonic,
        provided: Callable[[str], bool] | None = None,
        shared_look: float = SHARED_LOOK,
    ) -> None:
        if ttl <= 0:
            raise ValueError(f"a lease must last a positive time, not {ttl!r} s")
        if not shared_look > 0:
            raise ValueError(f"a shared store's liveness must be looked at every positive time, not {shared_look!r} s")
        self.sparql = sparql
        self.ttl = ttl
        self.name = name
        self._clock = clock
        self.provided = provided
        """Whether a bridge client provides a service (the server's bridge); None: not checked."""
        self.on_lapse: Callable[[str, str], None] | None = None
        """Called with the bridge service and the reason when a component's lease lapses or it is found
        deregistered: the server fails the calls waiting on it (``Bridge.fail_calls``), since its late
        answer would act on a plan that has moved on (or on a component nobody describes any more), and
        each is the server giving up on it as a disconnect is."""
        self._leases: dict[str, _Lease] = {}
        self._ended: OrderedDict[str, dict[str, str]] = OrderedDict()  # session -> {component: why it ended}
        self._guard = threading.Lock()
        self._stop = threading.Event()
        self._written = threading.Event()  # the store was written: the watchdog looks for deregistrations
        self._own = threading.local()  # .writing: this thread is telling the listeners of a write of ours
        self._unwatch: Callable[[], None] | None = None
        self._watchdog: threading.Thread | None = None
        self._period = min(0.25, ttl / 4)  # the watchdog's
        self.shared_look = shared_look
        self._seen = clock()  # when this server last kept time (the watchdog, a registration, a heartbeat)
        self._stood_still = 0.0  # seconds this server did not run, which no lease is charged

    # -- the bridge services ------------------------------------------------------------------

    def handlers(self) -> dict[str, tuple[str, Callable[[dict[str, Any]], dict[str, Any]]]]:
        return {
            "/cbrs/register": ("cbrs/Register", self.register_call),
            "/cbrs/heartbeat": ("cbrs/Heartbeat", self.heartbeat_call),
        }

    def register_call(self, args: dict[str, Any]) -> dict[str, Any]:
        caller = current_caller()
        if caller is not None and not caller.authorised:
            config = self.sparql.config
            if config.read_only or config.update_token is None:  # no token would help: say what would
                raise ServiceError(READ_ONLY)
            if caller.token_refused:
                raise ServiceError(f"registering a component needs the update token: {TOKEN_REFUSED}")
            raise ServiceError(
                "registering a component needs the update token: send it first with the auth op "
                '({"op": "auth", "mac": TOKEN}; roslibpy sends Ros.authenticate() only as it connects, so call '
                "it before run())"
            )
        session = caller.session if caller is not None else "in-process"
        _check_fields(args)
        description = args.get("description")
        if description is None:
            raise ServiceError("missing field 'description' (the component's description, as text)")
        if not isinstance(description, str):
            raise ServiceError(
                f"field 'description' must be the description as text (Turtle or JSON-LD), not {json_type(description)}"
            )
        fmt = args.get("format") or "turtle"  # "" and 0 are what a client built from the typedefs sends unset
        ttl = args.get("ttl", self.ttl)
        if ttl == 0 and not isinstance(ttl, bool):
            ttl = self.ttl
        if isinstance(ttl, bool) or not isinstance(ttl, int | float) or not 0.1 <= ttl <= 3600:
            raise ServiceError(f"field 'ttl' must be a number of seconds from 0.1 to 3600, not {ttl!r}")
        try:
            components = self.register(description, session, str(fmt), float(ttl), over_bridge=caller is not None)
        except (KnowledgeBaseError, ValueError) as error:
            raise ServiceError(str(error)) from error
        return {"components": components, "ttl": float(ttl)}

    def heartbeat_call(self, args: dict[str, Any]) -> dict[str, Any]:
        caller = current_caller()
        session = caller.session if caller is not None else "in-process"
        renewed = self.renew(session)
        ended = self.ended(session)
        if not renewed:
            deregistered = sorted(iri for iri, why in ended.items() if why == "it was deregistered")
            if deregistered:
                raise ServiceError(f"{', '.join(deregistered)} {DEREGISTERED}: it is no longer registered")
            unanswered = sorted(f"<{iri}>: {why}" for iri, why in ended.items() if why.startswith(UNPROVIDED))
            if unanswered:  # registering again would not help: say what would
                raise ServiceError(
                    f"{'; '.join(unanswered)}, so it is unavailable: advertise the service its cbrs:topic names "
                    "(advertise_service, after registering), then register again"
                )
            lapsed = "".join(f"; {iri}: {why}" for iri, why in sorted(ended.items()))
            raise ServiceError(f"{NO_LIVE_COMPONENT}: register first{lapsed}")
        return {"components": renewed, "ended": ended} if ended else {"components": renewed}

    # -- the library ---------------------------------------------------------------------------

    def register(
        self,
        description: str,
        session: str,
        fmt: str = "turtle",
        ttl: float | None = None,
        over_bridge: bool = False,
    ) -> list[str]:
        """Register (or bring back) the components ``description`` describes, for ``session``. Registered
        other than ``over_bridge`` (over HTTP), each needs a bridge client providing its service now, when
        :attr:`provided` can tell; a bridge session provides its own, after registering."""
        ttl = self.ttl if ttl is None else ttl
        if not description.strip():  # an empty file sent, or the body forgotten (curl -d without @)
            raise InvalidDescriptionError("<registration>", ["it is empty: send the description's text"])
        if len(description.encode("utf-8")) > MAX_DESCRIPTION_BYTES:
            raise InvalidDescriptionError("<registration>", [f"it is larger than {MAX_DESCRIPTION_BYTES} bytes"])
        fmt = fmt.lower()
        if fmt not in FORMATS:
            raise ValueError(f"unknown description format {fmt!r}; use {' or '.join(FORMATS)}")
        _check_format(description, fmt)
        turtle = description if fmt == "turtle" else _to_turtle(description, FORMATS[fmt])
        parsed = parse_bytes(turtle.encode("utf-8"), "<registration>", ox.RdfFormat.TURTLE, GraphName.SERVICES, BASE)
        named = {
            q.subject.value
            for q in parsed.quads
            if q.predicate.value == CBRS.serviceName and isinstance(q.subject, ox.NamedNode)
        }
        services: dict[str, str] = {}
        for iri in sorted(named):
            found = grounding(parsed.quads, iri)
            if found is None:
                raise InvalidDescriptionError(
                    iri,
                    [
                        "no service port grounds it in the bridge: give it a cbrs:ServicePort with the rosbridge "
                        "service (cbrs:topic) and its type (cbrs:messageType)"
                    ],
                )
            service = service_name(found[0])
            if service.startswith(SERVER_NAMESPACES):
                raise ServerServiceError(iri, service)
            other = next((known for known, held in services.items() if held == service), None)
            if other is not None:
                raise ServiceHeldError(iri, service, other, "this registration")
            services[iri] = service
            if not over_bridge and self.provided is not None and not self.provided(service):
                raise NotProvidedError(iri, service)
        kb = self.sparql.kb
        with self.sparql.lock:
            states = kb.liveness.states()
            self._refuse_held(services, session, states)
            returning = []
            for iri in sorted(named):
                if not kb.registry.is_registered(iri):
                    continue
                if iri not in states:
                    raise StoredComponentError(iri)  # a component of the store, not a live one
                returning.append(iri)
            if returning and len(returning) != len(named):  # one of a program's components was deregistered
                registered, updated = kb.registry.sync(turtle, "<registration>")  # both back, in one transaction
                iris = [iri for iri in sorted(named) if iri in {*registered, *updated}]
            elif returning:
                iris = kb.registry.update(turtle, "<registration>")
            else:
                iris = kb.registry.register(turtle, "<registration>")
            now = self._now()
            for iri in iris:
                until = kb.liveness.renew(iri, ttl, registered_by=self._registered_by(session))
                with self._guard:
                    self._leases[iri] = _Lease(session, services[iri], over_bridge, now + ttl, ttl, now + ttl, until)
                    self._ended.get(session, {}).pop(iri, None)
            self._changed()
        log.info("%s registered %s (lease %g s)", session, ", ".join(iris), ttl)
        return iris

    def _refuse_held(self, services: dict[str, str], session: str, states: dict[str, ComponentState]) -> None:
        """Raise :class:`ServiceHeldError` when a live component of another session holds a component's
        name or its bridge service: the second registration would take the first one's calls."""
        with self._guard:
            leases = dict(self._leases)
        shared = not isinstance(self.sparql.kb.store, EmbeddedStore)  # other servers may keep leases on it
        for iri, service in services.items():
            owner = leases.get(iri)
            if owner is not None and owner.session != session and iri in states and states[iri].live:
                raise ServiceHeldError(iri, owner.service, iri, owner.session)
            state = states.get(iri)
            if owner is None and shared and state is not None and state.live:  # live through another server
                holder = f"{state.registered_by or 'a session'}, through another server of this store"
                raise ServiceHeldError(iri, service, iri, holder)
            for held, lease in sorted(leases.items()):
                if held != iri and lease.service == service and lease.session != session:
                    raise ServiceHeldError(iri, service, held, lease.session)

    def holder(self, service: str, session: str) -> str | None:
        """Why the bridge session ``session`` may not provide ``service``: a live component another bridge
        session registered is grounded on it, and that session's program answers its calls. None if it may.
        (A component registered over HTTP holds no provider: any bridge client may answer for it.)"""
        with self._guard:
            held = [
                (iri, lease.session)
                for iri, lease in self._leases.items()
                if lease.bridge and lease.service == service and lease.session != session
            ]
        if not held:
            return None
        iri, owner = held[0]
        return (
            f"service {service!r} is held by the live component <{iri}>, which {owner} registered: only that "
            "session provides it while its lease lasts (a component of your own needs a service of its own)"
        )

    def holds(self, service: str) -> bool:
        """Whether a live component is grounded on the bridge ``service`` (its ``result`` is a verdict)."""
        with self._guard:
            return any(lease.service == service for lease in self._leases.values())

    def renew(self, session: str) -> list[str]:
        """Renew the leases of ``session``'s components; the store is written when half a lease has passed,
        and then a component deregistered meanwhile (``cbrs deregister``) loses its lease and its state."""
        now = self._now()
        renewed, stale, unprovided = [], [], []
        with self._guard:
            for iri, lease in self._leases.items():
                if lease.session == session and lease.deadline >= now:
                    lease.deadline = now + lease.ttl
                    renewed.append(iri)
                    if lease.written_until - now < lease.ttl / 2:
                        lease.written_until = lease.deadline
                        stale.append((iri, lease))
                        if self.provided is not None and not self.provided(lease.service):
                            unprovided.append((iri, lease))
        for iri, lease in unprovided:  # nobody would answer its calls: plans must not count on it
            if lease.bridge:
                self._end([iri], f"{UNPROVIDED} {lease.service} (its program registered it but does not answer it)")
                self._remember_ended(session, [iri], f"{UNPROVIDED} {lease.service}")
            else:
                self._end([iri], "no bridge client provides its service")
        if unprovided:
            dropped = {iri for iri, _ in unprovided}
            stale = [(iri, lease) for iri, lease in stale if iri not in dropped]
            renewed = [iri for iri in renewed if iri not in dropped]
        if stale:
            gone = []
            with self.sparql.lock:
                kb = self.sparql.kb
                for iri, lease in stale:
                    if kb.registry.is_registered(iri):  # the session too: a restore or an update may have
                        lease.stored = kb.liveness.renew(iri, lease.ttl, registered_by=self._registered_by(session))
                    else:
                        kb.liveness.forget(iri)
                        gone.append(iri)
                if gone:
                    self._changed()
            if gone:
                self._deregistered(dict.fromkeys(gone, session))
                renewed = [iri for iri in renewed if iri not in gone]
        return sorted(renewed)

    def forget_deregistered(self) -> list[str]:
        """End the leases of live components the store no longer registers (``cbrs deregister`` through
        the SPARQL endpoint, any update that removed their description), as :meth:`renew` does at a
        lease's store write: the watchdog asks at once after each store write, so a call's answer that
        comes meanwhile is not taken. Returns the components whose lease ended."""
        with self.sparql.lock:
            with self._guard:
                sessions = {iri: lease.session for iri, lease in self._leases.items()}
            kb = self.sparql.kb
            gone = {iri: session for iri, session in sessions.items() if not kb.registry.is_registered(iri)}
            for iri in gone:
                kb.liveness.forget(iri)
            if gone:
                self._changed()
        self._deregistered(gone)
        return sorted(gone)

    def restate(self) -> list[str]:
        """Write again the liveness of the components this server holds a lease of where the store says
        otherwise: not available, another lease's end or another session. Another's write did that: a
        restore by URL keeps the liveness it read before its write, which takes seconds, so the lease it
        puts back may have ended meanwhile (or be of a session that has since gone); an update of the
        liveness graph. The store is written with the lease's remaining time; a component the store no
        longer registers is left to :meth:`forget_deregistered`. Returns the components written again."""
        return self._restate()[0]

    def look(self) -> list[str]:
        """What :meth:`restate` does, and end the leases of the components whose liveness facts and
        description are both gone (``cbrs deregister`` removes both): the watchdog's look at a store other
        servers write too, every :data:`SHARED_LOOK` seconds. Returns the components whose lease ended."""
        _, unregistered = self._restate()
        if not unregistered:
            return []
        with self._guard:
            sessions = {iri: self._leases[iri].session for iri in unregistered if iri in self._leases}
        self._deregistered(sessions)
        return sorted(sessions)

    def _restate(self) -> tuple[list[str], list[str]]:
        """:meth:`restate`'s writes, and the leased components whose liveness facts are gone and which the
        store no longer registers."""
        written: list[str] = []
        unregistered: list[str] = []
        with self._guard:
            if not self._leases:
                return written, unregistered
        with self.sparql.lock:
            kb = self.sparql.kb
            states = kb.liveness.states()
            now = self._now()
            with self._guard:
                due = [
                    (iri, lease)
                    for iri, lease in self._leases.items()
                    if lease.deadline > now and _misstated(states.get(iri), lease, self._registered_by(lease.session))
                ]
            for iri, lease in due:
                if not kb.registry.is_registered(iri):
                    if iri not in states:
                        unregistered.append(iri)
                    continue
                left = lease.deadline - now
                lease.stored = kb.liveness.renew(iri, left, registered_by=self._registered_by(lease.session))
                lease.written_until = lease.deadline
                written.append(iri)
            if written:
                self._changed()
        if written:
            log.info("%s: the store said otherwise of its lease; written again", ", ".join(written))
        return written, unregistered

    def _changed(self) -> None:
        """Tell the store's listeners of a write of ours (with the store's lock held): our own listener
        does not check it, since a lease write or end changes nothing it looks for."""
        self._own.writing = True
        try:
            self.sparql.changed()
        finally:
            self._own.writing = False

    def _store_written(self) -> None:
        """The store's update listener: after another's write, the leases are stated again at once (before
        that write is answered) and the watchdog looks for deregistrations."""
        if getattr(self._own, "writing", False):
            return
        try:
            self.restate()
        except Exception:  # a listener must not fail the write it hears of
            log.exception("writing the leases again after a store write failed")
        self._written.set()

    def _deregistered(self, gone: dict[str, str]) -> None:
        """Components (with their sessions) found deregistered: their leases end and their calls fail."""
        if not gone:
            return
        with self._guard:
            services = {iri: self._leases.pop(iri).service for iri in gone if iri in self._leases}
        for iri, session in gone.items():
            self._remember_ended(session, [iri], "it was deregistered")
        log.info("%s deregistered: its lease ended", ", ".join(sorted(gone)))
        for iri, service in services.items():  # removed on purpose: its answer would act for nobody
            if self.on_lapse is not None and service:
                self.on_lapse(service, f"<{iri}> was deregistered while {{service!r}} was executing the call")

    def _registered_by(self, session: str) -> str:
        """What the store says registered a component of ``session`` (``cbrs:registeredBy``)."""
        return f"{self.name} session {session}"

    def ended(self, session: str) -> dict[str, str]:
        """The components of ``session`` whose lease ended while it stayed open, with why."""
        with self._guard:
            return dict(self._ended.get(session, {}))

    def _remember_ended(self, session: str, components: list[str], reason: str) -> None:
        with self._guard:
            self._ended.setdefault(session, {}).update(dict.fromkeys(components, reason))
            self._ended.move_to_end(session)
            while len(self._ended) > ENDED_SESSIONS:
                self._ended.popitem(last=False)

    def disconnected(self, session: str) -> None:
        """``session`` closed: its components become unavailable at once."""
        self._end([iri for iri, lease in self._leases_of(session)], "its session closed")
        with self._guard:
            self._ended.pop(session, None)

    def expire_lapsed(self) -> list[str]:
        """End the leases not renewed in time; returns the components made unavailable."""
        now = self._now()
        with self._guard:
            lapsed = [
                (iri, lease.session, lease.service) for iri, lease in self._leases.items() if lease.deadline < now
            ]
        self._end([iri for iri, _, _ in lapsed], "its lease lapsed")
        for iri, session, service in lapsed:
            self._remember_ended(session, [iri], "its lease lapsed")
            if self.on_lapse is not None and service:
                self.on_lapse(service, f"<{iri}>'s lease lapsed while {{service!r}} was executing the call")
        return [iri for iri, _, _ in lapsed]

    def live(self) -> list[str]:
        with self._guard:
            return sorted(self._leases)

    def _now(self) -> float:
        """The time leases are kept in: the clock, less the time this server stood still.

        While the server process does not run (stopped with SIGSTOP, its host suspended, or every thread
        held up by one long call that keeps the GIL) no heartbeat can be read, so the components beating
        all along would find their leases lapsed when it runs again: a gap of more than STALL_PERIODS
        watchdog periods in the server's own timekeeping is not counted against any lease, and the
        leases are written to the store again at their next renewal (other servers read them by time)."""
        with self._guard:
            now = self._clock()
            gap = now - self._seen
            self._seen = now
            if self._watchdog is not None and gap > STALL_PERIODS * self._period:
                self._stood_still += gap - STALL_PERIODS * self._period
                for lease in self._leases.values():
                    lease.written_until = -math.inf
                log.info("this server stood still for %.1f s: the leases are not charged for it", gap)
            return now - self._stood_still

    def _leases_of(self, session: str) -> list[tuple[str, _Lease]]:
        with self._guard:
            return [(iri, lease) for iri, lease in self._leases.items() if lease.session == session]

    def _end(self, components: list[str], reason: str) -> None:
        if not components:
            return
        with self._guard:
            for iri in components:
                self._leases.pop(iri, None)
        with self.sparql.lock:
            for iri in components:
                self.sparql.kb.liveness.expire(iri, reason)
            self._changed()
        log.info("%s unavailable: %s", ", ".join(components), reason)

    # -- the watchdog --------------------------------------------------------------------------

    def start(self) -> None:
        if self._watchdog is None:
            self._stop.clear()
            self._now()  # time kept from here
            self._unwatch = self.sparql.on_update(self._store_written)
            self._watchdog = threading.Thread(target=self._watch, name="cbrs-leases", daemon=True)
            self._watchdog.start()

    def stop(self) -> None:
        self._stop.set()
        self._written.set()
        if self._unwatch is not None:
            self._unwatch()
            self._unwatch = None
        if self._watchdog is not None:
            self._watchdog.join(timeout=5.0)
            self._watchdog = None

    def _watch(self) -> None:
        shared = not isinstance(self.sparql.kb.store, EmbeddedStore)  # other servers write it unheard
        looked = time.monotonic()
        while not self._stop.is_set():
            written = self._written.wait(self._period)
            if self._stop.is_set():
                return
            self._written.clear()  # before the store is read: a write after it wakes the next round
            try:
                self.expire_lapsed()
                if written:
                    self.forget_deregistered()
                if shared and time.monotonic() - looked >= self.shared_look:
                    looked = time.monotonic()
                    self.look()
            except Exception:  # the watchdog must outlive a failed write
                log.exception("ending lapsed or deregistered leases failed")


def _misstated(state: ComponentState | None, lease: _Lease, registered_by: str) -> bool:
    """Whether the store's ``state`` of a component says other than the ``lease`` this server holds."""
    if state is None or not state.live or state.registered_by != registered_by:
        return True
    return lease.stored is not None and state.lease_until != lease.stored


REGISTER_FIELDS = ("description", "format", "ttl")
"""The fields of a ``/cbrs/register`` call."""


def _check_fields(args: dict[str, Any]) -> None:
    """Refuse a field ``/cbrs/register`` does not take: a misspelt ``tll`` would otherwise give the
    component the default lease without a word."""
    unknown = sorted(set(args) - set(REGISTER_FIELDS))
    if unknown:
        close = difflib.get_close_matches(unknown[0], REGISTER_FIELDS, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise ServiceError(
            f"/cbrs/register takes no field {unknown[0]!r} (its fields: {', '.join(REGISTER_FIELDS)}){hint}"
        )


def _check_format(description: str, fmt: str) -> None:
    """Refuse a description sent as the other format, saying so: the parser's own error ("{ is not a
    valid predicate", "Unexpected char: '@'") does not say that the format was the mistake."""
    text = description.lstrip()
    head = text[:1]
    if head == "[":  # a JSON array of objects, or a Turtle blank node ("[ a cbrs:...")
        head = "{" if text[1:].lstrip()[:1] in ("{", "]") else ""
    written = {"{": "json-ld", "@": "turtle", "<": "turtle", "#": "turtle"}.get(head)
    if written is not None and written != fmt:
        raise InvalidDescriptionError(
            "<registration>",
            [
                f"it reads as {written}, not {fmt}: say so (format {written!r} on the bridge, or its Content-Type "
                "over HTTP: text/turtle, application/ld+json)"
            ],
        )


def service_name(name: str) -> str:
    """A service's global name, as the bridge resolves it (``door/open`` -> ``/door/open``)."""
    return name if name.startswith("/") else "/" + name


def _to_turtle(text: str, fmt: ox.RdfFormat) -> str:
    try:
        triples = list(ox.parse(text.encode("utf-8"), format=fmt, base_iri=BASE))
    except SyntaxError as error:
        raise InvalidDescriptionError("<registration>", [f"it is not valid {fmt.name}: {error}"]) from None
    written = ox.serialize(triples, format=ox.RdfFormat.TURTLE)
    assert written is not None  # serialize writes to bytes when given no output
    return written.decode("utf-8")
