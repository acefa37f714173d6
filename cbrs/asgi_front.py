"""The ASGI application ``cbrs serve`` puts on Granian: ``/sparql`` queries here, everything else to Flask.

A point lookup costs Oxigraph some tens of microseconds; under waitress the HTTP server's own Python
(parsing, threads, the WSGI call) cost ten times that, holding the GIL, so the endpoint did about one
core's worth of lookups whatever the number of clients. Granian (:mod:`cbrs.http_listener`) reads and
writes HTTP in Rust, off the GIL, and calls this application on one asyncio loop. It answers the
request the WSGI hot path (:mod:`cbrs.web.sparql_wsgi`) answers, with the same status, headers and
body: a ``GET`` or ``HEAD`` whose only parameters are one ``query`` and optionally ``format`` or
``output``, or a ``POST`` of an ``application/sparql-query`` body with no parameters, from a client that
sends no ``Origin`` and names this server in ``Host``. A single scan whose result fits in
``inline_bytes`` is answered on the loop itself (:meth:`SparqlService.query_here`); any other query
waits on one of ``threads`` threads, so the loop never waits for a query worker. Every other request,
and any this front is unsure of, goes to the Flask app through a2wsgi's WSGI-to-ASGI adapter, whose
threads run it as waitress's did. Whichever answers, the answer goes to Granian paced
(:class:`UnreadAnswers`), and a client holds at most a share of the connections' bodies still coming
(:class:`BodyWaits`): docs/security.md, section 8.
"""

from __future__ import annotations

import asyncio
import functools
import logging
import types
from collections import Counter
from collections.abc import Awaitable, Callable, Collection, Generator, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import Any
from urllib.parse import unquote_to_bytes

from a2wsgi import WSGIMiddleware
from a2wsgi.wsgi import WSGIResponder

from cbrs.sparql_service import BUSY_RETRY_AFTER, Answer, SparqlService
from cbrs.web.sparql_wsgi import (
    COMMON_HEADERS,
    error_answer,
    error_headers,
    host_allowed,
    json_body,
    plain_get,
    plain_post_length,
)

log = logging.getLogger("cbrs.server")

Scope = dict[str, Any]
Message = dict[str, Any]
Receive = Callable[[], Awaitable[Message]]
Send = Callable[[Message], Awaitable[None]]
WSGIApp = Callable[[dict[str, Any], Callable[..., Any]], Iterable[bytes]]

# What every answer of /sparql carries, as the Flask view sends it.
_COMMON = [(name.lower().encode("latin-1"), value.encode("latin-1")) for name, value in COMMON_HEADERS]
_RETRY = (("Retry-After", str(BUSY_RETRY_AFTER)),)  # a busy answer's, as the endpoint's
# The request headers the front reads; a request repeating one of them goes to Flask, which joins them.
_READ = frozenset({b"host", b"accept", b"origin", b"content-type", b"content-length"})


class SparqlFront:
    """An ASGI app: plain ``/sparql`` queries answered here, every other request handed to ``wsgi_app``."""

    def __init__(
        self,
        wsgi_app: WSGIApp,
        sparql: SparqlService,
        host_names: Callable[[], Collection[str | None] | None],
        max_body: int,
        threads: int = 16,
        wsgi_threads: int = 24,
        inline_bytes: int = 256 * 1024,
        body_timeout: float = 30.0,
        bodies_per_client: int = 16,
        unread_per_client: int = 64 * 1024 * 1024,
        send_timeout: float = 30.0,
    ) -> None:
        self.sparql = sparql
        self.host_names = host_names  # the names Host may give, None for any (as cbrs.web._check_host)
        self.max_body = max_body
        self.inline_bytes = inline_bytes
        self.body_timeout = body_timeout
        self.bodies = BodyWaits(bodies_per_client)
        self.unread = UnreadAnswers(unread_per_client, send_timeout)
        self.wsgi = _WsgiAdapter(wsgi_app, wsgi_threads, max_body, body_timeout, self.bodies)
        self._names: Collection[str | None] | None = None
        self._hosts: dict[str, bool] = {}
        self._queries = ThreadPoolExecutor(threads, thread_name_prefix="cbrs-sparql")

    def close(self) -> None:
        """Let the threads end once their request has (new requests no longer arrive)."""
        self._queries.shutdown(wait=False, cancel_futures=True)
        self.wsgi.executor.shutdown(wait=False, cancel_futures=True)

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.wsgi(scope, receive, send)
            return
        client = scope.get("client")
        reader = client and client[0]
        if self.unread.over(reader):
            await _too_much_unread(send, reader, self.unread)
            return
        try:
            await self._http(scope, receive, self.unread.paced(send, reader))
        except SlowReaderError as error:  # the answer is dropped with its connection
            log.info("%s", error)

    async def _http(self, scope: Scope, receive: Receive, send: Send) -> None:
        headers = _headers(scope)
        plain = self._plain_query(scope, headers) if headers is not None else None
        if headers is None or plain is None:
            await self.wsgi(scope, receive, send)
            return
        text, short, length = plain
        client = scope.get("client")
        if length >= 0:  # a POST: the body is the query
            sender = client and client[0]
            if not self.bodies.admit(sender):
                await _too_many_bodies(send, sender, self.bodies.per_client)
                return
            try:
                body = await asyncio.wait_for(_read_body(receive), self.body_timeout)
            except TimeoutError:
                await _body_late(send, self.body_timeout)
                return
            finally:
                self.bodies.done(sender)
            if body is None:
                await _body_cut(send)
                return
            try:
                text = body.decode("utf-8")
            except UnicodeDecodeError:  # Flask reads it again and names the error
                await self.wsgi(scope, _replay(body, receive), send)
                return
        answered = await self._answer(text, headers.get(b"accept"), short, client and client[0])
        status, media_type, content, extra = answered
        await _respond(send, scope["method"] == "HEAD", status, media_type, content, extra)

    async def _answer(
        self, text: str, accept: str | None, short: str | None, client: str | None
    ) -> tuple[int, str, bytes, tuple[tuple[str, str], ...]]:
        try:
            answer: Answer | None = self.sparql.query_here(text, accept, short, client, self.inline_bytes)
            if answer is None:
                run = functools.partial(self.sparql.query, text, accept, short, client=client)
                answer = await asyncio.get_running_loop().run_in_executor(self._queries, run)
        except Exception as error:
            status, body = error_answer(error)
            return status, "application/json", body, error_headers(error)
        return 200, answer.media_type + "; charset=utf-8", answer.body, ()

    def _plain_query(self, scope: Scope, headers: dict[bytes, str]) -> tuple[str, str | None, int] | None:
        """(query, short format, -1) of a GET or HEAD this front answers, ("", None, body length) of such
        a POST; None for Flask's."""
        if scope.get("path") != "/sparql" or scope.get("root_path") or b"origin" in headers:
            return None
        if not self._host_ok(headers.get(b"host")):
            return None
        method = scope.get("method")
        try:
            query_string = scope.get("query_string", b"").decode("ascii")
            lookup = _lone_query(query_string) if method == "GET" else None
            if lookup is not None:
                return lookup, None, -1
            parameters = _parameters(query_string)
        except (UnicodeDecodeError, ValueError):
            return None
        if method in ("GET", "HEAD"):
            plain = plain_get(parameters)
            return None if plain is None else (*plain, -1)
        if method == "POST" and not parameters:
            length = plain_post_length(headers.get(b"content-type"), headers.get(b"content-length"), self.max_body)
            return None if length is None else ("", None, length)
        return None

    def _host_ok(self, host: str | None) -> bool:
        names = self.host_names()
        if names is None:
            return True
        if not host:
            return False
        if names is not self._names:  # the names are fixed once the server listens: remember answers
            self._names, self._hosts = names, {}
        known = self._hosts.get(host)
        if known is None:
            known = host_allowed(host, names)
            if len(self._hosts) < 64:  # the few Host values clients send; other values are not kept
                self._hosts[host] = known
        return known


class ClientDisconnectedError(OSError):
    """Raised in a WSGI thread writing to a client that has gone, so that the app's iterable is closed
    (a stream ends and gives its slot back) instead of writing on into nothing."""


PIECE = 64 * 1024  # an answer goes to Granian in pieces of this size, each awaited: its send waits for the reader


class SlowReaderError(ClientDisconnectedError):
    """A client read nothing of its answer for ``send_timeout``: the answer is dropped."""

    def __init__(self, client: str | None, timeout: float) -> None:
        self.client = client
        super().__init__(f"dropped an answer to {client}: it read nothing of it for {timeout:g} s")


class UnreadAnswers:
    """The bytes of answers each client (an IP address) has not read yet, and the pace they are sent at.

    Granian takes a body given in one message whole, at once, whether the client reads it or not: 40
    connections that sent a query for a 3 MB result and read nothing held 170 MB of the server's memory,
    and up to ``max_result_bytes`` (64 MiB) each. So an answer is handed over in :data:`PIECE` pieces,
    each awaited (Granian's send waits once the connection's buffers are full); a piece not taken within
    ``timeout`` drops the answer and its connection; and a client with ``per_client`` bytes or more of
    answers unread gets 503 at once for anything more. All on the event loop's thread, so no lock."""

    def __init__(self, per_client: int, timeout: float) -> None:
        self.per_client = per_client
        self.timeout = timeout
        self.held: Counter[str | None] = Counter()

    def over(self, client: str | None) -> bool:
        return self.held.get(client, 0) >= self.per_client  # without Counter's miss, in Python

    def paced(self, send: Send, client: str | None) -> Send:
        """``send`` with every body sent in pieces, counted against ``client`` until taken."""

        async def paced_send(message: Message) -> None:
            body = message.get("body", b"") if message["type"] == "http.response.body" else b""
            if len(body) <= PIECE:  # as _within, without its frame: every answer's two messages pass here
                waiting = send(message).__await__()
                try:
                    signal = next(waiting)
                except StopIteration:
                    return
                await self._rest(waiting, signal, client)
                return
            more = message.get("more_body", False)
            self.held[client] += len(body)
            left = len(body)
            try:
                view = memoryview(body)
                for start in range(0, len(body), PIECE):
                    piece = bytes(view[start : start + PIECE])
                    last = start + PIECE >= len(body)
                    await self._within(send({**message, "body": piece, "more_body": more or not last}), client)
                    self.held[client] -= len(piece)
                    left -= len(piece)
            finally:
                self.held[client] -= left
                if self.held[client] <= 0:
                    del self.held[client]

        return paced_send

    async def _within(self, sending: Awaitable[None], client: str | None) -> None:
        """Await ``sending`` for at most :attr:`timeout`. A send Granian takes at once (a lookup's
        answer, a piece while the buffers have room) costs no timer: a timer per message cost a
        lookup some 5-20 microseconds of the front's 20."""
        waiting = sending.__await__()
        try:
            signal = next(waiting)
        except StopIteration:
            return
        await self._rest(waiting, signal, client)

    async def _rest(self, waiting: Iterator[Any], signal: Any, client: str | None) -> None:
        """The rest of a send that has to wait (``signal``: for what), for at most :attr:`timeout`."""
        try:
            async with asyncio.timeout(self.timeout):
                await _resumed(waiting, signal)
        except TimeoutError:
            raise SlowReaderError(client, self.timeout) from None


@types.coroutine
def _resumed(waiting: Iterator[Any], signal: Any) -> Generator[Any, None, None]:
    """The rest of an awaitable whose first step, which gave ``signal`` (what it waits for), was taken."""
    while True:
        yield signal
        try:
            signal = next(waiting)
        except StopIteration:
            return


class BodyWaits:
    """The requests of each client (an IP address) whose body is still coming. Each holds a connection,
    and Granian serves a fixed number of connections at once: a client sending bodies slowly (a byte a
    second, each within ``body_timeout``) held all of them, and nobody else was answered. Past
    ``per_client`` such requests, a client's next one is refused at once (503), which closes its
    connection. All on the event loop's thread, so no lock."""

    def __init__(self, per_client: int) -> None:
        self.per_client = per_client
        self.waiting: Counter[str | None] = Counter()

    def admit(self, client: str | None) -> bool:
        if self.waiting[client] >= self.per_client:
            return False
        self.waiting[client] += 1
        return True

    def done(self, client: str | None) -> None:
        self.waiting[client] -= 1
        if self.waiting[client] <= 0:
            del self.waiting[client]


class _WsgiAdapter(WSGIMiddleware):
    """a2wsgi's WSGI-to-ASGI adapter, made to treat clients as waitress did: a request reaches a WSGI
    thread only once its body is in (at most ``max_body`` bytes of it, within ``body_timeout``), so a
    slow client holds no thread; and the app hears when its client has gone."""

    def __init__(self, app: WSGIApp, workers: int, max_body: int, body_timeout: float, bodies: BodyWaits) -> None:
        super().__init__(app, workers=workers)  # type: ignore[arg-type]
        self.max_body = max_body
        self.body_timeout = body_timeout
        self.bodies = bodies

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        if scope["type"] != "http":
            await super().__call__(scope, _coroutine(receive), send)  # type: ignore[arg-type]
            return
        responder = _Responder(self.app, self.executor, self.send_queue_size)
        await responder.serve(scope, receive, send, self.max_body, self.body_timeout, self.bodies)


class _Responder(WSGIResponder):
    """One request through the adapter. A task reads the request's messages as they come: the body,
    kept for the WSGI app up to one chunk past ``max_body`` (Flask's limit refuses it then), and the
    disconnect, after which a write raises (Granian drops what is sent to a closed connection without a
    word, and a stream would go on)."""

    gone = False

    async def serve(
        self, scope: Any, receive: Any, send: Any, max_body: int, body_timeout: float, bodies: BodyWaits
    ) -> None:
        client = scope.get("client")
        sender = client and client[0]
        waits = _has_body(scope)
        if waits and not bodies.admit(sender):
            await _too_many_bodies(send, sender, bodies.per_client)
            return
        messages: asyncio.Queue[Message] = asyncio.Queue()
        body_in = asyncio.Event()
        size = 0

        async def pump() -> None:
            nonlocal size
            while True:
                message = await receive()
                if message["type"] == "http.disconnect":
                    self.gone = True
                    body_in.set()
                    await messages.put(message)
                    return
                if body_in.is_set():
                    continue  # past the limit: not kept
                size += len(message.get("body", b""))
                if size > max_body:
                    message = {**message, "more_body": False}
                if not message.get("more_body", False):
                    body_in.set()
                await messages.put(message)

        reader = self.loop.create_task(pump())
        try:
            try:
                await asyncio.wait_for(body_in.wait(), body_timeout)
            except TimeoutError:
                await _body_late(send, body_timeout)
                return
            finally:
                if waits:
                    bodies.done(sender)
                    waits = False
            if self.gone:  # Granian says so of a malformed body too: answered (a gone client hears nothing)
                await _body_cut(send)
            else:
                await self(_with_length(scope, size), messages.get, send)  # type: ignore[arg-type]
        except ClientDisconnectedError:
            pass  # nobody to answer
        finally:
            reader.cancel()

    def send(self, message: Any) -> None:
        if self.gone:
            raise ClientDisconnectedError("the client closed the connection")
        super().send(message)

    async def sender(self, send: Any) -> None:
        """a2wsgi's, except that a client that stops reading ends the answer: the app's next write
        raises, and what it had queued is taken and dropped (a2wsgi's would stop taking, and leave the
        app's thread waiting to queue for ever)."""
        while True:
            message = await self.send_queue.get()
            if message is None:
                break
            if not self.gone:
                try:
                    await send(message)
                except SlowReaderError as error:
                    self.gone = True
                    log.info("%s", error)
            self.send_queue.task_done()


def _has_body(scope: Scope) -> bool:
    """Whether the request announces a body: a Content-Length other than 0, or a transfer coding."""
    for name, value in scope.get("headers", ()):
        if name == b"transfer-encoding" or (name == b"content-length" and value.strip() not in (b"", b"0")):
            return True
    return False


def _with_length(scope: Scope, size: int) -> Scope:
    """``scope`` with the Content-Length of its body, which is in: a chunked body is given to the WSGI
    app as waitress gave it (werkzeug reads no body without a length, and refuses one past its limit)."""
    headers = scope.get("headers", [])
    if any(name == b"content-length" for name, _ in headers):
        return scope
    kept = [(name, value) for name, value in headers if name != b"transfer-encoding"]
    return {**scope, "headers": [*kept, (b"content-length", str(size).encode("ascii"))]}


def _parameters(query_string: str) -> list[tuple[str, str]]:
    """``parse_qsl(query_string, keep_blank_values=True, errors="strict")`` of an ASCII query string,
    without its generality: this runs for every lookup (tests/test_asgi_front.py checks the two agree)."""
    pairs = []
    for field in query_string.split("&"):
        if field:
            name, _, value = field.partition("=")
            pairs.append((_unquote(name), _unquote(value)))
    return pairs


def _lone_query(query_string: str) -> str | None:
    """The query of an ASCII query string that is one ``query`` parameter, as ``plain_get(_parameters(...))``
    reads it; ``None`` for any other (then those two read it). A robot's lookup sends just that."""
    if "&" in query_string or not query_string.startswith("query="):
        return None
    return _unquote(query_string[6:])


def _unquote(text: str) -> str:
    """``unquote_plus(text, errors="strict")`` of an ASCII ``text``, in C: each ``%XX`` becomes a ``\\xXX``
    escape (the text's own backslashes doubled first) that the ``unicode_escape`` codec turns into its
    byte, and the bytes are read as UTF-8. A ``%`` without two hex digits after it, which ``unquote``
    keeps as it is, makes the codec fail, and such a text is read by ``unquote_to_bytes``. A lookup's
    query string has some thirty escapes, which ``unquote`` reads one by one in Python."""
    text = text.replace("+", " ")
    if "%" not in text:
        return text
    try:
        raw = text.replace("\\", "\\\\").replace("%", "\\x").encode("ascii").decode("unicode_escape")
    except UnicodeDecodeError:
        return unquote_to_bytes(text).decode("utf-8")
    return raw.encode("latin-1").decode("utf-8")


def _headers(scope: Scope) -> dict[bytes, str] | None:
    """The headers the front reads, or None when one of them repeats (Flask decides then)."""
    found: dict[bytes, str] = {}
    for name, value in scope.get("headers", ()):
        if name in _READ:
            if name in found:
                return None
            found[name] = value.decode("latin-1")
    return found


async def _read_body(receive: Receive) -> bytes | None:
    """The request body (the server holds it to its Content-Length, which the front has checked), or
    None if the connection ended first (Granian says so of a malformed chunked body too)."""
    chunks: list[bytes] = []
    while True:
        message = await receive()
        if message["type"] != "http.request":
            return None
        chunks.append(message.get("body", b""))
        if not message.get("more_body", False):
            return b"".join(chunks)


async def _body_cut(send: Send) -> None:
    """Granian answered 500 when the app sent nothing for a request whose body it could not read."""
    message = "the request body ended before it was whole (a malformed chunked encoding, or a closed connection)"
    await _respond(send, False, 400, "application/json", json_body({"error": "bad-request", "message": message}))


def _coroutine(receive: Receive) -> Receive:
    """``receive`` as a coroutine function: Granian's gives an awaitable of its own, which a2wsgi's
    ``asyncio.run_coroutine_threadsafe`` refuses."""

    async def receive_coroutine() -> Message:
        return await receive()

    return receive_coroutine


def _replay(body: bytes, receive: Receive) -> Receive:
    """A ``receive`` that gives ``body`` again, then whatever the connection says next."""
    given = [False]

    async def again() -> Message:
        if not given[0]:
            given[0] = True
            return {"type": "http.request", "body": body, "more_body": False}
        return await receive()

    return again


async def _body_late(send: Send, timeout: float) -> None:
    message = f"the request body did not arrive within {timeout:g} s"
    await _respond(send, False, 408, "application/json", json_body({"error": "timeout", "message": message}))


async def _too_many_bodies(send: Send, client: str | None, limit: int) -> None:
    message = (
        f"{client} is already sending {limit} request bodies at once, the most one client may; "
        "send the rest when those are in"
    )
    await _respond(send, False, 503, "application/json", json_body({"error": "busy", "message": message}), _RETRY)


async def _too_much_unread(send: Send, client: str | None, unread: UnreadAnswers) -> None:
    message = (
        f"{client} has {unread.held[client]} bytes of answers it has not read yet, the most one client may "
        f"have ({unread.per_client}); read them, or close their connections"
    )
    await _respond(send, False, 503, "application/json", json_body({"error": "busy", "message": message}), _RETRY)


async def _respond(
    send: Send, head: bool, status: int, media_type: str, body: bytes, extra: tuple[tuple[str, str], ...] = ()
) -> None:
    headers = [(b"content-type", media_type.encode("latin-1")), (b"content-length", str(len(body)).encode()), *_COMMON]
    headers.extend((name.lower().encode("latin-1"), value.encode("latin-1")) for name, value in extra)
    await send({"type": "http.response.start", "status": status, "headers": headers})
    await send({"type": "http.response.body", "body": b"" if head else body})
