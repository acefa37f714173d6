"""Granian's embedded server, run on a thread of the cbrs process: the HTTP listener of ``cbrs serve``.

Granian is a Rust HTTP server: hyper reads and writes the connections on its own threads without the
GIL, and hands each request to an ASGI app (:class:`cbrs.asgi_front.SparqlFront`) on one asyncio loop.
It runs in the same process as the store because it must: an on-disk Oxigraph store admits one
process (RocksDB's lock), and Granian embeds in a process only for ASGI (for WSGI it runs worker
processes). The listener's socket is made before the loop starts, so ``port=0`` gives a known free
port, and :meth:`HttpListener.stop` ends the server from any thread: it stops accepting, the loop
ends, and the port is closed when :meth:`stop` returns.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import resource
import socket
import threading
import time
from dataclasses import dataclass
from typing import Any

from granian._granian import ListenerSpec
from granian.constants import HTTPModes, Interfaces
from granian.http import HTTP1Settings
from granian.log import LogLevels
from granian.server.embed import Server as _Embedded

from cbrs.access_log import ACCESS_LOGGER, AccessLog
from cbrs.settings import EVENT_LOOPS

log = logging.getLogger("cbrs.server")

# Granian's own log records go to the root logger (cbrs serve's format), errors only: its
# default configuration prints every start and stop on stdout, where cbrs serve says it is ready.
# The access log, one line a request at INFO, is cbrs's (cbrs.access_log), on Granian's logger name.
_LOGGING: dict[str, Any] = {
    "version": 1,
    "disable_existing_loggers": False,
    "formatters": {},
    "handlers": {},
    "loggers": {"_granian": {"propagate": True}, "granian.access": {"propagate": True}},
}


@dataclass(frozen=True)
class ListenerConfig:
    """How the listener treats connections (docs/serving.md, "The HTTP front")."""

    host: str = "127.0.0.1"
    port: int = 8080
    io_threads: int = 1  # Rust threads doing the HTTP work; Python runs on the one loop whatever this is
    header_timeout: float = 10.0  # seconds a client may take to send a request's headers
    max_header_bytes: int = 64 * 1024  # what one connection may buffer while its headers are read
    backlog: int = 1024  # connections the kernel holds before Granian accepts them
    # Connections open at once, idle ones included: Granian holds a permit per connection from accept to
    # close, and at 128 (its default) 128 idle sockets from one client kept every other client out
    # until header_timeout closed them (docs/security.md, section 2)
    max_connections: int = 4096
    loop: str = "auto"  # the asyncio loop the app runs on: "uvloop", "asyncio", or "auto" (uvloop when installed)
    access_log: bool = True  # a line a request at INFO (cbrs.access_log), unless the log level leaves INFO out


class _Server(_Embedded):
    """Granian's embedded server with its socket made once, here, and kept: on Linux Granian would
    make one per worker with SO_REUSEPORT, whose port cannot be learnt when it was 0."""

    def _init_shared_socket(self) -> None:
        _refuse_taken(self.bind_addr, self.bind_port)
        holder = ListenerSpec(self.bind_addr, self.bind_port, self.backlog).build()
        self._ssp, self._shd, self._sfd = None, holder, holder.get_fd()  # type: ignore[assignment]


def _refuse_taken(host: str, port: int) -> None:
    """Raise EADDRINUSE when something listens on ``host:port``. Granian's socket sets SO_REUSEPORT, so
    its own bind would succeed beside another server of this user (a second cbrs serve) and the two
    would share the connections; a plain bind first says the port is taken, as waitress's did. Port 0 is
    probed too: a host that is no address of this machine is then an OSError (EADDRNOTAVAIL), where
    Granian's bind raised a RuntimeError with a Rust backtrace."""
    family, kind, proto, _, address = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0]
    with socket.socket(family, kind, proto) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        probe.bind(address)


# Descriptors kept for what is not a client's connection: the store's files, the query workers' pipes,
# the bridge's listener and connections.
_SPARE_DESCRIPTORS = 1024


def _descriptors_for(connections: int) -> int:
    """The connections the listener may hold, ``connections`` if the process may open that many files
    beside its others: the soft limit on open files is raised toward the hard one if needed, and past
    the hard one the count is cut (with a warning), so that a flood of connections meets Granian's
    permit, not a failing ``accept`` or a store that cannot open a file."""
    wanted = connections + _SPARE_DESCRIPTORS
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft != resource.RLIM_INFINITY and soft < wanted:
        raised = wanted if hard == resource.RLIM_INFINITY else min(wanted, hard)
        with contextlib.suppress(ValueError, OSError):
            resource.setrlimit(resource.RLIMIT_NOFILE, (raised, hard))
            soft = raised
    if soft != resource.RLIM_INFINITY and soft < wanted:
        allowed = max(64, soft - _SPARE_DESCRIPTORS)
        log.warning("the limit on open files (%d) allows %d HTTP connections, not %d", soft, allowed, connections)
        return allowed
    return connections


class UnknownLoopError(ValueError):
    """An event loop kind that is none of :data:`cbrs.settings.EVENT_LOOPS`; carries it."""

    def __init__(self, kind: str) -> None:
        super().__init__(f"unknown event loop {kind!r}; use {', '.join(EVENT_LOOPS)}")
        self.kind = kind


def new_loop(kind: str) -> asyncio.AbstractEventLoop:
    """A new event loop of ``kind`` (:attr:`ListenerConfig.loop`). uvloop's is written in C: Granian's
    thread hands each request to the loop with ``call_soon_threadsafe``, which in asyncio's loop is
    Python and a write to a socket pair holding the GIL, in uvloop's a wake-up of libuv; and the loop's
    own turn per request is C, not Python (docs/serving.md, "The HTTP front")."""
    if kind not in EVENT_LOOPS:
        raise UnknownLoopError(kind)
    if kind != "asyncio":
        try:
            import uvloop
        except ImportError:
            if kind == "uvloop":
                raise
        else:
            return uvloop.new_event_loop()
    return asyncio.new_event_loop()


class HttpListener:
    """An ASGI app served by Granian on a thread; start, read :attr:`port`, stop."""

    def __init__(self, app: Any, config: ListenerConfig) -> None:
        self.config = config
        # decided once: a level that leaves INFO out (--log-level warning) costs the requests nothing
        logged = config.access_log and logging.getLogger(ACCESS_LOGGER).isEnabledFor(logging.INFO)
        self.access = AccessLog() if logged else None
        self._server = _Server(
            app if self.access is None else self.access.wrap(app),
            address=config.host,
            port=config.port,
            interface=Interfaces.ASGINL,
            http=HTTPModes.http1,
            websockets=False,  # the rosbridge websocket has its own port and server
            runtime_threads=config.io_threads,
            backlog=config.backlog,
            backpressure=_descriptors_for(config.max_connections),
            http1_settings=HTTP1Settings(
                header_read_timeout=int(config.header_timeout * 1000), max_buffer_size=config.max_header_bytes
            ),
            log_level=LogLevels.error,  # its warning that embedding is "experimental" would greet every start
            log_dictconfig=_LOGGING,
            log_access=False,  # cbrs's own (self.access): Granian's wrote each line on the event loop
        )
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._listening = threading.Event()
        self._failed: BaseException | None = None
        self.port = 0

    def start(self, timeout: float = 10.0) -> None:
        """Listen and serve on a thread; returns once the socket is open, raising OSError if it cannot be."""
        if self.access is not None:
            self.access.start()
        self._thread = threading.Thread(target=self._run, name="cbrs-http", daemon=True)
        self._thread.start()
        if not self._listening.wait(timeout) and self._failed is None:
            self.stop(timeout)
            raise OSError(f"the HTTP listener did not start within {timeout:g} s")
        if self._failed is not None:
            self._thread.join(timeout)
            if self.access is not None:
                self.access.close()  # its thread too: a listener that never started is not stopped
            raise self._failed
        self._await_listen(timeout)

    def _await_listen(self, timeout: float) -> None:
        """Wait until the worker listens on the socket (Granian's start-up returns when it is bound),
        so that whoever hears "ready" can connect."""
        fd: int = self._server._sfd  # type: ignore[assignment]
        deadline = time.monotonic() + timeout
        with socket.socket(fileno=os.dup(fd)) as bound:
            while not bound.getsockopt(socket.SOL_SOCKET, socket.SO_ACCEPTCONN):
                if time.monotonic() > deadline or self._thread is None or not self._thread.is_alive():
                    self.stop(timeout)
                    raise OSError(f"the HTTP listener did not start listening within {timeout:g} s")
                time.sleep(0.001)

    def stop(self, timeout: float = 10.0) -> None:
        """Stop accepting, end the loop and close the port; bounded by ``timeout``."""
        loop, thread = self._loop, self._thread
        if loop is not None and not loop.is_closed():
            with contextlib.suppress(RuntimeError):  # the loop ended meanwhile
                loop.call_soon_threadsafe(self._server.stop)
        if thread is not None:
            thread.join(timeout)
            if thread.is_alive():
                log.warning("the HTTP listener did not stop within %g s", timeout)
        self._thread = None
        if self.access is not None:
            self.access.close()

    def _run(self) -> None:
        loop = new_loop(self.config.loop)
        asyncio.set_event_loop(loop)
        self._loop = loop
        startup = self._server.startup

        def started(*args: Any) -> None:
            try:
                startup(*args)  # type: ignore[no-untyped-call]
                fd: int = self._server._sfd  # type: ignore[assignment]
                with socket.socket(fileno=os.dup(fd)) as bound:
                    self.port = int(bound.getsockname()[1])
            except BaseException as error:
                self._failed = error
                raise
            finally:
                self._listening.set()

        self._server.startup = started  # type: ignore[method-assign]
        try:
            loop.run_until_complete(self._server.serve())
        except BaseException as error:  # a port taken, a host not ours: start() raises it
            if not self._listening.is_set():
                self._failed = error
                self._listening.set()
            elif self._failed is None:  # a failure of start-up is start()'s to raise, not to log as well
                log.exception("the HTTP listener failed")
        finally:
            try:
                loop.run_until_complete(loop.shutdown_asyncgens())
            finally:
                loop.close()
                # Let Granian's objects go now, by reference count, while the interpreter runs: the
                # hook above made a cycle, and a cycle freed at interpreter exit dropped Rust objects
                # that needed it, which aborted the process now and then.
                del self._server.startup
                self._server._shd = None
                self._server.wrks.clear()
