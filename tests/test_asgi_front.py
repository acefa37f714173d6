"""The HTTP front of ``cbrs serve``: the ASGI app on Granian (cbrs.asgi_front, cbrs.http_listener).

The front answers plain ``/sparql`` queries itself; each answer is compared with the Flask view's for
the same request, called in-process. Over a real Granian listener on loopback: slow and oversized
headers are refused, a slow body holds no thread, and ``start`` returns only once the port accepts.
"""

from __future__ import annotations

import asyncio
import json
import socket
import threading
from collections.abc import Iterator
from typing import Any
from urllib.parse import parse_qsl, quote

import httpx
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from werkzeug.test import Client

from cbrs.asgi_front import SparqlFront, _lone_query, _parameters
from cbrs.http_listener import HttpListener, ListenerConfig, UnknownLoopError, new_loop
from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app
from cbrs.web.sparql_wsgi import plain_get

WAIT = 10.0
OWN = "http://127.0.0.1:8080"
LOOKUP = "SELECT ?p ?o WHERE { home:Cup ?p ?o }"
SELECT = "SELECT ?ad WHERE { ?ad a cbrs:DynamicPerceptionComponent } ORDER BY ?ad LIMIT 3"
EVERY_TYPE = "SELECT ?s ?t WHERE { ?s a ?t }"  # one scan with a result of some hundred kilobytes


def front_for(kb: KnowledgeBase, **options: Any) -> tuple[SparqlFront, Any]:
    app = create_app(SparqlService(kb, EndpointConfig()), own_origins=lambda: {OWN})
    names = frozenset({"127.0.0.1", "localhost", "::1"})
    flask_only = app.wsgi_app.app  # type: ignore[attr-defined]  # without the WSGI hot path
    return SparqlFront(flask_only, app.extensions["cbrs.sparql"], lambda: names, 1 << 20, **options), flask_only


def call(front: SparqlFront, method: str, path: str, headers: dict[str, str], body: bytes = b"") -> Any:
    """One request through the ASGI app: (status, headers as a lower-cased dict, body)."""
    target, _, query_string = path.partition("?")
    scope = {
        "type": "http",
        "method": method,
        "path": target,
        "root_path": "",
        "query_string": query_string.encode("ascii"),
        "http_version": "1.1",
        "scheme": "http",
        "server": ("127.0.0.1", 8080),
        "client": ("127.0.0.1", 50000),
        "headers": [(k.lower().encode("latin-1"), v.encode("latin-1")) for k, v in headers.items()],
    }
    sent: list[dict[str, Any]] = []
    given = [False]

    async def receive() -> dict[str, Any]:
        if not given[0]:
            given[0] = True
            return {"type": "http.request", "body": body, "more_body": False}
        await asyncio.sleep(WAIT)
        return {"type": "http.disconnect"}

    async def send(message: dict[str, Any]) -> None:
        sent.append(message)

    asyncio.run(front(scope, receive, send))
    start = sent[0]
    answer_headers = {k.decode("latin-1"): v.decode("latin-1") for k, v in start["headers"]}
    return start["status"], answer_headers, b"".join(m.get("body", b"") for m in sent[1:])


def flask_answer(app: Any, method: str, path: str, headers: dict[str, str], body: bytes = b"") -> Any:
    response = Client(app).open(path, method=method, headers=headers, data=body or None)
    return response.status_code, {k.lower(): v for k, v in response.headers.items()}, response.data


@pytest.mark.parametrize(
    ("method", "path", "headers", "body"),
    [
        pytest.param("GET", f"/sparql?query={quote(LOOKUP)}", {}, b"", id="get-lookup"),
        pytest.param("HEAD", f"/sparql?query={quote(LOOKUP)}", {}, b"", id="head-lookup"),
        pytest.param("GET", f"/sparql?query={quote(SELECT)}&format=xml", {}, b"", id="get-format-thread"),
        pytest.param("GET", f"/sparql?query={quote(LOOKUP)}", {"Accept": "text/csv"}, b"", id="accept-csv"),
        pytest.param("GET", f"/sparql?query={quote(LOOKUP)}", {"Accept": "text/nope"}, b"", id="not-acceptable"),
        pytest.param("GET", "/sparql?query=SELECT%20%3Fx%20WHERE%20%7B", {}, b"", id="syntax-error"),
        pytest.param("GET", f"/sparql?query={quote(LOOKUP)}&output=tsv", {}, b"", id="output"),
        pytest.param("GET", f"/sparql?query={quote(LOOKUP)}&query=ASK%7B%7D", {}, b"", id="two-queries"),
        pytest.param("GET", f"/sparql?query={quote(LOOKUP)}", {"Origin": "http://other.example"}, b"", id="origin"),
        pytest.param("GET", f"/sparql?query={quote(LOOKUP)}", {"Host": "evil.example"}, b"", id="rebinding"),
        pytest.param(
            "POST", "/sparql", {"Content-Type": "application/sparql-query"}, LOOKUP.encode(), id="post-direct"
        ),
        pytest.param("POST", "/sparql", {"Content-Type": "application/sparql-query"}, b"\xff", id="post-not-utf8"),
        pytest.param("POST", "/sparql", {"Content-Type": "text/plain"}, LOOKUP.encode(), id="post-wrong-type"),
        pytest.param("GET", "/sparql", {}, b"", id="service-description"),
        pytest.param("GET", "/healthz", {}, b"", id="flask-page"),
    ],
)
def test_the_front_answers_as_the_flask_view_does(
    bundled_kb: KnowledgeBase, method: str, path: str, headers: dict[str, str], body: bytes
) -> None:
    front, flask_only = front_for(bundled_kb)
    headers = {"Host": "127.0.0.1:8080", **headers}
    if body:
        headers["Content-Length"] = str(len(body))
    try:
        mine = call(front, method, path, headers, body)
        theirs = flask_answer(flask_only, method, path, headers, body)
    finally:
        front.close()
    assert mine[0] == theirs[0]
    assert mine[1] == theirs[1]
    assert mine[2] == theirs[2]


def test_a_scan_past_the_inline_budget_is_answered_on_a_thread_alike(bundled_kb: KnowledgeBase) -> None:
    inline, _ = front_for(bundled_kb)
    small, _ = front_for(bundled_kb, inline_bytes=1024)
    path = f"/sparql?query={quote(EVERY_TYPE)}"
    try:
        answers = [call(front, "GET", path, {"Host": "127.0.0.1:8080"}) for front in (inline, small)]
    finally:
        inline.close()
        small.close()
    assert answers[0] == answers[1]
    assert answers[0][0] == 200 and len(answers[0][2]) > 1024
    assert small.sparql.query_here(EVERY_TYPE, None, None, None, 1024) is None  # too big for the loop


@pytest.mark.parametrize(
    "query_string",
    [
        "query=a+b%20c&format=json",
        "a",
        "a=&b",
        "&&x=1",
        "q=%zz",
        "x=1=2",
        "query=%E2%82%AC",
        "",
        "q=%5Cx41%4",
        "q=\\%41\\x41",
        "q=%41%",
        "q=%C3%A9%2",
        "q=%%41",
    ],
)
def test_query_strings_are_read_as_parse_qsl_reads_them(query_string: str) -> None:
    assert _parameters(query_string) == parse_qsl(query_string, keep_blank_values=True, errors="strict")


@settings(max_examples=500, deadline=None)
@given(st.text(alphabet="%+&=aZ09fFxX-_.~ ?<>{}\\", max_size=40))
def test_any_ascii_query_string_is_read_as_parse_qsl_reads_it(query_string: str) -> None:
    try:
        expected = parse_qsl(query_string, keep_blank_values=True, errors="strict")
    except UnicodeDecodeError:
        with pytest.raises(UnicodeDecodeError):
            _parameters(query_string)
        return
    assert _parameters(query_string) == expected
    lone = _lone_query(query_string)  # the front's shortcut for a lookup's one parameter
    if lone is not None:
        assert plain_get(expected) == (lone, None)


@pytest.mark.parametrize("query_string", ["query=a%20b", "query=", "query=%2B+", "query=a&format=json", "format=json"])
def test_a_lone_query_parameter_is_read_as_plain_get_reads_it(query_string: str) -> None:
    lone = _lone_query(query_string)
    plain = plain_get(parse_qsl(query_string, keep_blank_values=True))
    assert (lone is None) == ("&" in query_string or not query_string.startswith("query="))
    if lone is not None:
        assert plain == (lone, None)


def test_a_query_string_that_is_not_utf8_goes_to_flask() -> None:
    with pytest.raises(UnicodeDecodeError):
        _parameters("query=%FF")


# -- over a real listener ------------------------------------------------------------------------------


async def _hello(scope: dict[str, Any], receive: Any, send: Any) -> None:
    await send({"type": "http.response.start", "status": 200, "headers": [(b"content-type", b"text/plain")]})
    await send({"type": "http.response.body", "body": b"hello"})


@pytest.fixture
def listener() -> Iterator[HttpListener]:
    running = HttpListener(_hello, ListenerConfig(port=0, header_timeout=0.5, max_header_bytes=16384))
    running.start()
    yield running
    running.stop(WAIT)


def _exchange(port: int, request: bytes) -> bytes:
    with socket.create_connection(("127.0.0.1", port), timeout=WAIT) as connection:
        connection.sendall(request)
        return connection.recv(4096)


def test_the_loop_is_uvloop_when_installed_and_asyncio_when_asked() -> None:
    uvloop = pytest.importorskip("uvloop")
    for kind, expected in (("auto", uvloop.Loop), ("uvloop", uvloop.Loop), ("asyncio", asyncio.BaseEventLoop)):
        loop = new_loop(kind)
        try:
            assert isinstance(loop, expected)
            assert kind != "asyncio" or not isinstance(loop, uvloop.Loop)
        finally:
            loop.close()
    with pytest.raises(UnknownLoopError, match="'trio'") as refused:
        new_loop("trio")
    assert refused.value.kind == "trio"


@pytest.mark.parametrize("kind", ["asyncio", "auto"])
def test_the_listener_serves_and_stops_on_either_loop(kind: str) -> None:
    running = HttpListener(_hello, ListenerConfig(port=0, loop=kind))
    running.start()
    try:
        assert httpx.get(f"http://127.0.0.1:{running.port}/", timeout=WAIT).text == "hello"
    finally:
        running.stop(WAIT)
    with pytest.raises(OSError), socket.create_connection(("127.0.0.1", running.port), timeout=1):
        pass


def test_start_returns_once_the_port_accepts_and_stop_closes_it() -> None:
    for _ in range(3):  # start-up used to race the worker's listen()
        running = HttpListener(_hello, ListenerConfig(port=0))
        running.start()
        port = running.port
        try:
            assert httpx.get(f"http://127.0.0.1:{port}/", timeout=WAIT).text == "hello"
        finally:
            running.stop(WAIT)
        with pytest.raises(httpx.ConnectError):
            httpx.get(f"http://127.0.0.1:{port}/", timeout=WAIT)


def test_a_port_in_use_is_an_oserror_from_start(listener: HttpListener) -> None:
    with pytest.raises(OSError):
        HttpListener(_hello, ListenerConfig(port=listener.port)).start()


def test_a_client_slow_to_send_its_headers_is_dropped(listener: HttpListener) -> None:
    # the connection ends (an empty read) instead of waiting for the rest of the headers
    assert _exchange(listener.port, b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n") == b""


@pytest.mark.parametrize(
    "headers",
    [
        pytest.param(b"X-Big: " + b"a" * 40_000 + b"\r\n", id="one-header-too-large"),
        pytest.param(b"".join(b"X-H%d: v\r\n" % i for i in range(200)), id="too-many-headers"),
    ],
)
def test_oversized_headers_are_refused_with_431(listener: HttpListener, headers: bytes) -> None:
    answer = _exchange(listener.port, b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n" + headers + b"\r\n")
    assert answer.startswith(b"HTTP/1.1 431")


def test_a_slow_body_holds_no_thread_and_times_out_with_408(fresh_bundled_kb: KnowledgeBase) -> None:
    from cbrs.server import ServeConfig, Server

    config = ServeConfig(port=0, bridge_port=0, http_threads=1, stream_limit=0, body_timeout=1)
    server = Server(fresh_bundled_kb, config)
    server.start()
    try:
        port = server.http_port
        slow = socket.create_connection(("127.0.0.1", port), timeout=WAIT)
        slow.sendall(  # to a Flask route, with its body never sent
            b"POST /update HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/sparql-update\r\n"
            b"Content-Length: 100\r\n\r\nINSERT"
        )
        # the one WSGI thread is free meanwhile: a Flask page answers
        assert httpx.get(f"http://127.0.0.1:{port}/healthz", timeout=WAIT).json()["status"] == "ok"
        answer = slow.recv(4096)
        slow.close()
        assert answer.startswith(b"HTTP/1.1 408")
        assert json.loads(answer.partition(b"\r\n\r\n")[2])["error"] == "timeout"
    finally:
        server.stop(WAIT)


def test_a_chunked_body_reaches_flask_whole_and_past_the_limit_is_refused(fresh_bundled_kb: KnowledgeBase) -> None:
    from cbrs.server import ServeConfig, Server

    server = Server(fresh_bundled_kb, ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token="t")))
    server.start()
    try:
        limit = server.app.config["MAX_CONTENT_LENGTH"]

        def chunks() -> Iterator[bytes]:  # chunked: no Content-Length for Flask to refuse up front
            for _ in range(limit // 65536 + 4):
                yield b"x" * 65536

        answer = httpx.post(
            f"http://127.0.0.1:{server.http_port}/update",
            content=chunks(),
            headers={"Content-Type": "application/sparql-update", "Authorization": "Bearer t"},
            timeout=WAIT,
        )
        assert answer.status_code == 413
        insert = b"INSERT DATA { GRAPH <urn:test:g> { <urn:test:s> <urn:test:p> 'chunked' } }"
        answer = httpx.post(  # a chunked body within the limit reaches Flask whole
            f"http://127.0.0.1:{server.http_port}/update",
            content=iter([insert[:20], insert[20:]]),
            headers={"Content-Type": "application/sparql-update", "Authorization": "Bearer t"},
            timeout=WAIT,
        )
        assert answer.status_code == 204
        assert fresh_bundled_kb.query("ASK { GRAPH ?g { <urn:test:s> <urn:test:p> 'chunked' } }")
    finally:
        server.stop(WAIT)


def test_threads_end_after_a_served_stream(fresh_bundled_kb: KnowledgeBase) -> None:
    from cbrs.server import ServeConfig, Server
    from tests.helpers_threads import assert_threads_end

    threads = threading.active_count()
    server = Server(fresh_bundled_kb, ServeConfig(port=0, bridge_port=0))
    server.app.config.update(CBRS_HEARTBEAT_SECONDS=0.2)
    server.start()
    try:
        with httpx.stream("GET", f"http://127.0.0.1:{server.http_port}/tasks/events", timeout=WAIT) as stream:
            assert stream.status_code == 200
            next(stream.iter_lines())
        # the client went: the stream ends at its next write and gives its slot back
        streams = server.app.extensions["cbrs.streams"]
        for _ in range(100):
            if not streams.open:
                break
            threading.Event().wait(0.05)
        assert streams.open == 0
    finally:
        server.stop(WAIT)
    assert_threads_end(threads, WAIT)


def test_the_serve_config_takes_its_loop_from_the_setting(monkeypatch: pytest.MonkeyPatch) -> None:
    from cbrs.server import ServeConfig

    monkeypatch.setenv("CBRS_HTTP_LOOP", " AsyncIO ")
    assert ServeConfig().http_loop == "asyncio"
    monkeypatch.setenv("CBRS_HTTP_LOOP", "trio")
    with pytest.raises(ValueError, match="CBRS_HTTP_LOOP='trio'"):
        ServeConfig()
    monkeypatch.delenv("CBRS_HTTP_LOOP")
    assert ServeConfig().http_loop == "auto"
