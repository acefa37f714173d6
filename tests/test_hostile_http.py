"""The HTTP side of ``cbrs serve`` against anonymous hostile clients and careless ones (docs/security.md,
section 8): held connections, slow bodies, parameters that are not UTF-8, ambiguous protocol requests,
unbounded graph-store reads, markup stored in literals and IRIs, credentials in the store's URL, and
pybullet's banner.

One in-process server for the module (loopback, port 0); a second client is told apart by binding
127.0.0.2. Every wait is bounded.
"""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any
from urllib.parse import quote

import httpx
import pytest

from cbrs.asgi_front import SlowReaderError, UnreadAnswers
from cbrs.graph_store import GraphStore, Target
from cbrs.http_listener import HttpListener, ListenerConfig
from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointBusyError, EndpointConfig, SparqlService
from cbrs.web import create_app

WAIT = 10.0
TOKEN = "hostile-http-token"
BODIES = 4  # bodies_per_client of the served server
AUTH = {"Authorization": f"Bearer {TOKEN}"}


@pytest.fixture(scope="module")
def served() -> Iterator[Server]:
    kb = KnowledgeBase.open(":memory:")
    config = ServeConfig(
        port=0,
        bridge_port=0,
        endpoint=EndpointConfig(update_token=TOKEN, timeout=WAIT, max_result_bytes=64 * 1024),
        header_timeout=60.0,  # held connections stay for the test's length: what is tested is that they are harmless
        bodies_per_client=BODIES,
    )
    server = Server(kb, config)
    server.start()
    yield server
    server.stop(timeout=WAIT)
    kb.close()


def url(server: Server, path: str) -> str:
    return f"http://127.0.0.1:{server.http_port}{path}"


def client(address: str = "127.0.0.1") -> httpx.Client:
    return httpx.Client(transport=httpx.HTTPTransport(local_address=address), timeout=WAIT)


def connection(server: Server, address: str, data: bytes = b"") -> socket.socket:
    held = socket.socket()
    held.settimeout(WAIT)
    held.bind((address, 0))
    held.connect(("127.0.0.1", server.http_port))
    if data:
        held.sendall(data)
    return held


# -- connections --------------------------------------------------------------------------------------


def test_idle_connections_past_granians_default_leave_others_answered(served: Server) -> None:
    """Granian holds a permit per open connection; at its default of 128, 128 idle sockets from one
    client kept every other client out until the header timeout closed them."""
    held = [connection(served, "127.0.0.2") for _ in range(200)]
    try:
        with client() as other:
            assert other.get(url(served, "/healthz")).status_code == 200
            assert other.get(url(served, "/sparql"), params={"query": "ASK { ?s ?p ?o }"}).json()["boolean"] is True
    finally:
        for socket_ in held:
            socket_.close()


def _partial_post(path: str, media_type: str) -> bytes:
    head = f"POST {path} HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: {media_type}\r\nContent-Length: 1000\r\n\r\n"
    return head.encode("ascii") + b"query=ASK"


def _answer(held: socket.socket) -> bytes:
    data = b""
    while b"\r\n\r\n" not in data or not data.rstrip().endswith(b"}"):
        chunk = held.recv(4096)
        if not chunk:
            break
        data += chunk
    return data


def test_a_client_sending_bodies_slowly_holds_its_share_not_the_server(served: Server) -> None:
    front = served._front
    assert front is not None
    slow = [connection(served, "127.0.0.2", _partial_post("/update", "application/x-www-form-urlencoded"))]
    try:
        for _ in range(BODIES - 1):
            slow.append(connection(served, "127.0.0.2", _partial_post("/sparql", "application/sparql-query")))
        deadline = time.monotonic() + WAIT
        while front.bodies.waiting["127.0.0.2"] < BODIES and time.monotonic() < deadline:
            time.sleep(0.01)
        assert front.bodies.waiting["127.0.0.2"] == BODIES
        for path, media_type in (
            ("/update", "application/x-www-form-urlencoded"),
            ("/sparql", "application/sparql-query"),
        ):
            refused = connection(served, "127.0.0.2", _partial_post(path, media_type))
            try:
                answer = _answer(refused)
            finally:
                refused.close()
            assert answer.startswith(b"HTTP/1.1 503")
            body = json.loads(answer.partition(b"\r\n\r\n")[2])
            assert body["error"] == "busy" and "127.0.0.2 is already sending 4 request bodies" in body["message"]
        with client() as other:  # another client's bodies are read as ever
            answer = other.post(url(served, "/sparql"), data={"query": "ASK { ?s ?p ?o }"})
            assert answer.status_code == 200 and answer.json()["boolean"] is True
    finally:
        for socket_ in slow:
            socket_.close()


async def _big_answer(scope: dict[str, Any], receive: Any, send: Any) -> None:
    """20 MiB for every request, sent as the front sends answers (paced, counted for its client)."""
    if scope["type"] != "http":
        return
    body = b"x" * (20 << 20)
    paced = SLOW.paced(send, scope["client"][0])
    try:
        await paced({"type": "http.response.start", "status": 200, "headers": [(b"content-length", b"%d" % len(body))]})
        await paced({"type": "http.response.body", "body": body})
    except SlowReaderError:
        DROPPED.append(scope["client"][0])


SLOW = UnreadAnswers(per_client=8 << 20, timeout=0.5)
DROPPED: list[str] = []


def test_an_answer_its_client_does_not_read_is_dropped_and_its_memory_freed() -> None:
    """Granian took a whole answer at once whether its client read it or not: 40 connections asking
    for 3 MB and reading nothing held 170 MB of the server. Paced, an unread answer waits in the
    server's memory, counted for its client, until send_timeout drops it with its connection."""
    listener = HttpListener(_big_answer, ListenerConfig(port=0))
    listener.start()
    try:
        reader = socket.socket()
        reader.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        reader.settimeout(WAIT)
        reader.connect(("127.0.0.1", listener.port))
        reader.sendall(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
        deadline, counted = time.monotonic() + WAIT, 0
        while not DROPPED and time.monotonic() < deadline:
            counted = max(counted, SLOW.held.get("127.0.0.1", 0))
            time.sleep(0.01)
        assert counted > SLOW.per_client  # what the buffers did not take was counted for its client
        assert DROPPED == ["127.0.0.1"] and SLOW.held == {}
        received = 0
        while chunk := reader.recv(1 << 20):  # what was in the buffers, then the end of the connection
            received += len(chunk)
        assert received < 20 << 20
        reader.close()
    finally:
        listener.stop(WAIT)


def test_a_client_with_answers_unread_gets_no_more(served: Server) -> None:
    front = served._front
    assert front is not None
    front.unread.held["127.0.0.2"] = front.unread.per_client  # as if it had asked for that much and read none
    try:
        with client("127.0.0.2") as slow, client() as other:
            refused = slow.get(url(served, "/sparql"), params={"query": "ASK { ?s ?p ?o }"})
            assert refused.status_code == 503 and refused.json()["error"] == "busy"
            assert refused.json()["message"].startswith("127.0.0.2 has 67108864 bytes of answers it has not read yet")
            assert other.get(url(served, "/sparql"), params={"query": "ASK { ?s ?p ?o }"}).status_code == 200
    finally:
        del front.unread.held["127.0.0.2"]


@pytest.mark.parametrize(
    ("path", "media_type"),
    [
        pytest.param("/sparql", "application/sparql-query", id="front"),
        pytest.param("/update", "application/sparql-update", id="flask"),
    ],
)
def test_a_malformed_chunked_body_is_a_400(served: Server, path: str, media_type: str) -> None:
    """Granian tells the app such a body as a disconnect; the app answered nothing, and Granian 500."""
    head = (
        f"POST {path} HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: {media_type}\r\nTransfer-Encoding: chunked\r\n\r\n"
    )
    held = connection(served, "127.0.0.1", head.encode("ascii") + b"zz\r\nASK {}\r\n0\r\n\r\n")
    try:
        answer = _answer(held)
    finally:
        held.close()
    assert answer.startswith(b"HTTP/1.1 400")
    assert json.loads(answer.partition(b"\r\n\r\n")[2])["message"].startswith(
        "the request body ended before it was whole"
    )


# -- parameters -----------------------------------------------------------------------------------------

# INSERT DATA { GRAPH <urn:cafe> { <urn:a> <urn:b> "café" } }, percent-encoded from Latin-1 (é is %E9)
LATIN1_UPDATE = "update=" + quote('INSERT DATA { GRAPH <urn:cafe> { <urn:a> <urn:b> "café" } }', encoding="latin-1")
CAFE_COUNT = "SELECT (COUNT(*) AS ?n) WHERE { GRAPH <urn:cafe> { ?s ?p ?o } }"


def _count(http: httpx.Client, served: Server, text: str) -> int:
    answer = http.get(url(served, "/sparql"), params={"query": text})
    return int(answer.json()["results"]["bindings"][0]["n"]["value"])


def test_a_form_not_in_utf8_is_refused_and_writes_nothing(served: Server) -> None:
    """Werkzeug kept undecodable bytes percent-encoded: this update stored the literal "caf%E9" and said 204."""
    form = {"Content-Type": "application/x-www-form-urlencoded", **AUTH}
    with client() as http:
        answer = http.post(url(served, "/update"), content=LATIN1_UPDATE, headers=form)
        assert answer.status_code == 400
        assert answer.json()["message"].startswith("the form field 'update' is not UTF-8 once percent-decoded")
        assert "%E9" in answer.json()["message"]
        assert _count(http, served, CAFE_COUNT) == 0
        # the same bytes, with the charset named, are read in it
        named = {**form, "Content-Type": "application/x-www-form-urlencoded; charset=ISO-8859-1"}
        assert http.post(url(served, "/update"), content=LATIN1_UPDATE, headers=named).status_code == 204
        answer = http.get(url(served, "/sparql"), params={"query": "SELECT ?o WHERE { GRAPH <urn:cafe> { ?s ?p ?o } }"})
        assert [row["o"]["value"] for row in answer.json()["results"]["bindings"]] == ["café"]
        bogus = {**form, "Content-Type": "application/x-www-form-urlencoded; charset=rot13"}
        answer = http.post(url(served, "/sparql"), content="query=ASK%7B%7D", headers=bogus)
        assert answer.status_code == 400 and "'rot13' is not one this server knows" in answer.json()["message"]
        http.post(url(served, "/update"), data={"update": "DROP GRAPH <urn:cafe>"}, headers=AUTH)


@pytest.mark.parametrize(
    ("path", "named"),
    [
        pytest.param("/sparql?query=ASK%20%7B%7D%FF", "'query'", id="query"),
        pytest.param("/sparql?qu%FFery=ASK", "'qu\ufffdery'", id="name"),
        pytest.param("/resource.json?iri=urn:%E9", "'iri'", id="page-twin"),
        pytest.param("/store?graph=urn:%C3", "'graph'", id="graph-store"),
    ],
)
def test_a_url_parameter_not_in_utf8_is_a_400_naming_it(served: Server, path: str, named: str) -> None:
    with client() as http:
        answer = http.get(url(served, path))
    assert answer.status_code == 400
    assert answer.json()["message"].startswith(f"the URL's parameter {named} is not UTF-8")


def test_a_page_with_such_a_parameter_says_so_on_a_page(served: Server) -> None:
    with client() as http:
        answer = http.get(url(served, "/search?q=%FF"), headers={"Accept": "text/html"})
    assert answer.status_code == 400 and answer.headers["content-type"].startswith("text/html")
    assert "the URL&#39;s parameter &#39;q&#39; is not UTF-8" in answer.text


@pytest.mark.parametrize(
    ("path", "body", "media_type"),
    [
        pytest.param("/sparql?query=ASK%7B%7D", "ASK { ?s ?p ?o }", "application/sparql-query", id="direct"),
        pytest.param("/sparql?query=ASK%7B%7D", "query=ASK%7B%7D", "application/x-www-form-urlencoded", id="form"),
        pytest.param(
            "/update?update=CLEAR%20ALL",
            "update=CLEAR%20SILENT%20GRAPH%20%3Curn%3Ax%3E",
            "application/x-www-form-urlencoded",
            id="update",
        ),
    ],
)
def test_a_post_with_its_text_in_the_url_too_is_a_400(served: Server, path: str, body: str, media_type: str) -> None:
    """Which text was meant? The body's was run and the URL's dropped without a word."""
    with client() as http:
        answer = http.post(url(served, path), content=body, headers={"Content-Type": media_type, **AUTH})
    assert answer.status_code == 400
    assert "but the URL has" in answer.json()["message"]


def test_a_json_body_nested_past_the_parser_is_a_400(served: Server) -> None:
    """POST /tasks read its JSON before the access check: 100,000 brackets were a RecursionError, 500."""
    deep = "[" * 100_000 + "]" * 100_000
    with client() as http:
        answer = http.post(url(served, "/tasks.json"), content=deep, headers={"Content-Type": "application/json"})
    assert answer.status_code == 400
    assert answer.json()["message"].startswith("the JSON body nests deeper than this server reads")


# -- the graph store ----------------------------------------------------------------------------------


def test_a_graph_name_that_is_no_iri_is_a_400_not_a_500(served: Server) -> None:
    with client() as http:
        answer = http.get(url(served, "/store"), params={"graph": "http://a b"})
    assert answer.status_code == 400
    assert answer.json()["message"].startswith("graph='http://a b' is not an absolute IRI")


def test_reading_the_store_keeps_the_endpoints_result_limit(served: Server) -> None:
    """A dump of the whole store was built in memory on a request thread, however big: now it stops at
    max_result_bytes (64 KiB here; the bundled store's dump is some 340 KB) like a query."""
    turtle = {"Content-Type": "text/turtle", **AUTH}
    with client() as http:
        assert http.put(
            url(served, "/store?graph=urn:small"), content="<urn:a> <urn:b> <urn:c> .", headers=turtle
        ).is_success
        try:
            answer = http.get(url(served, "/store"))
            assert answer.status_code == 422 and answer.json()["error"] == "result-too-large"
            small = http.get(url(served, "/store"), params={"graph": "urn:small"})
            assert small.status_code == 200 and "<urn:a> <urn:b> <urn:c>" in small.text
        finally:
            http.delete(url(served, "/store?graph=urn:small"), headers=AUTH)


def test_a_store_read_takes_a_query_slot(bundled_kb: KnowledgeBase) -> None:
    sparql = SparqlService(bundled_kb, EndpointConfig(workers=1, isolate=False))
    with sparql.bounded_read("10.0.0.1"), pytest.raises(EndpointBusyError, match="all 1 query workers are busy"):
        GraphStore(sparql).read(Target(None), None, "10.0.0.2")


# -- what pages show ------------------------------------------------------------------------------------

HOSTILE = """
PREFIX rdfs: <http://www.w3.org/2000/01/rdf-schema#>
PREFIX owl: <http://www.w3.org/2002/07/owl#>
INSERT DATA { GRAPH <urn:hostile> {
  <javascript:alert(1)//x> a owl:Class ; rdfs:subClassOf owl:Thing ;
    rdfs:label "<script>alert('label')</script>\\"><img src=x onerror=alert(2)>" .
  <http://x.example/a'onmouseover='alert(4)> rdfs:label "x' onmouseover='alert(5)" ;
    rdfs:seeAlso <javascript:alert(1)//x> ;
    <http://x.example/p> "v"^^<http://x.example/dt'onclick='alert(6)> .
} }
"""


def test_markup_stored_by_a_token_holder_is_text_on_every_page(served: Server) -> None:
    """Stored XSS: a literal or IRI written with the token, shown to an anonymous reader."""
    with client() as http:
        done = http.post(
            url(served, "/update"), content=HOSTILE, headers={"Content-Type": "application/sparql-update", **AUTH}
        )
        assert done.status_code == 204
        try:
            pages = [
                ("/resource", {"iri": "javascript:alert(1)//x"}),
                ("/resource", {"iri": "http://x.example/a'onmouseover='alert(4)"}),
                ("/search", {"q": "alert"}),
                ("/taxonomy/class", {"iri": "javascript:alert(1)//x"}),
                ("/query", {"query": "SELECT * WHERE { GRAPH <urn:hostile> { ?s ?p ?o } }"}),
            ]
            for path, params in pages:
                page = http.get(url(served, path), params=params, headers={"Accept": "text/html"})
                assert page.status_code == 200, (path, params)
                text = page.text
                assert "<script>alert" not in text and "<img src=x" not in text, (path, params)
                assert "' onmouseover='" not in text and "'onclick='" not in text, (path, params)
                assert 'href="javascript:' not in text, (path, params)
                assert "&lt;script&gt;alert" in text or "alert(4)" in text or path == "/taxonomy/class"
        finally:
            http.post(url(served, "/update"), data={"update": "DROP GRAPH <urn:hostile>"}, headers=AUTH)


def test_a_picture_opened_alone_runs_no_script(served: Server) -> None:
    with client() as http:
        answer = http.get(url(served, "/home.svg"))
    assert answer.status_code == 200 and answer.headers["content-type"].startswith("image/svg+xml")
    assert answer.headers["content-security-policy"].startswith("default-src 'none'")


def test_a_remote_stores_password_is_shown_to_nobody(
    bundled_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The CLI masked it in its banner; every page's footer, /healthz and the overview showed it."""
    monkeypatch.setattr(bundled_kb.store, "location", "http://robot:s3cret@store.invalid/sparql")
    app = create_app(SparqlService(bundled_kb, EndpointConfig(isolate=False)))
    http = app.test_client()
    health = http.get("/healthz").get_json()
    assert health["store"] == "http://robot:***@store.invalid/sparql"
    page = http.get("/no-such-page", headers={"Accept": "text/html"})
    assert page.status_code == 404 and "robot:***@store.invalid" in page.text and "s3cret" not in page.text


# -- pybullet's banner ------------------------------------------------------------------------------------


def test_pybullet_imported_on_a_thread_prints_no_banner() -> None:
    """cbrs serve imports pybullet on a thread (a task run, the first page's preload), where the
    descriptors cannot be redirected: C's streams are held instead, and what is printed after is kept."""
    quiet = Path(__file__).resolve().parents[1] / "sim" / "quiet.py"
    script = f"""
import ctypes, importlib.util, sys, threading
def load():
    spec = importlib.util.spec_from_file_location("quiet", {str(quiet)!r})
    spec.loader.exec_module(importlib.util.module_from_spec(spec))
worker = threading.Thread(target=load)
worker.start()
worker.join()
libc = ctypes.CDLL(None)
libc.fprintf(ctypes.c_void_p.in_dll(libc, "stderr"), b"C after\\n")
libc.printf(b"C out after\\n")
libc.fflush(None)
print("Python after", file=sys.stderr)
"""
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    assert "pybullet build time" not in done.stderr + done.stdout
    assert done.stderr.splitlines() == ["C after", "Python after"] and done.stdout == "C out after\n"
    assert threading.active_count() >= 1  # (the test's own process is untouched)
