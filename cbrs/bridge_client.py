"""A rosbridge v2 client for Python programs: call services, provide services, publish.

One websocket, one reader thread. ``call`` returns a future (it is the executor's
:class:`~actions.remote.Transport`); ``provide`` answers calls from the server with a handler run on a
small thread pool, so a slow handler does not hold up the connection. The component SDK
(:mod:`cbrs.component`) and the executor's remote components are built on it.
"""

from __future__ import annotations

import contextlib
import itertools
import json
import logging
import threading
from collections import deque
from collections.abc import Callable, Mapping
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any

from websockets.exceptions import ConnectionClosed, InvalidHandshake, InvalidURI
from websockets.sync.client import ClientConnection, connect

from cbrs.actions.remote_errors import RemoteCallError

__all__ = ["AdvertiseRefusedError", "BridgeClient", "BridgeClosedError", "HandlerAnswerError", "ServiceHandler"]

log = logging.getLogger("cbrs.bridge_client")

STATUSES_KEPT = 100
"""Status messages a client keeps (a long-running component must not grow without bound)."""

ServiceHandler = Callable[[dict[str, Any]], Mapping[str, Any]]
"""A provided service: the request's fields -> the response's fields (raise to answer result: false)."""


class BridgeClosedError(ConnectionError):
    """The connection to the bridge is closed; calls waiting on it fail with this."""


class AdvertiseRefusedError(RuntimeError):
    """The bridge refused to let this client provide ``service``; ``reason`` is the bridge's."""

    def __init__(self, service: str, reason: str) -> None:
        self.service, self.reason = service, reason
        super().__init__(f"the bridge refused to let this client provide {service}: {reason}")


class BridgeClient:
    """A connection to a rosbridge server (``ws://host:port``), optionally authorised with ``token``."""

    def __init__(self, url: str, token: str | None = None, timeout: float = 10.0, workers: int = 4) -> None:
        self.url = url
        self.timeout = timeout
        self._exit = contextlib.ExitStack()
        try:
            self._socket: ClientConnection = self._exit.enter_context(
                connect(url, open_timeout=timeout, max_size=16 << 20)
            )
        except (OSError, TimeoutError) as error:
            raise BridgeClosedError(f"cannot reach the bridge at {url}: {error}") from error
        except InvalidURI:
            raise BridgeClosedError(
                f"{url} is not a websocket URL: give the bridge as ws://HOST:PORT (cbrs serve's --bridge-port, 9090"
                " by default)"
            ) from None
        except InvalidHandshake as error:  # something answered, but no websocket: the HTTP port, say
            raise BridgeClosedError(
                f"{url} is no rosbridge websocket ({error}): is it cbrs serve's HTTP port? Its bridge is on"
                " --bridge-port, 9090 by default, as cbrs serve prints on start"
            ) from None
        self._send_lock = threading.Lock()
        self._ids = itertools.count(1)
        self._waiting: dict[str, Future[dict[str, Any]]] = {}
        self._handlers: dict[str, ServiceHandler] = {}
        self._listeners: dict[str, list[Callable[[dict[str, Any]], None]]] = {}
        self._pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="cbrs-provide")
        self._closed = threading.Event()
        self._closing = False  # close() was called: the end is this client's, not the server's
        self.close_reason: str | None = None
        """Why the connection closed, once it has."""
        self.statuses: deque[dict[str, Any]] = deque(maxlen=STATUSES_KEPT)
        """The last status messages the server sent (its errors and warnings about this client's ops);
        each error is also logged as a warning, since it means a message of ours was refused (a service
        response too large or malformed, say) and its caller got a failure in our place."""
        self._reader = threading.Thread(target=self._read, name="cbrs-bridge-reader", daemon=True)
        self._reader.start()
        if token is not None:
            self.send({"op": "auth", "mac": token})

    # -- life cycle ---------------------------------------------------------------------------------

    @property
    def closed(self) -> bool:
        return self._closed.is_set()

    def close(self) -> None:
        """Close the connection; calls still waiting fail with :class:`BridgeClosedError`."""
        self._closing = True
        self._exit.close()
        self._reader.join(timeout=self.timeout)
        self._shutdown("the connection was closed by this client")

    def __enter__(self) -> BridgeClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def closed_by_server(self) -> bool:
        """Whether the connection ended from the server's side (it stopped, restarted or dropped us)."""
        return self.closed and not self._closing

    def wait_closed(self, timeout: float | None = None) -> bool:
        return self._closed.wait(timeout)

    # -- calls --------------------------------------------------------------------------------------

    def call(self, service: str, args: Mapping[str, Any], timeout: float | None = None) -> Future[dict[str, Any]]:
        """Call ``service``; the future gets the response's values, or raises :class:`RemoteCallError`
        (the service answered ``result: false``) or :class:`BridgeClosedError`."""
        future: Future[dict[str, Any]] = Future()
        if self.closed:
            future.set_exception(BridgeClosedError(f"the connection to {self.url} is closed"))
            return future
        key = f"call:{service}:{next(self._ids)}"
        self._waiting[key] = future
        message: dict[str, Any] = {"op": "call_service", "id": key, "service": service, "args": dict(args)}
        if timeout is not None:
            message["timeout"] = timeout
        try:
            self.send(message)
        except BridgeClosedError as error:
            if self._waiting.pop(key, None) is not None:  # else the reader's shutdown failed it already
                future.set_exception(error)
        return future

    def call_sync(self, service: str, args: Mapping[str, Any], timeout: float | None = None) -> dict[str, Any]:
        """Call ``service`` and wait for the answer (at most ``timeout``, the client's by default)."""
        wait = timeout if timeout is not None else self.timeout
        return self.call(service, args, wait).result(timeout=wait + 1.0)

    # -- providing ----------------------------------------------------------------------------------

    def provide(self, service: str, service_type: str, handler: ServiceHandler) -> None:
        """Advertise ``service`` and answer the server's calls to it with ``handler``."""
        self._handlers[service] = handler
        self.send({"op": "advertise_service", "service": service, "type": service_type})

    def advertise(self, service: str, service_type: str, handler: ServiceHandler) -> None:
        """:meth:`provide`, and wait until the bridge has read the advertisement: AdvertiseRefusedError
        with its reason if it refused it (the server provides the service itself, say)."""
        key = f"advertise:{service}:{next(self._ids)}"
        self._handlers[service] = handler
        self.send({"op": "advertise_service", "id": key, "service": service, "type": service_type})
        # the bridge answers one client's messages in order: once this call is answered, a refusal of the
        # advertisement (a status with its id) has arrived before it
        self.call_sync("/rosapi/get_time", {})
        for status in list(self.statuses):
            if status.get("id") == key and status.get("level") == "error":
                self._handlers.pop(service, None)
                raise AdvertiseRefusedError(service, str(status.get("msg")))

    def withdraw(self, *services: str) -> None:
        """Stop providing ``services`` and wait until the bridge has read that (at most the client's
        timeout); nothing if the connection has closed, as the bridge has dropped them then."""
        for service in services:
            self._handlers.pop(service, None)
        with contextlib.suppress(BridgeClosedError, RemoteCallError, TimeoutError):
            for service in services:
                self.send({"op": "unadvertise_service", "service": service})
            self.call_sync("/rosapi/get_time", {})

    def publish(self, topic: str, msg: Mapping[str, Any]) -> None:
        self.send({"op": "publish", "topic": topic, "msg": dict(msg)})

    def subscribe(self, topic: str, callback: Callable[[dict[str, Any]], None]) -> None:
        """Call ``callback(msg)`` (on the reader thread) for each message on ``topic``."""
        self._listeners.setdefault(topic, []).append(callback)
        self.send({"op": "subscribe", "topic": topic})

    # -- the wire -----------------------------------------------------------------------------------

    def send(self, message: Mapping[str, Any]) -> None:
        text = json.dumps(message, separators=(",", ":"))
        with self._send_lock:
            try:
                self._socket.send(text)
            except ConnectionClosed as error:
                raise BridgeClosedError(f"the connection to {self.url} is closed") from error

    def _read(self) -> None:
        reason = f"the connection to {self.url} closed"
        try:
            while True:
                frame = self._socket.recv()
                try:
                    message = json.loads(frame)
                except ValueError:
                    log.warning("the bridge sent a frame that is not JSON")
                    continue
                if isinstance(message, dict):
                    self._dispatch(message)
        except ConnectionClosed as error:
            self.close_reason = str(error)  # the close frames: "received 1001 (going away); ..."
            reason += f" ({error})"
        finally:
            self._shutdown(reason)

    def _dispatch(self, message: dict[str, Any]) -> None:
        op = message.get("op")
        if op == "service_response":
            future = self._waiting.pop(str(message.get("id")), None)
            if future is None or future.done():
                return
            values = message.get("values")
            if message.get("result", False) is True:
                future.set_result(values if isinstance(values, dict) else {"values": values})
            else:
                future.set_exception(RemoteCallError(str(values)))
        elif op == "call_service":
            self._pool.submit(self._answer, message)
        elif op == "status":
            self.statuses.append(message)
            if message.get("level") == "error":  # the server refused one of our messages: say so here
                log.warning("the bridge at %s refused a message of this client: %s", self.url, message.get("msg"))
        elif op == "publish":
            msg = message.get("msg")
            for listener in self._listeners.get(str(message.get("topic")), []):
                if isinstance(msg, dict):
                    listener(msg)

    def _answer(self, message: dict[str, Any]) -> None:
        service = str(message.get("service", ""))
        handler = self._handlers.get(service)
        args = message.get("args")
        reply: dict[str, Any] = {"op": "service_response", "service": service, "id": message.get("id")}
        try:
            if handler is None:
                raise LookupError(f"this client does not provide {service}")
            if isinstance(args, list) and args:  # rosbridge's positional form: no field names to give them
                raise TypeError(f"{service} takes its args as an object of named fields, not the list {args!r:.80}")
            values = _response(service, handler(args if isinstance(args, dict) else {}))
            reply |= {"result": True, "values": values}
        except Exception as error:  # the handler's failure is the call's answer, not this client's crash
            log.exception("the handler of %s failed; the call is answered with the error", service)
            reply |= {"result": False, "values": f"{type(error).__name__}: {error}"}
        with contextlib.suppress(BridgeClosedError):
            self.send(reply)

    def _shutdown(self, reason: str) -> None:
        if self._closed.is_set():
            return
        if self.close_reason is None:
            self.close_reason = reason
        self._closed.set()
        for key in list(self._waiting):
            future = self._waiting.pop(key, None)
            if future is not None and not future.done():
                future.set_exception(BridgeClosedError(reason))
        self._pool.shutdown(wait=False, cancel_futures=True)


class HandlerAnswerError(TypeError):
    """A handler answered something a service response cannot carry; ``answer`` is what it returned."""

    def __init__(self, service: str, answer: object, why: str) -> None:
        self.service, self.answer = service, answer
        shown = repr(answer)
        shown = shown if len(shown) <= 80 else shown[:77] + "..."
        super().__init__(f"the handler of {service} returned {shown}: {why}")


def _response(service: str, answer: object) -> dict[str, Any]:
    """A handler's answer as the response's values: a dict of the response's fields, JSON all through."""
    if not isinstance(answer, Mapping):
        raise HandlerAnswerError(
            service, answer, f"a {type(answer).__name__}, not a dict of the response's fields ({{field: value}})"
        )
    values = dict(answer)
    try:
        json.dumps(values, allow_nan=False)
    except (TypeError, ValueError) as error:  # NaN and infinities are not JSON: the server refuses the frame
        raise HandlerAnswerError(service, answer, f"not JSON ({error})") from None
    return values
