"""Write a component that runs in its own process, and plug it into a running cbrs server.

A component is its six-tuple description (Turtle or JSON-LD) with a service port that names the
rosbridge service doing its work (``cbrs:topic``) and the service's type (``cbrs:messageType``), plus
one handler for that service. ``connect`` opens a bridge session, authenticates with the update
token, registers the description, then provides the service (in that order, so a refused
registration, a second copy of a running program say, provides nothing and takes no other
program's calls) and keeps its lease with a heartbeat, registering again if the lease lapsed; the
server then matches, plans and invokes it like any other component. See docs/components.md::

    thermometer = Component(DESCRIPTION)

    @thermometer.handler
    def read(request):
        return {"roomTemperature": {"@type": "home:RoomTemperature", "celsius": 21.5}}

    thermometer.run("ws://127.0.0.1:9090", token=os.environ["CBRS_UPDATE_TOKEN"])
"""

from __future__ import annotations

import inspect
import logging
import math
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from typing import Any
from urllib.parse import urlsplit

import pyoxigraph as ox

from cbrs.actions.remote_errors import RemoteCallError
from cbrs.bridge_client import BridgeClient, BridgeClosedError, ServiceHandler
from cbrs.component_protocol import DEFAULT_TTL, DEREGISTERED, FORMATS, NO_LIVE_COMPONENT, UNPROVIDED, grounding
from cbrs.kb.errors import InvalidDescriptionError
from cbrs.kb.namespaces import BASE, RDF, GraphName, shorten
from cbrs.kb.vocab import CBRS
from cbrs.stop_signals import POLL, StopRequest, handling

__all__ = ["Component", "ComponentEndedError", "ConnectedComponent", "RegistrationRefusedError"]

log = logging.getLogger("cbrs.component")

Hook = Callable[[], None]
_Beats = deque[tuple[float, Future[dict[str, Any]]]]
"""Heartbeats waiting for their answers: when each was sent, and its answer."""

HEARTBEAT = "/cbrs/heartbeat"
REGISTER = "/cbrs/register"
REREGISTER_ATTEMPTS = 5
"""Registrations tried after the server says the lease is gone, before the component gives up."""
REREGISTER_BACKOFF = 2.0
"""Each failed try waits this many times longer than the one before (from one heartbeat period)."""


class RegistrationRefusedError(RemoteCallError):
    """The server refused the component's registration; ``reason`` is the server's own words."""

    def __init__(self, component: str, reason: str) -> None:
        self.component, self.reason = component, reason
        super().__init__(f"{shorten(component)} was not registered: {reason}")


class ComponentEndedError(ConnectionError):
    """A connected component ended without being stopped: the server closed its connection (it stopped
    or restarted), deregistered it, or it could not register again; ``reason`` says which."""

    def __init__(self, component: str, reason: str) -> None:
        self.component, self.reason = component, reason
        super().__init__(f"{shorten(component)} stopped serving: {reason}")


class Component:
    """One component: its description, the handler of its service, optional start and stop hooks."""

    def __init__(self, description: str, format: str = "turtle") -> None:
        if format not in FORMATS:
            raise ValueError(f"unknown description format {format!r}; use {' or '.join(FORMATS)}")
        self.description = description
        self.format = format
        quads = _quads(description.encode("utf-8"), format)
        named = sorted(
            {
                q.subject.value
                for q in quads
                if q.predicate.value == CBRS.serviceName and isinstance(q.subject, ox.NamedNode)
            }
        )
        if not named:
            raise InvalidDescriptionError(
                "<component>", ["it describes no component (a subject with cbrs:serviceName)"]
            )
        if len(named) > 1:  # one handler each: an on and an off switch are two Components in one program
            names = ", ".join(shorten(iri) for iri in named)
            raise InvalidDescriptionError(
                "<component>",
                [
                    f"it must describe one component, not {len(named)} ({names}): give each a Component of its "
                    "own; one program serves several (connect() each but the last, run() that one)"
                ],
            )
        self.iri = named[0]
        found = grounding(quads, self.iri)
        if found is None:
            hints = "".join(f"; {hint}" for hint in _grounding_slips(quads))
            raise InvalidDescriptionError(
                self.iri,
                ["it needs a cbrs:ServicePort with the service (cbrs:topic) and its type (cbrs:messageType)" + hints],
            )
        self.service, self.service_type = found
        self._handler: ServiceHandler | None = None
        self._on_start: list[Hook] = []
        self._on_stop: list[Hook] = []

    def handler(self, function: ServiceHandler) -> ServiceHandler:
        """Decorate the function that answers the service: request fields -> response fields."""
        try:
            inspect.signature(function).bind({})
        except ValueError:  # no signature to read (some builtins): its first call will tell
            pass
        except TypeError as error:  # said now, not as the first call's failure on the caller's side
            raise TypeError(
                f"the handler of {self.service} must take one argument, the request's fields "
                f"(def read(request): ...): {error}"
            ) from None
        self._handler = function
        return function

    def on_start(self, hook: Hook) -> Hook:
        """Decorate a function called once connected and registered."""
        self._on_start.append(hook)
        return hook

    def on_stop(self, hook: Hook) -> Hook:
        """Decorate a function called when the component disconnects."""
        self._on_stop.append(hook)
        return hook

    def connect(
        self, url: str, token: str | None, heartbeat: float = 1.0, ttl: float = DEFAULT_TTL
    ) -> ConnectedComponent:
        """Connect to the bridge at ``url``, register, provide the service and start the heartbeat.

        Raises :class:`RegistrationRefusedError` with the server's reason when it refuses the
        registration; nothing was provided then, so a refused second copy harms the first. An
        ``on_start`` hook that raises disconnects the component (it is unavailable at once, and no
        ``on_stop`` hook runs) before its error propagates."""
        return self._connect(url, token, heartbeat, ttl, StopRequest())

    def _connect(
        self, url: str, token: str | None, heartbeat: float, ttl: float, stop: StopRequest
    ) -> ConnectedComponent:
        """:meth:`connect`, giving up with :class:`_Stopped` (nothing provided, no hook run) once ``stop``
        notes a signal before the on_start hooks begin."""
        if self._handler is None:
            raise ValueError(f"{self.iri} has no handler: decorate one with @component.handler")
        if not 0 < heartbeat < ttl:
            raise ValueError(f"the heartbeat ({heartbeat} s) must be shorter than the lease ({ttl} s)")
        client = _bridge_client(url, token)
        try:
            registered = self._register(client, ttl, token_given=token is not None, stop=stop)
            if stop.signal is not None:
                raise _Stopped
            client.provide(self.service, self.service_type, self._handler)
        except BaseException:
            client.close()
            raise
        connected = ConnectedComponent(self, client, heartbeat, registered, ttl)
        try:
            for hook in self._on_start:
                hook()
        except BaseException:  # a component that did not start must not serve: its session closes
            connected._close()
            raise
        return connected

    def _register(
        self, client: BridgeClient, ttl: float, token_given: bool = True, stop: StopRequest | None = None
    ) -> list[str]:
        args = {"description": self.description, "format": self.format, "ttl": ttl}
        try:
            answer = _answer(client.call(REGISTER, args, client.timeout), client.timeout, stop)
        except RemoteCallError as error:
            reason = _servers_reason(client, str(error))
            if not token_given and "needs the update token" in reason:  # the protocol's words; the SDK's own fix
                # (the server goes on to tell a hand-written client to send the auth op, which the SDK does itself)
                reason = (
                    "registering a component needs the update token, and this component was given none (token=None): "
                    "pass the token cbrs serve was started with, e.g. token=os.environ['CBRS_UPDATE_TOKEN']"
                )
            raise RegistrationRefusedError(self.iri, reason) from None
        return list(answer.get("components", []))

    def run(self, url: str, token: str | None, heartbeat: float = 1.0, ttl: float = DEFAULT_TTL) -> None:
        """Connect and serve until the process is interrupted (Ctrl-C, SIGTERM): then the on_stop hooks
        run and this returns. When the component cannot serve (its registration refused, the server
        gone or restarted, the component deregistered) the process exits with status 1 and the reason,
        so a supervisor (systemd ``Restart=on-failure``, a container's restart policy) starts it again."""
        request = StopRequest()  # taken for the whole run: a signal never raises between two statements
        try:
            with handling(request, signal.SIGTERM, signal.SIGINT):
                connected = self._connect(url, token, heartbeat, ttl, request)
                # a program started in the background otherwise says nothing until it ends
                print(
                    f"cbrs component: {shorten(self.iri)} registered at {url}; serving {self.service} "
                    "until Ctrl-C or SIGTERM",
                    file=sys.stderr,
                    flush=True,
                )
                connected._serve(request)
        except _Stopped:  # stopped while connecting: nothing was provided, no hook ran
            pass
        except (RegistrationRefusedError, ComponentEndedError, BridgeClosedError) as error:
            raise SystemExit(f"cbrs component: {error}") from None  # printed on stderr, status 1


def _bridge_client(url: str, token: str | None) -> BridgeClient:
    """A client of the bridge at ``url``. Refused at a URL with no port, which tried the scheme's port (80
    for ws://), the error says so and names the bridge's default port: "connection refused" alone does not."""
    try:
        return BridgeClient(url, token)
    except BridgeClosedError as error:
        if not isinstance(error.__cause__, ConnectionRefusedError) or _port_of(url) is not None:
            raise
        from cbrs.settings import setting  # here: only a refused connection needs the default

        default = setting("bridge_port").default()
        tried = 443 if url.lower().startswith("wss:") else 80
        raise BridgeClosedError(
            f"{error}. {url} names no port, so port {tried} was tried; cbrs serve's bridge listens on port "
            f"{default} by default (--bridge-port): give ws://HOST:{default}"
        ) from error


def _port_of(url: str) -> int | None:
    """The port ``url`` names; None when it names none, -1 when it cannot be read (then no advice is given)."""
    try:
        return urlsplit(url).port
    except ValueError:
        return -1


class ConnectedComponent:
    """A component serving through a bridge session; ``stop()`` disconnects it (it becomes unavailable)."""

    def __init__(
        self,
        component: Component,
        client: BridgeClient,
        heartbeat: float,
        registered: list[str],
        ttl: float = DEFAULT_TTL,
    ) -> None:
        self.component = component
        self.client = client
        self.registered = registered
        self.heartbeat = heartbeat
        self.ttl = ttl
        self.ended: str | None = None
        """Why the component ended by itself (None while it serves or after ``stop()``)."""
        self._stop = threading.Event()
        self._registered_at = time.monotonic()  # beats sent before it speak of an older registration
        self._unanswered_since: float | None = None  # sent time of the oldest beat failed since one was answered
        self._warned = False
        self._beat = threading.Thread(target=self._beat_loop, name="cbrs-heartbeat", daemon=True)
        self._beat.start()

    def _beat_loop(self) -> None:
        """Beat every ``heartbeat`` seconds on a fixed schedule, whatever the server's answers take.

        A beat is not waited for before the next is sent: a server busy with a simulation may answer
        after more than a heartbeat, and it renews the lease when it reads the beat, not when the
        answer arrives. Waiting for each answer (as this loop once did, for at most one heartbeat)
        stretched the period to twice the heartbeat, two thirds of the default lease, and logged a
        warning for each slow answer although the lease held. Answers are read in the order sent; at
        most a lease's worth of beats wait at once."""
        beats: _Beats = deque()
        in_flight = max(2, math.ceil(self.ttl / self.heartbeat) + 1)
        due = time.monotonic()
        try:
            while True:
                now = time.monotonic()
                due = max(due + self.heartbeat, now)  # after a hang, one beat now rather than a burst
                if self._stop.wait(due - now) or not self._read_answers(beats):
                    return
                if len(beats) < in_flight:
                    beats.append((time.monotonic(), self.client.call(HEARTBEAT, {}, timeout=self.ttl)))
                self._watch_unanswered(beats)
        except Exception as error:  # a dead heartbeat would lapse the lease for good: end loudly instead
            log.exception("the heartbeat of %s broke", self.component.iri)
            self._end(f"its heartbeat broke: {type(error).__name__}: {error}")

    def _read_answers(self, beats: _Beats) -> bool:
        """Act on the beats answered so far, oldest first; False when the component ends."""
        while beats and beats[0][1].done():
            sent, answer = beats.popleft()
            try:
                answer.result()
            except BridgeClosedError:
                return False
            except RemoteCallError as error:
                text = str(error)
                if DEREGISTERED in text:
                    self._end(f"the server says {text}; start the program again to register it again")
                    return False
                if UNPROVIDED in text:  # nobody answers its service: registering again would not help
                    self._end(f"the server says {text}")
                    return False
                if NO_LIVE_COMPONENT in text:
                    if sent < self._registered_at:
                        continue  # it speaks of the registration before the last one
                    beats.clear()  # all sent before registering again: their answers say the same
                    return self._register_again(text)
                self._unanswered_since = min(self._unanswered_since or sent, sent)
                if not text.startswith(f"service {HEARTBEAT!r} did not answer within"):
                    log.warning("heartbeat of %s failed: %s", self.component.iri, text)
            except Exception as error:  # a missed beat is the server's to count, not a reason to stop
                self._unanswered_since = min(self._unanswered_since or sent, sent)
                log.warning("heartbeat of %s failed: %s", self.component.iri, error)
            else:
                if self._warned:
                    log.warning("heartbeats of %s are answered again", self.component.iri)
                self._unanswered_since, self._warned = None, False
        return True

    def _watch_unanswered(self, beats: _Beats) -> None:
        """Warn once when no beat has been answered for half the lease: the lease lapses if it goes on."""
        waiting = [sent for sent in (self._unanswered_since, beats[0][0] if beats else None) if sent is not None]
        if not waiting or self._warned:
            return
        silent = time.monotonic() - min(waiting)
        if silent > self.ttl / 2:
            self._warned = True
            log.warning(
                "no heartbeat of %s answered for %.1f s (its lease lasts %g s): the server is busy or unreachable;"
                " the lease lapses if this goes on",
                self.component.iri,
                silent,
                self.ttl,
            )

    def _register_again(self, why: str) -> bool:
        """The lease is gone (the program hung, the network dropped): register again, a bounded number of
        times with growing waits; give up (end the component) if none is accepted."""
        log.warning("%s lost its registration (%s): registering again", self.component.iri, why)
        wait = self.heartbeat
        for attempt in range(1, REREGISTER_ATTEMPTS + 1):
            try:
                self.registered = self.component._register(self.client, self.ttl)
            except BridgeClosedError:
                return False
            except Exception as error:
                log.warning(
                    "registering %s again failed (try %d of %d): %s",
                    self.component.iri,
                    attempt,
                    REREGISTER_ATTEMPTS,
                    error,
                )
                if attempt == REREGISTER_ATTEMPTS:
                    self._end(f"it could not register again after {attempt} tries: {error}")
                    return False
                if self._stop.wait(wait):
                    return False
                wait *= REREGISTER_BACKOFF
            else:
                self._registered_at = time.monotonic()
                self._unanswered_since, self._warned = None, False
                log.warning("%s registered again (try %d)", self.component.iri, attempt)
                return True
        return False

    def _end(self, reason: str) -> None:
        """End the component from the heartbeat thread; ``serve`` then raises :class:`ComponentEndedError`."""
        self.ended = reason
        self.client.close()

    def serve(self) -> None:
        """Serve until the process is interrupted (Ctrl-C or SIGTERM, when called in the main thread) or
        the connection ends; then stop (the on_stop hooks run). Raises :class:`ComponentEndedError` when
        the component ended without being stopped: the server closed the connection, say."""
        request = StopRequest()
        with handling(request, signal.SIGTERM, signal.SIGINT):
            self._serve(request)

    def _serve(self, request: StopRequest) -> None:
        try:
            request.wait(until=self.client.wait_closed)
        except KeyboardInterrupt:  # Ctrl-C where no handler of ours took SIGINT (serve() outside the main thread)
            pass
        finally:
            ended = not self._stop.is_set() and (self.ended is not None or self.client.closed_by_server)
            self.stop()
        if ended:
            reason = self.ended or f"the server closed the connection ({self.client.close_reason})"
            raise ComponentEndedError(self.component.iri, reason)

    def stop(self) -> None:
        if self._close():
            for hook in self.component._on_stop:
                hook()

    def _close(self) -> bool:
        """Disconnect (the server marks the component unavailable at once); False if already done."""
        if self._stop.is_set():
            return False
        self._stop.set()
        self.client.close()
        if self._beat is not threading.current_thread():
            self._beat.join(timeout=self.heartbeat + 1.0)
        return True

    def __enter__(self) -> ConnectedComponent:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


class _Stopped(Exception):
    """A stop signal arrived while the component was connecting (:meth:`Component.run`)."""


def _answer(answer: Future[dict[str, Any]], timeout: float, stop: StopRequest | None) -> dict[str, Any]:
    """The answer within ``timeout``; looked at every :data:`POLL` seconds so that a stop signal noted in
    ``stop`` meanwhile ends the wait (with :class:`_Stopped`) instead of the call's timeout."""
    if stop is None:
        return answer.result(timeout=timeout + 1.0)
    deadline = time.monotonic() + timeout + 1.0
    while True:
        if stop.signal is not None:
            raise _Stopped
        try:
            return answer.result(timeout=min(POLL, max(0.0, deadline - time.monotonic())))
        except FutureTimeout:
            if time.monotonic() >= deadline:
                raise


def _servers_reason(client: BridgeClient, refusal: str) -> str:
    """The server's refusal, with the reason it gave for refusing the token when that was the cause (a
    wrong token is answered on the auth op; the registration only sees an unauthorised session)."""
    refused = [
        str(status.get("msg", ""))
        for status in client.statuses
        if status.get("level") == "error" and str(status.get("msg", "")).startswith("auth")
    ]
    if not refused:
        return refusal
    # the refusal itself tells a hand-written client to send the auth op, which the SDK did: the token is wrong
    return f"{refused[-1]}: give the component the token cbrs serve was started with (CBRS_UPDATE_TOKEN)"


def _quads(raw: bytes, format: str) -> list[ox.Quad]:
    """The description's triples, for finding its component and service port.

    A Turtle description that Oxigraph parses as it is is read here; only one it refuses (or with NUL
    bytes, which the loader refuses) goes through the loader (:func:`cbrs.kb.loader.parse_bytes`), whose
    error names the line and the fault, as it did when every description went that way. The loader's
    other work (blank nodes named, the graph set) only matters to a store, and importing it would
    bring the store, the shapes and the SPARQL queries into every component's program. The server
    validates the whole description again when it registers it."""
    if format != "turtle":
        return [ox.Quad(t.subject, t.predicate, t.object) for t in ox.parse(raw, format=FORMATS[format])]
    if b"\x00" not in raw:
        try:
            return list(ox.parse(raw, format=ox.RdfFormat.TURTLE, base_iri=BASE))
        except (SyntaxError, ValueError):
            pass
    from cbrs.kb.loader import parse_bytes  # here: only a faulty description needs the loader

    return parse_bytes(raw, "<component>", ox.RdfFormat.TURTLE, GraphName.SERVICES, BASE).quads


def _grounding_slips(quads: list[ox.Quad]) -> list[str]:
    """Did-you-means (the shapes' own) for a service port the description misspelt: a property near
    cbrs:topic, cbrs:messageType or cbrs:hasPort, a class near cbrs:ServicePort."""
    from cbrs.kb.shapes import nearest_term  # here: only a faulty description needs the shapes

    wanted = [CBRS.topic, CBRS.messageType, CBRS.hasPort]
    slips = set()
    for quad in quads:
        used = quad.predicate.value
        if used not in wanted:
            near = nearest_term(used, wanted)
            if near is not None:
                slips.add(f"{shorten(used)}: did you mean {shorten(near)}?")
        if used == RDF + "type" and isinstance(quad.object, ox.NamedNode) and quad.object.value != CBRS.ServicePort:
            near = nearest_term(quad.object.value, [CBRS.ServicePort])
            if near is not None:
                slips.add(f"{shorten(quad.object.value)}: did you mean {shorten(near)}?")
    return sorted(slips)
