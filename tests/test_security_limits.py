"""Security issue 20, items 2-4, 6 and 8: what one client can take from the others, and who may write.

- A query past its deadline (or its memory budget) is stopped: its worker process is killed, so the
  slot is free at once, and a SERVICE to a tarpit endpoint (federation allowed) is bounded the same way.
- One client (an IP address) runs at most ``workers_per_client`` queries and holds at most
  ``streams_per_client`` streams; streams have threads of their own, so ``/sparql`` keeps answering.
- The rosbridge outbox is bounded in bytes and emptied when its client goes.
- Anonymous clients only read, on the bridge as on HTTP; the server's topics and services are its own.
- ``Origin`` and ``Host`` are checked against the address the server binds, and pages carry a CSP.

Network use is loopback only (a second client is told apart by binding 127.0.0.2); every wait is bounded.
"""

from __future__ import annotations

import asyncio
import json
import socket
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest

from cbrs.kb import KnowledgeBase
from cbrs.rosbridge import Bridge
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointBusyError, EndpointConfig, QueryMemoryError, QueryTimeoutError, SparqlService
from tests.test_serve import bridge, call, receive

WAIT = 10.0
TOKEN = "security-test-token"
# About 1.9e11 solutions on the bundled store: it never finishes by itself within a test.
HEAVY = "SELECT (COUNT(*) AS ?n) WHERE { ?a ?b ?c . ?d ?e ?f . ?g ?h ?i }"
# Some 2 KB more of answer per row of a product of the store with itself: past 200 MiB within a second or two
# (without the padding it took 7 to 15 s).
GROWING = (
    'SELECT (GROUP_CONCAT(CONCAT(STR(?a), STR(?c), STR(?f), "' + "x" * 2000 + '")) AS ?n) WHERE { ?a ?b ?c . ?d ?e ?f }'
)
POINT = "ASK { GRAPH ?g { <https://w3id.org/cbrs/core#hasPort> ?p ?o } }"


@pytest.fixture(scope="module")
def disk_kb(tmp_path_factory: pytest.TempPathFactory) -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(tmp_path_factory.mktemp("security") / "store")
    yield kb
    kb.close()


def service(kb: KnowledgeBase, **config: Any) -> SparqlService:
    return SparqlService(kb, EndpointConfig(**{"update_token": TOKEN, **config}))


# -- item 2: a stopped query frees its worker --------------------------------------------------------


def test_a_query_past_its_deadline_is_killed_and_its_only_worker_answers_the_next(disk_kb: KnowledgeBase) -> None:
    sparql = service(disk_kb, timeout=1.0, workers=1)
    try:
        with pytest.raises(QueryTimeoutError, match="it was stopped"):
            sparql.query(HEAVY)
        # the runaway query no longer holds the one worker: the next query gets it (it was "busy" before)
        assert json.loads(sparql.query(POINT).body)["boolean"] is True
        with pytest.raises(QueryTimeoutError):
            sparql.query(HEAVY)
        assert sparql.processes is not None and sparql.processes.killed == 2
    finally:
        sparql.close()


def test_a_query_that_outgrows_its_memory_is_stopped_with_422(disk_kb: KnowledgeBase) -> None:
    sparql = service(disk_kb, timeout=30.0, workers=1, memory=200 << 20)
    try:
        with pytest.raises(QueryMemoryError) as refused:
            sparql.query(GROWING)
        assert refused.value.http_status == 422 and "query_memory" in str(refused.value)
        assert json.loads(sparql.query(POINT).body)["boolean"] is True
    finally:
        sparql.close()


def test_a_query_sees_every_write_made_before_it(disk_kb: KnowledgeBase) -> None:
    sparql = service(disk_kb)
    try:
        ask = "ASK { GRAPH ?g { <urn:security:a> <urn:security:b> ?n } }"
        assert json.loads(sparql.query(ask).body)["boolean"] is False
        sparql.update("INSERT DATA { GRAPH <urn:security:g> { <urn:security:a> <urn:security:b> 1 } }", TOKEN)
        assert json.loads(sparql.query(ask).body)["boolean"] is True
        disk_kb.update("DROP GRAPH <urn:security:g>")  # a write through the library, not the endpoint
        assert json.loads(sparql.query(ask).body)["boolean"] is False
    finally:
        sparql.close()


def test_one_client_cannot_take_every_worker(disk_kb: KnowledgeBase) -> None:
    sparql = service(disk_kb, timeout=3.0, workers=3, workers_per_client=2)
    outcomes: list[str] = []

    def heavy() -> None:
        try:
            sparql.query(HEAVY, client="10.0.0.1")
        except (QueryTimeoutError, EndpointBusyError) as error:
            outcomes.append(type(error).__name__)

    holders = [threading.Thread(target=heavy) for _ in range(2)]
    try:
        for holder in holders:
            holder.start()
        deadline = time.monotonic() + WAIT
        while sparql._clients.get("10.0.0.1", 0) < 2 and time.monotonic() < deadline:
            time.sleep(0.01)
        with pytest.raises(EndpointBusyError, match=r"10\.0\.0\.1 already runs 2 queries"):
            sparql.query(POINT, client="10.0.0.1")
        other = sparql.query(POINT, client="10.0.0.2")
        assert json.loads(other.body)["boolean"] is True
    finally:
        for holder in holders:
            holder.join(WAIT)
        sparql.close()
    assert outcomes == ["QueryTimeoutError", "QueryTimeoutError"]


class Tarpit:
    """A loopback port that accepts connections and never answers, until stopped."""

    def __init__(self) -> None:
        self.socket = socket.create_server(("127.0.0.1", 0))
        self.socket.settimeout(0.2)
        self.port = self.socket.getsockname()[1]
        self.stopping = threading.Event()
        self.held: list[socket.socket] = []
        self.thread = threading.Thread(target=self._accept, daemon=True)
        self.thread.start()

    def _accept(self) -> None:
        while not self.stopping.is_set():
            try:
                connection, _ = self.socket.accept()
            except TimeoutError:
                continue
            self.held.append(connection)

    def stop(self) -> None:
        self.stopping.set()
        self.thread.join(WAIT)
        for connection in self.held:
            connection.close()
        self.socket.close()


def test_an_allowed_service_endpoint_that_never_answers_costs_one_deadline(tmp_path: Path) -> None:
    tarpit = Tarpit()
    kb = KnowledgeBase.open(tmp_path / "store", remote_access=(f"http://127.0.0.1:{tarpit.port}/",))
    sparql = service(kb, timeout=1.0, workers=1)
    try:
        with pytest.raises(QueryTimeoutError):
            sparql.query(f"SELECT * WHERE {{ SERVICE <http://127.0.0.1:{tarpit.port}/sparql> {{ ?s ?p ?o }} }}")
        assert json.loads(sparql.query(POINT).body)["boolean"] is True  # the one worker is free again
        assert tarpit.held  # the endpoint was reached: federation was allowed
    finally:
        sparql.close()
        kb.close()
        tarpit.stop()


# -- items 4, 6 and 8 on a served server --------------------------------------------------------------------


@pytest.fixture(scope="module")
def served(disk_kb: KnowledgeBase) -> Iterator[Server]:
    """One server for the module: each test leaves it as it found it (its streams and sockets closed)."""
    config = ServeConfig(
        port=0,
        bridge_port=0,
        endpoint=EndpointConfig(update_token=TOKEN, timeout=5.0),
        http_threads=1,  # one request thread: a stream that took it would leave /sparql unanswered
        stream_limit=2,
        streams_per_client=1,
    )
    server = Server(disk_kb, config)
    server.app.config.update(CBRS_STREAM_SECONDS=30.0, CBRS_STREAM_IDLE_SECONDS=30.0, CBRS_HEARTBEAT_SECONDS=0.5)
    server.start()
    yield server
    server.stop(timeout=WAIT)


def client(address: str = "127.0.0.1") -> httpx.Client:
    return httpx.Client(transport=httpx.HTTPTransport(local_address=address), timeout=WAIT)


def test_streams_have_their_own_threads_and_one_client_gets_one(served: Server) -> None:
    base = f"http://127.0.0.1:{served.http_port}"
    with (
        client() as first,
        client("127.0.0.2") as second,
        client() as third,
        first.stream("GET", base + "/tasks/events") as stream,
    ):
        assert stream.status_code == 200
        # Keep the iterator: httpx closes the connection when a dropped one is collected, and the server
        # then rightly frees the slot at its next heartbeat (under load, before the checks below ran).
        lines = stream.iter_lines()
        next(lines)
        refused = third.get(base + "/tasks/events")
        assert refused.status_code == 503 and "streams_per_client" in refused.text
        answer = second.get(base + "/sparql", params={"query": POINT})
        assert answer.status_code == 200 and answer.json()["boolean"] is True
        with second.stream("GET", base + "/tasks/events") as other:
            assert other.status_code == 200
            full = client("127.0.0.3").get(base + "/tasks/events")
            assert full.status_code == 503 and "stream_limit" in full.text
            assert third.get(base + "/sparql", params={"query": POINT}).json()["boolean"] is True
            assert served.app.extensions["cbrs.streams"].open == 2  # both streams still held
    deadline = time.monotonic() + WAIT  # closed streams give their slots back
    while served.app.extensions["cbrs.streams"].open and time.monotonic() < deadline:
        time.sleep(0.05)
    assert served.app.extensions["cbrs.streams"].open == 0


def test_anonymous_bridge_clients_only_read(served: Server) -> None:
    before = served.kb.store.dump()
    with bridge(served) as ws:
        planned = call(ws, "/cbrs/plan", {"task": "FetchMyPen"})
        run = call(ws, "/cbrs/run_task", {"task": "FetchMyPen"})
        ws.send(json.dumps({"op": "auth", "id": "wrong", "mac": "not-the-token"}))
        wrong = receive(ws, "status", id="wrong")
        still = call(ws, "/cbrs/run_task", {"task": "FetchMyPen"})
    assert planned["result"] is True and planned["values"]["status"] == "planned"
    assert planned["values"]["recorded"] is False
    assert run["result"] is False and "update token" in run["values"]
    assert wrong["level"] == "error" and "not this server's update token" in wrong["msg"]
    assert still["result"] is False
    assert served.kb.store.dump() == before


def test_a_page_of_the_server_itself_may_record_a_plan(served: Server) -> None:
    from websockets.sync.client import connect
    from websockets.typing import Origin

    page = Origin(f"http://127.0.0.1:{served.http_port}")
    with connect(f"ws://127.0.0.1:{served.bridge_port}", origin=page, open_timeout=WAIT) as ws:
        planned = call(ws, "/cbrs/plan", {"task": "FetchMyPen"})
    assert planned["values"]["recorded"] is True


@pytest.mark.parametrize(
    "message",
    [
        pytest.param(
            {"op": "advertise", "topic": "/cbrs/task", "type": "cbrs/TaskStatus"}, id="advertise-server-topic"
        ),
        pytest.param({"op": "publish", "topic": "/cbrs/task", "msg": {"status": "succeeded"}}, id="publish-verdict"),
        pytest.param({"op": "advertise", "topic": "/cbrs/new", "type": "std_msgs/String"}, id="advertise-in-namespace"),
        pytest.param({"op": "advertise_service", "service": "/cbrs/query", "type": "x/Y"}, id="take-server-service"),
        pytest.param({"op": "advertise_service", "service": "/cbrs/verdict", "type": "x/Y"}, id="service-namespace"),
    ],
)
def test_clients_cannot_speak_for_the_server(served: Server, message: dict[str, Any]) -> None:
    with bridge(served, TOKEN) as spoofer, bridge(served) as listener:
        listener.send(json.dumps({"op": "subscribe", "topic": "/cbrs/task"}))
        time.sleep(0.1)
        spoofer.send(json.dumps({**message, "id": "spoof"}))
        refused = receive(spoofer, "status", id="spoof")
        assert refused["level"] == "error" and "server" in refused["msg"]
        with pytest.raises(TimeoutError):
            receive(listener, "publish", timeout=0.3)
    assert ("/cbrs/verdict", "x/Y") not in served.bridge.services()


def test_a_task_without_origin_needs_the_token(served: Server) -> None:
    base = f"http://127.0.0.1:{served.http_port}"
    with client() as http:
        anonymous = http.post(base + "/tasks.json", data={"task": "NoSuchTask"})
        with_token = http.post(
            base + "/tasks.json", data={"task": "NoSuchTask"}, headers={"Authorization": f"Bearer {TOKEN}"}
        )
        from_page = http.post(base + "/tasks.json", data={"task": "NoSuchTask"}, headers={"Origin": base})
    assert anonymous.status_code == 403 and "update token" in anonymous.json()["message"]
    assert with_token.status_code == 400 and "NoSuchTask" in with_token.text  # past the gate, to the form
    assert from_page.status_code == 400


def test_dns_rebinding_is_refused_by_host_and_origin(served: Server) -> None:
    port = served.http_port
    rebound = f"evil.example:{port}"
    with client() as http:
        read = http.get(f"http://127.0.0.1:{port}/sparql", params={"query": POINT}, headers={"Host": rebound})
        task = http.post(
            f"http://127.0.0.1:{port}/tasks.json",
            data={"task": "FetchMyPen"},
            headers={"Host": rebound, "Origin": f"http://{rebound}"},
        )
        local = http.get(f"http://localhost:{port}/sparql", params={"query": POINT})
    assert read.status_code == 421 and "evil.example" in read.text
    assert task.status_code == 421
    assert local.status_code == 200


def test_pages_cannot_be_framed_or_sniffed(served: Server) -> None:
    with client() as http:
        page = http.get(f"http://127.0.0.1:{served.http_port}/services")
        answer = http.get(f"http://127.0.0.1:{served.http_port}/sparql", params={"query": POINT})
    policy = page.headers["Content-Security-Policy"]
    assert "frame-ancestors 'none'" in policy and "default-src 'self'" in policy
    nonce = policy.split("'nonce-", 1)[1].split("'", 1)[0]
    assert f'<script nonce="{nonce}">' in page.text  # the page's own inline script still runs
    assert page.headers["X-Frame-Options"] == "DENY"
    assert page.headers["X-Content-Type-Options"] == "nosniff"
    assert answer.headers["X-Content-Type-Options"] == "nosniff"


# -- item 5: the rosbridge outbox ---------------------------------------------------------------------------


def test_the_outbox_is_bounded_in_bytes_and_freed_when_its_client_goes() -> None:
    async def scenario() -> tuple[int, int, int]:
        bridge_core = Bridge(max_queue_bytes=4 << 20)
        bridge_core.add_topic("/big", "std_msgs/String")
        bridge_core.attach(asyncio.get_running_loop())
        never = asyncio.Event()

        async def stuck(text: str) -> None:  # a client that never reads: its socket is full
            await never.wait()

        session = bridge_core.open_session("slow", stuck, lambda reason: None)
        bridge_core.receive(session, json.dumps({"op": "subscribe", "topic": "/big", "queue_length": 1000}))
        for number in range(40):
            bridge_core._fan_out("/big", json.dumps({"data": str(number) * 900_000}))
        await asyncio.sleep(0)
        held = session.pending_bytes
        newest_kept = "393939" in next(iter(session.queues.values()))._pending[-1][1]
        bridge_core.close_session(session)
        await bridge_core.detach()
        return held, session.pending_bytes, int(newest_kept)

    held, after, newest_kept = asyncio.run(scenario())
    assert held <= (4 << 20) + 1_000_000  # 40 messages of 900 KB would be 36 MB
    assert newest_kept == 1
    assert after == 0
