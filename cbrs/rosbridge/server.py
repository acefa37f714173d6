"""The websocket transport: serve a :class:`Bridge` in an event loop, or in a thread of its own.

Text frames carry rosbridge JSON messages (and binary frames the topic messages a client asked for as
CBOR; a client's binary frame is read as UTF-8 JSON, see ``Bridge.receive``). The websocket's own frame
limit is set well above the bridge's ``max_message_bytes`` (16 MiB, or twice the bridge's limit if that
is larger), so a message that is merely too large gets a status error and the connection stays up;
only a frame beyond the transport limit closes the connection (code 1009, as websockets does).
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import logging
import threading
import time
from collections import Counter
from collections.abc import Callable, Sequence
from typing import Any

from websockets.asyncio.server import ServerConnection
from websockets.asyncio.server import serve as ws_serve
from websockets.exceptions import ConnectionClosed
from websockets.protocol import State
from websockets.typing import Origin

from cbrs.rosbridge.bridge import MIB, Bridge
from cbrs.rosbridge.errors import RosbridgeError
from cbrs.rosbridge.workers import WorkerPool

log = logging.getLogger("cbrs.rosbridge")

#: How long a client has to answer the server's close frame when the server stops.
CLOSE_TIMEOUT = 2.0

#: Frames of one client handled before its reader yields to the other tasks. Frames already buffered are
#: read without yielding, so without a bound a fast publisher could fill its subscribers' queues before
#: their writers send anything; yielding after every frame instead costs a writer wake-up per message.
#: 16 publishers x 16 frames stay well inside a pass-through queue (max_queue_length, 1000).
FRAMES_PER_TURN = 16


def transport_limit(bridge: Bridge) -> int:
    """The websocket frame limit for ``bridge``: above its message limit, so that limit can answer."""
    return max(16 * MIB, 2 * bridge.max_message_bytes)


async def send_frames(websocket: ServerConnection, texts: list[str | bytes]) -> None:
    """Send ``texts`` in order, ``str`` as text frames and ``bytes`` (CBOR) as binary ones, with two
    socket writes instead of one per message.

    All but the last are framed by the connection's own sans-I/O protocol (``send_text`` or
    ``send_binary``, as ``websocket.send`` frames them) and written to the transport joined; the last
    goes through ``websocket.send``, which applies websockets' flow control and raises
    ``ConnectionClosed`` as usual. A connection that is not open gets only that ``send`` (which raises).
    """
    protocol = websocket.protocol
    if len(texts) > 1 and protocol.state is State.OPEN:
        for text in texts[:-1]:
            if isinstance(text, str):
                protocol.send_text(text.encode())
            else:
                protocol.send_binary(text)
        websocket.transport.write(b"".join(protocol.data_to_send()))
    await websocket.send(texts[-1])


def _peer(address: Any) -> str:
    try:
        return f"{address[0]}:{address[1]}"
    except (TypeError, IndexError):
        return str(address)


async def serve(
    bridge: Bridge,
    host: str = "127.0.0.1",
    port: int = 9090,
    *,
    ready: Callable[[int], None] | None = None,
    origins: Sequence[str | None] | None = None,
) -> None:
    """Serve ``bridge`` on ``ws://host:port`` in the running loop until cancelled.

    ``origins``, when given, is the list of ``Origin`` header values a handshake may carry (``None``
    admits clients that send none, as roslibpy and node do); browsers always send one, so this keeps
    pages from other sites off the bridge. Others are refused with HTTP 403.
    """
    await _serve(bridge, host, port, ready, None, origins)


async def _serve(
    bridge: Bridge,
    host: str,
    port: int,
    ready: Callable[[int], None] | None,
    detached: Callable[[list[WorkerPool]], None] | None,
    origins: Sequence[str | None] | None = None,
) -> None:
    loop = asyncio.get_running_loop()
    bridge.attach(loop)
    bound = port
    closing: set[asyncio.Task[None]] = set()
    per_address: Counter[str] = Counter()

    async def connection(websocket: ServerConnection) -> None:
        address = websocket.remote_address
        ip = str(address[0]) if isinstance(address, tuple) and address else str(address)
        if per_address[ip] >= bridge.connections_per_client:
            log.warning("%s: refused, it holds %d connections already", ip, per_address[ip])
            await websocket.close(1013, f"{ip} holds {bridge.connections_per_client} connections already")
            return
        per_address[ip] += 1
        try:
            await _session(websocket, ip)
        finally:
            per_address[ip] -= 1
            if per_address[ip] <= 0:
                del per_address[ip]

    async def _session(websocket: ServerConnection, ip: str) -> None:
        def abort(reason: str) -> None:
            log.warning("%s: disconnected: %s", session.name, reason)
            task = loop.create_task(websocket.close(1008, reason))
            closing.add(task)
            task.add_done_callback(closing.discard)

        session = bridge.open_session(
            _peer(websocket.remote_address),
            websocket.send,
            abort,
            origin=websocket.request.headers.get("Origin") if websocket.request is not None else None,
            address=ip,
            send_many=functools.partial(send_frames, websocket),
        )
        turn = 0
        try:
            async for frame in websocket:
                bridge.receive(session, frame)
                turn += 1
                if turn == FRAMES_PER_TURN:  # let the writers send what this client's frames queued
                    turn = 0
                    await asyncio.sleep(0)
        except ConnectionClosed:
            pass
        finally:
            bridge.close_session(session)

    try:
        async with ws_serve(
            connection,
            host,
            port,
            max_size=transport_limit(bridge),
            compression=None,
            origins=None if origins is None else [None if o is None else Origin(o) for o in origins],
            close_timeout=CLOSE_TIMEOUT,
        ) as server:
            bound = int(server.sockets[0].getsockname()[1])
            log.info("rosbridge serving on ws://%s:%d", host, bound)
            if ready is not None:
                ready(bound)
            await asyncio.Future()  # until cancelled
    finally:
        pools = await bridge.detach()
        if detached is not None:
            detached(pools)
        log.info("rosbridge on %s:%d stopped", host, bound)


class RunningBridge:
    """A bridge served by :func:`start` in a background thread; ``stop`` it (or use it as a context)."""

    def __init__(self, host: str, thread: threading.Thread, state: dict[str, Any]) -> None:
        self.host = host
        self.port: int = state["port"]
        self._thread = thread
        self._state = state

    @property
    def url(self) -> str:
        return f"ws://{self.host}:{self.port}"

    def stop(self, timeout: float = 5.0) -> bool:
        """Close every connection, stop the loop and join its thread and the service and action workers.

        Returns False if something was still running after ``timeout`` seconds (then logged).
        """
        deadline = time.monotonic() + timeout
        loop: asyncio.AbstractEventLoop | None = self._state.get("loop")
        task: asyncio.Task[None] | None = self._state.get("task")
        if loop is not None and task is not None:
            with contextlib.suppress(RuntimeError):  # the loop is already closed
                loop.call_soon_threadsafe(task.cancel)
        self._thread.join(max(0.0, deadline - time.monotonic()))
        if self._thread.is_alive():
            log.warning("rosbridge thread still running after %.1f s", timeout)
            return False
        pools: list[WorkerPool] = self._state.get("workers", [])
        return sum(pool.join(max(0.0, deadline - time.monotonic())) for pool in pools) == 0

    def __enter__(self) -> RunningBridge:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


def start(
    bridge: Bridge,
    host: str = "127.0.0.1",
    port: int = 9090,
    *,
    startup_timeout: float = 10.0,
    origins: Sequence[str | None] | None = None,
) -> RunningBridge:
    """Serve ``bridge`` in a new thread with its own event loop; returns once the port is bound."""
    ready = threading.Event()
    state: dict[str, Any] = {}

    def on_ready(bound: int) -> None:
        state["port"] = bound
        ready.set()

    def on_detached(pools: list[WorkerPool]) -> None:
        state["workers"] = pools

    def main() -> None:
        loop = asyncio.new_event_loop()
        task = loop.create_task(_serve(bridge, host, port, on_ready, on_detached, origins))
        state["loop"], state["task"] = loop, task
        try:
            loop.run_until_complete(task)
        except asyncio.CancelledError:
            pass
        except BaseException as error:
            state["error"] = error
            if ready.is_set():
                log.exception("rosbridge stopped on an error")
        finally:
            ready.set()
            leftovers = asyncio.all_tasks(loop)
            for leftover in leftovers:
                leftover.cancel()
            if leftovers:
                loop.run_until_complete(asyncio.gather(*leftovers, return_exceptions=True))
            loop.run_until_complete(loop.shutdown_asyncgens())
            loop.close()

    thread = threading.Thread(target=main, name=f"cbrs-rosbridge-{host}:{port}", daemon=True)
    thread.start()
    if not ready.wait(startup_timeout):
        running = RunningBridge(host, thread, {**state, "port": port})
        running.stop()
        raise RosbridgeError(f"the rosbridge server did not start within {startup_timeout:g} s")
    if "error" in state:
        thread.join(startup_timeout)
        raise state["error"]
    return RunningBridge(host, thread, state)
