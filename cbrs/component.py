"""Write a component that runs in its own process, and plug it into a running cbrs server.

A component is its six-tuple description (Turtle or JSON-LD) with a service port that names the
rosbridge service doing its work (``cbrs:topic``) and the service's type (``cbrs:messageType``), plus
one handler for that service. ``connect`` opens a bridge session, authenticates with the update
token, provides the service, registers the description and keeps its lease with a heartbeat; the
server then matches, plans and invokes it like any other component. See docs/components.md::

    thermometer = Component(DESCRIPTION)

    @thermometer.handler
    def read(request):
        return {"temperature": {"@type": "home:RoomTemperature", "celsius": 21.5}}

    thermometer.run("ws://127.0.0.1:9090", token=os.environ["CBRS_UPDATE_TOKEN"])
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

import pyoxigraph as ox

from cbrs.bridge_client import BridgeClient, BridgeClosedError, ServiceHandler
from cbrs.kb.errors import InvalidDescriptionError
from cbrs.kb.loader import parse_bytes
from cbrs.kb.namespaces import BASE, GraphName
from cbrs.kb.vocab import CBRS
from cbrs.live_components import DEFAULT_TTL, FORMATS, grounding

__all__ = ["Component", "ConnectedComponent"]

log = logging.getLogger("cbrs.component")

Hook = Callable[[], None]


class Component:
    """One component: its description, the handler of its service, optional start and stop hooks."""

    def __init__(self, description: str, format: str = "turtle") -> None:
        if format not in FORMATS:
            raise ValueError(f"unknown description format {format!r}; use {' or '.join(FORMATS)}")
        self.description = description
        self.format = format
        raw = description.encode("utf-8")
        if format == "turtle":
            quads = parse_bytes(raw, "<component>", ox.RdfFormat.TURTLE, GraphName.SERVICES, BASE).quads
        else:
            quads = [ox.Quad(t.subject, t.predicate, t.object) for t in ox.parse(raw, format=FORMATS[format])]
        named = sorted(
            {
                q.subject.value
                for q in quads
                if q.predicate.value == CBRS.serviceName and isinstance(q.subject, ox.NamedNode)
            }
        )
        if len(named) != 1:
            raise InvalidDescriptionError("<component>", [f"it must describe one component, not {len(named)}"])
        self.iri = named[0]
        found = grounding(quads, self.iri)
        if found is None:
            raise InvalidDescriptionError(
                self.iri, ["it needs a cbrs:ServicePort with the service (cbrs:topic) and its type (cbrs:messageType)"]
            )
        self.service, self.service_type = found
        self._handler: ServiceHandler | None = None
        self._on_start: list[Hook] = []
        self._on_stop: list[Hook] = []

    def handler(self, function: ServiceHandler) -> ServiceHandler:
        """Decorate the function that answers the service: request fields -> response fields."""
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
        """Connect to the bridge at ``url``, provide the service, register and start the heartbeat."""
        if self._handler is None:
            raise ValueError(f"{self.iri} has no handler: decorate one with @component.handler")
        if not 0 < heartbeat < ttl:
            raise ValueError(f"the heartbeat ({heartbeat} s) must be shorter than the lease ({ttl} s)")
        client = BridgeClient(url, token)
        try:
            client.provide(self.service, self.service_type, self._handler)
            answer = client.call_sync(
                "/cbrs/register", {"description": self.description, "format": self.format, "ttl": ttl}
            )
        except BaseException:
            client.close()
            raise
        connected = ConnectedComponent(self, client, heartbeat, list(answer.get("components", [])))
        for hook in self._on_start:
            hook()
        return connected

    def run(self, url: str, token: str | None, heartbeat: float = 1.0, ttl: float = DEFAULT_TTL) -> None:
        """Connect and serve until the connection closes or the process is interrupted."""
        self.connect(url, token, heartbeat, ttl).serve()


class ConnectedComponent:
    """A component serving through a bridge session; ``stop()`` disconnects it (it becomes unavailable)."""

    def __init__(self, component: Component, client: BridgeClient, heartbeat: float, registered: list[str]) -> None:
        self.component = component
        self.client = client
        self.registered = registered
        self.heartbeat = heartbeat
        self._stop = threading.Event()
        self._beat = threading.Thread(target=self._beat_loop, name="cbrs-heartbeat", daemon=True)
        self._beat.start()

    def _beat_loop(self) -> None:
        while not self._stop.wait(self.heartbeat):
            try:
                self.client.call_sync("/cbrs/heartbeat", {}, timeout=self.heartbeat)
            except BridgeClosedError:
                return
            except Exception as error:  # a missed beat is the server's to count, not a reason to stop
                log.warning("heartbeat of %s failed: %s", self.component.iri, error)

    def serve(self) -> None:
        """Serve until the connection closes or the process is interrupted; then stop."""
        try:
            self.client.wait_closed()
        except KeyboardInterrupt:
            pass
        finally:
            self.stop()

    def stop(self) -> None:
        if self._stop.is_set():
            return
        self._stop.set()
        self.client.close()
        self._beat.join(timeout=self.heartbeat + 1.0)
        for hook in self.component._on_stop:
            hook()

    def __enter__(self) -> ConnectedComponent:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
