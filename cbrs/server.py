"""``cbrs serve``: the HTTP app on Granian and the rosbridge websocket, over one knowledge base.

Both listen on ``host`` (loopback by default). Each runs in its own thread; :meth:`Server.stop` closes
both and waits for them, so Ctrl-C (or SIGTERM) ends the process cleanly. HTTP is Granian, a Rust
server embedded in this process (:mod:`cbrs.http_listener`), in front of an ASGI app that answers plain
``/sparql`` queries itself and hands every other request to the Flask app (:mod:`cbrs.asgi_front`).
"""

from __future__ import annotations

import logging
import signal
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from cbrs.asgi_front import SparqlFront
from cbrs.bridge_services import KnowledgeServices, attach
from cbrs.http_listener import HttpListener, ListenerConfig
from cbrs.kb import KnowledgeBase
from cbrs.kb.store import EmbeddedStore, StoreDiskError, mark_served
from cbrs.live_components import LiveComponents
from cbrs.matchmakers import Matchmakers
from cbrs.rosbridge import Bridge
from cbrs.rosbridge.rosout import RosoutHandler
from cbrs.settings import setting
from cbrs.sim_sensors import SimSensors
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.stop_signals import StopRequest, handling
from cbrs.tasks import TaskRunner
from cbrs.web import create_app, host_names
from cbrs.web.components import blueprint as components_blueprint
from cbrs.web.context import StreamSlots
from cbrs.web.warmup import warm_up

if TYPE_CHECKING:
    from cbrs.bridge_client import BridgeClient  # its websocket client loads with the first task run

log = logging.getLogger("cbrs.server")
LOGGERS = ("cbrs", "kb", "actions", "reasoner", "sim")
"""The loggers whose records go out on the bridge's /rosout topic."""


@dataclass(frozen=True)
class ServeConfig:
    host: str = "127.0.0.1"
    port: int = 8080
    bridge_port: int = 9090
    endpoint: EndpointConfig = field(default_factory=EndpointConfig)
    cors_origins: Sequence[str] = ()
    server_names: Sequence[str] = ()  # the host names clients reach a routable bind by (the server_names setting)
    http_threads: int = 16  # threads answering requests; the streams have their own on top
    http_io_threads: int = 1  # Granian's Rust threads reading and writing HTTP, off the GIL
    header_timeout: float = 10.0  # seconds a client may take to send a request's headers, then it is dropped
    body_timeout: float = 30.0  # seconds it may take to send a body (held on the loop, not a thread); then 408
    max_connections: int = 4096  # HTTP connections open at once, idle ones included (Granian's permits)
    bodies_per_client: int = 16  # requests of one client whose body is still coming; one more: 503
    unread_per_client: int = 64 * 1024 * 1024  # bytes of answers one client has not read; past them: 503
    send_timeout: float = 30.0  # seconds a client may read nothing of an answer; then it is dropped
    inline_bytes: int = 256 * 1024  # a single scan answered on the loop up to this result size, else on a thread
    http_loop: str = field(default_factory=lambda: setting("http_loop").resolve())  # auto, uvloop or asyncio
    stream_limit: int = field(default_factory=lambda: setting("stream_limit").resolve())
    streams_per_client: int = field(default_factory=lambda: setting("streams_per_client").resolve())
    bridge_connections_per_client: int = field(
        default_factory=lambda: setting("bridge_connections_per_client").resolve()
    )
    action_workers: int = field(default_factory=lambda: setting("action_workers").resolve())
    run_queue: int = field(default_factory=lambda: setting("run_queue").resolve())  # runs that may wait their turn
    bridge_non_finite: str = field(default_factory=lambda: setting("bridge_non_finite").resolve())
    bridge_max_message_bytes: int = field(default_factory=lambda: setting("bridge_max_message_bytes").resolve())
    component_lease: float = field(default_factory=lambda: setting("component_lease").resolve())
    match_params: tuple[str, ...] = field(default_factory=lambda: setting("match_params").resolve())


class Server:
    """The library objects a running cbrs serves, and the two listeners in front of them."""

    def __init__(self, kb: KnowledgeBase, config: ServeConfig | None = None) -> None:
        self.kb = kb
        self.config = config or ServeConfig()
        self.lock = threading.RLock()
        self.sparql = SparqlService(kb, self.config.endpoint, self.lock)
        self.tasks = TaskRunner(kb, self.lock, read_only=self.config.endpoint.read_only, queue=self.config.run_queue)
        endpoint = self.config.endpoint
        token = None if endpoint.read_only else endpoint.update_token
        self.bridge = Bridge(
            token=token,
            reserved=("/cbrs/",),
            connections_per_client=self.config.bridge_connections_per_client,
            action_workers=self.config.action_workers,
            non_finite=self.config.bridge_non_finite,
            max_message_bytes=self.config.bridge_max_message_bytes,
        )
        # one taxonomy index for the pages and the bridge
        self.matchmakers = Matchmakers(self.sparql, tuple(self.config.match_params))
        services = KnowledgeServices(self.sparql, self.tasks, self.matchmakers, self.own_origins)
        self._detach = attach(self.bridge, services)
        self.live = LiveComponents(self.sparql, ttl=self.config.component_lease)
        self.live.provided = lambda name: name in dict(self.bridge.services())  # HTTP registrations need a provider
        self.live.on_lapse = self.bridge.fail_calls  # a late answer of a lapsed component acts on nothing
        for name, (kind, handler) in self.live.handlers().items():
            self.bridge.add_service(name, kind, handler)
        self.bridge.on_disconnect(self.live.disconnected)
        self.bridge.hold_services(self.live.holder)  # a live component's calls go to its own program only
        self.bridge.strict_results(self.live.holds)  # and its `result: false` is a failure, values or not
        self._rosout = RosoutHandler(self.bridge)
        self.tasks.transport = self._own_bridge
        self.sensors = SimSensors()  # /sim/capture, /sim/load: a run's world as devices' hardware
        self.sensors.offer(self.bridge)
        self.tasks.sensors = self.sensors
        self._transport: BridgeClient | None = None
        self.app = create_app(
            self.sparql,
            self.config.cors_origins,
            self.tasks,
            self.matchmakers,
            self.own_origins,
            self.config.server_names,
        )
        self.app.extensions["cbrs.live"] = self.live
        self.app.register_blueprint(components_blueprint)
        self.app.extensions["cbrs.streams"] = StreamSlots(self.config.stream_limit, self.config.streams_per_client)
        self._http: HttpListener | None = None
        self._front: SparqlFront | None = None
        self._names: list[frozenset[str | None] | None] = []
        self._bridge: Any = None

    @property
    def http_port(self) -> int:
        assert self._http is not None, "the server is not listening"
        return self._http.port

    @property
    def bridge_port(self) -> int:
        return int(self._bridge.port)

    def start(self) -> None:
        """Open both listeners (port 0 picks a free port) and serve in background threads."""
        self._front = SparqlFront(
            self.app.wsgi_app,
            self.sparql,
            self._host_names,
            self.app.config["MAX_CONTENT_LENGTH"],
            threads=self.config.http_threads,
            wsgi_threads=self.config.http_threads + self.config.stream_limit,
            inline_bytes=self.config.inline_bytes,
            body_timeout=self.config.body_timeout,
            bodies_per_client=self.config.bodies_per_client,
            unread_per_client=self.config.unread_per_client,
            send_timeout=self.config.send_timeout,
        )
        listener = ListenerConfig(
            host=self.config.host,
            port=self.config.port,
            io_threads=self.config.http_io_threads,
            header_timeout=self.config.header_timeout,
            max_connections=self.config.max_connections,
            loop=self.config.http_loop,
        )
        self._http = HttpListener(self._front, listener)
        try:
            self._http.start()
        except BaseException:
            self._http = None
            self._front.close()
            raise
        try:
            self._bridge = self.bridge.start(self.config.host, self.config.bridge_port, origins=self.bridge_origins())
        except BaseException:
            self._stop_http(5.0)
            raise
        self.live.start()
        if isinstance(self.kb.store, EmbeddedStore) and not self.kb.store.in_memory:
            host = "127.0.0.1" if self.config.host in ("0.0.0.0", "::") else self.config.host
            mark_served(self.kb.store.location, f"http://{host}:{self.http_port}")
            self.kb.store.on_failure = _log_store_failure
        for name in LOGGERS:
            logging.getLogger(name).addHandler(self._rosout)
        warm_up(self.app)  # a big store's first pages: read in the background now (cbrs.web.warmup)

    def _own_bridge(self) -> BridgeClient | None:
        """A connection to this server's own bridge, through which task runs call live components."""
        if self._bridge is None:
            return None
        if self._transport is None or self._transport.closed:
            from cbrs.bridge_client import BridgeClient

            host = "127.0.0.1" if self.config.host in ("0.0.0.0", "::") else self.config.host
            token = self.config.endpoint.update_token
            self._transport = BridgeClient(f"ws://{host}:{self.bridge_port}", token)
        return self._transport

    def own_origins(self) -> frozenset[str]:
        """The origins this server's pages come from: the address it binds, the loopback names and the
        configured server names, on its HTTP port. Never taken from a request, so DNS rebinding cannot
        add one."""
        if self._http is None or not self._http.port:
            return frozenset()
        port = self.http_port
        host = f"[{self.config.host}]" if ":" in self.config.host else self.config.host
        names = {host, "127.0.0.1", "localhost", "[::1]", *self.config.server_names}
        return frozenset(f"http://{name}:{port}" for name in names)

    def bridge_origins(self) -> list[str | None]:
        """Who may open the websocket: clients that send no Origin (roslibpy, node, a microcontroller),
        pages served by this server itself, and the CORS origins; other web pages get 403."""
        return [None, *sorted(self.own_origins()), *self.config.cors_origins]

    def stop(self, timeout: float = 10.0) -> None:
        """Close both listeners and their connections; a task run still going gets ``timeout`` to end."""
        self.app.extensions["cbrs.closing"].set()  # event and camera streams end within half a second
        self.live.stop()
        if isinstance(self.kb.store, EmbeddedStore) and not self.kb.store.in_memory:
            mark_served(self.kb.store.location, None)
        for name in LOGGERS:
            logging.getLogger(name).removeHandler(self._rosout)
        if self._transport is not None:
            self._transport.close()
            self._transport = None
        if self._bridge is not None:
            self._bridge.stop(timeout)
            self._bridge = None
        self._stop_http(timeout)
        self._detach()
        self.tasks.close(timeout)
        self.sparql.close()

    def serve_forever(self, ready: Callable[[Server], None] | None = None) -> None:
        """Start, report through ``ready``, and serve until SIGINT or SIGTERM; then stop."""
        request = StopRequest()
        try:
            with handling(request, signal.SIGINT, signal.SIGTERM):
                self.start()
                if ready is not None:
                    ready(self)
                request.wait()
        finally:
            self.stop()

    def _host_names(self) -> frozenset[str | None] | None:
        """The names a request's Host may give (cbrs.web.host_names), fixed once the port is known."""
        if self._names:
            return self._names[0]
        own = self.own_origins()
        names = host_names(own, frozenset(self.config.cors_origins), frozenset(self.config.server_names))
        if own and self._http is not None and self._http.port:
            self._names.append(names)
        return names

    def _stop_http(self, timeout: float) -> None:
        if self._http is None:
            return
        listener, self._http = self._http, None
        listener.stop(timeout)
        if self._front is not None:
            self._front.close()
            self._front = None


def _log_store_failure(error: StoreDiskError) -> None:
    """The first of a run of disk errors (a full disk): the client whose write failed is told, the log
    is the administrator's (docs/serving.md, "Logs")."""
    log.error("%s", error)
