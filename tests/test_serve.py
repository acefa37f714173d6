"""``cbrs serve``: the HTTP endpoint and the rosbridge interface together, over loopback.

Every wait is bounded; servers listen on free ports picked by the OS.
"""

from __future__ import annotations

import contextlib
import http.client
import json
import os
import queue
import signal
import subprocess
import sys
import threading
import time
import urllib.parse
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from websockets.exceptions import InvalidStatus
from websockets.sync.client import ClientConnection, connect
from websockets.typing import Origin

from cbrs.bridge_services import TOPICS
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import expand
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig
from tests.conftest import OxigraphServer
from tests.helpers_seeded import put_quads, seeded_quads
from tests.helpers_threads import assert_threads_end
from tests.test_rosapi_typedefs import cbrs_types, mismatches

WAIT = 10.0
TOKEN = "serve-test-token"


@pytest.fixture
def server(fresh_bundled_kb: KnowledgeBase) -> Iterator[Server]:
    threads = threading.active_count()
    config = ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN))
    running = Server(fresh_bundled_kb, config)
    running.start()
    yield running
    running.stop(timeout=WAIT)
    assert_threads_end(threads, WAIT)


@contextlib.contextmanager
def bridge(server: Server, token: str | None = None) -> Iterator[ClientConnection]:
    """A websocket to the bridge; with ``token``, authorised to write (op auth) before it is handed over."""
    with connect(f"ws://127.0.0.1:{server.bridge_port}", open_timeout=WAIT, close_timeout=WAIT) as ws:
        if token is not None:
            ws.send(json.dumps({"op": "set_level", "level": "info"}))
            ws.send(json.dumps({"op": "auth", "id": "auth", "mac": token}))
            answer = receive(ws, "status", id="auth")
            assert answer["level"] == "info", answer
            ws.send(json.dumps({"op": "set_level", "level": "error"}))
        yield ws


def receive(ws: ClientConnection, op: str, timeout: float = WAIT, **match: Any) -> dict[str, Any]:
    """The next message with ``op`` (and the given field values), skipping others; bounded."""
    deadline = time.monotonic() + timeout
    while True:
        message = json.loads(ws.recv(timeout=max(0.01, deadline - time.monotonic())))
        if message.get("op") == op and all(message.get(k) == v for k, v in match.items()):
            return message


def call(ws: ClientConnection, service: str, args: dict[str, Any], timeout: float = WAIT) -> dict[str, Any]:
    call_id = f"call:{service}:{time.monotonic_ns()}"
    ws.send(json.dumps({"op": "call_service", "id": call_id, "service": service, "args": args}))
    return receive(ws, "service_response", timeout, id=call_id)


def test_http_and_bridge_answer_on_loopback(server: Server) -> None:
    assert server.config.host == "127.0.0.1"
    base = f"http://127.0.0.1:{server.http_port}"
    health = httpx.get(base + "/healthz", timeout=WAIT)
    assert health.json()["status"] == "ok"
    answer = httpx.get(base + "/sparql", params={"query": "ASK { ?s a cbrs:Advertisement }"}, timeout=WAIT)
    assert answer.json()["boolean"] is False  # advertisements are typed by their component kind
    with bridge(server) as ws:
        response = call(ws, "/rosapi/services", {})
    assert response["result"] is True
    assert {"/cbrs/query", "/cbrs/match", "/cbrs/plan", "/cbrs/run_task"} <= set(response["values"]["services"])


def test_query_service_returns_sparql_json(server: Server) -> None:
    with bridge(server) as ws:
        response = call(ws, "/cbrs/query", {"query": "SELECT ?d WHERE { ?s cbrs:deviceName ?d } ORDER BY ?d LIMIT 2"})
    assert response["result"] is True
    values = response["values"]
    assert values["media_type"] == "application/sparql-results+json"
    assert values["result"]["head"]["vars"] == ["d"]
    assert len(values["result"]["results"]["bindings"]) == 2


def test_query_service_refuses_updates_and_reports_syntax_errors(server: Server) -> None:
    before = server.kb.store.dump()
    with bridge(server) as ws:
        update = call(ws, "/cbrs/query", {"query": "INSERT DATA { <urn:a> <urn:b> <urn:c> }"})
        broken = call(ws, "/cbrs/query", {"query": "SELECT ?x WHERE {"})
        missing = call(ws, "/cbrs/query", {})
    assert update["result"] is False and "syntax error" in str(update["values"]).lower()
    assert broken["result"] is False and "syntax error" in str(broken["values"]).lower()
    assert missing["result"] is False and "query" in str(missing["values"])
    assert server.kb.store.dump() == before


def test_match_service_ranks_like_the_library(server: Server) -> None:
    expected = Matchmaker(server.kb).rank(expand("req:RobotSelfPosition")).candidates[0].advertisement
    with bridge(server) as ws:
        response = call(ws, "/cbrs/match", {"requirement": "RobotSelfPosition", "top": 3})
        wrong = call(ws, "/cbrs/match", {"requirement": "RobotSelfPosition", "top": "three"})
    assert response["result"] is True
    ranked = response["values"]["candidates"]
    assert len(ranked) == 3
    assert ranked[0]["advertisement"] == expected
    assert ranked[0]["pairs"]  # the explanation travels with the score
    assert wrong["result"] is False and "top" in str(wrong["values"])


def test_plan_service_plans_and_records_the_plan(server: Server) -> None:
    with bridge(server, TOKEN) as ws:
        response = call(ws, "/cbrs/plan", {"task": "FetchMyPen"})
        unknown = call(ws, "/cbrs/plan", {"task": "FlyToTheMoon"})
    assert response["result"] is True
    plan = response["values"]
    assert plan["status"] == "planned"
    assert len(plan["steps"]) > 5
    recorded = server.kb.query("ASK { ?plan cbrs:planFor req:FetchMyPen }")
    assert bool(recorded)
    assert unknown["result"] is False and "FlyToTheMoon" in str(unknown["values"])


def test_run_task_streams_progress_and_ends_succeeded(server: Server) -> None:
    with bridge(server) as watcher, bridge(server, TOKEN) as caller:
        for topic in ("/cbrs/task_progress", "/cbrs/lifecycle", "/cbrs/events", "/cbrs/task"):
            watcher.send(json.dumps({"op": "subscribe", "topic": topic}))
        time.sleep(0.2)  # let the subscriptions land before the run starts
        response = call(caller, "/cbrs/run_task", {"task": "RobotArmServeACup", "seed": 1}, timeout=120)
        heard: list[dict[str, Any]] = []
        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline:
            message = receive(watcher, "publish", timeout=deadline - time.monotonic())
            heard.append(message)
            if message["topic"] == "/cbrs/events" and message["msg"].get("event") == "run_finished":
                break
    assert response["result"] is True
    run = response["values"]
    assert run["status"] == "succeeded"
    assert run["result"]["execution"]["status"] == "succeeded"
    progress = [m["msg"] for m in heard if m["topic"] == "/cbrs/task_progress"]
    assert progress[0]["event"] == "step_started" and progress[0]["run"] == run["id"]
    assert sum(1 for p in progress if p["event"] == "step_succeeded") == len(run["result"]["plan"]["steps"])
    assert any(m["topic"] == "/cbrs/lifecycle" for m in heard)
    finished = [m["msg"] for m in heard if m["topic"] == "/cbrs/events"]
    naming = {"run": run["id"], "task": "RobotArmServeACup", "iri": run["iri"], "shown": "RobotArmServeACup"}
    assert finished[-1] == {"event": "run_finished", **naming, "status": run["status"]}
    assert (run["shown"], finished[0]) == ("RobotArmServeACup", {"event": "run_started", **naming})
    named = [m["msg"] for m in heard if m["topic"] in ("/cbrs/task_progress", "/cbrs/task")]
    assert named and {(m["iri"], m["shown"]) for m in named} == {(run["iri"], run["shown"])}  # one name throughout
    assert {m["task"] for m in named if "task" in m} == {run["iri"]}  # the plan's task, as before
    types = cbrs_types()  # every message and the reply are what rosapi's typedefs say
    assert mismatches(types.response("cbrs/RunTask"), run) == []
    assert {"/cbrs/task_progress", "/cbrs/lifecycle", "/cbrs/events"} <= {m["topic"] for m in heard} <= set(TOPICS)
    assert [p for m in heard for p in mismatches(types.message(TOPICS[m["topic"]]), m["msg"], m["topic"])] == []


def test_run_task_without_waiting_then_status_and_one_at_a_time(server: Server) -> None:
    with bridge(server, TOKEN) as ws:  # a one-step task: its world takes a second to build, long enough to be busy
        started = call(ws, "/cbrs/run_task", {"task": "FindCupOnTable", "wait": False})
        assert started["result"] is True
        run_id = started["values"]["id"]
        busy = call(ws, "/cbrs/run_task", {"task": "FetchMyPen", "wait": False})
        bad_fault = call(ws, "/cbrs/run_task", {"task": "FetchMyPen", "fail": ["svc:NoSuchThing"]})
        status: dict[str, Any] = {}
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            status = call(ws, "/cbrs/task_status", {"run": run_id})["values"]
            if status["status"] != "running":
                break
            time.sleep(0.2)
    assert busy["result"] is False and "one task runs at a time" in str(busy["values"])
    assert bad_fault["result"] is False and "NoSuchThing" in str(bad_fault["values"])
    assert status["status"] == "succeeded"
    assert any(e.get("event") == "step_succeeded" for e in status["events"])
    assert mismatches(cbrs_types().response("cbrs/TaskStatus"), status) == []


def test_update_over_http_is_announced_on_the_bridge(server: Server) -> None:
    with bridge(server) as ws:
        ws.send(json.dumps({"op": "subscribe", "topic": "/cbrs/events"}))
        time.sleep(0.2)
        refused = httpx.post(
            f"http://127.0.0.1:{server.http_port}/update",
            content=b"INSERT DATA { <urn:a> <urn:b> <urn:c> }",
            headers={"Content-Type": "application/sparql-update"},
            timeout=WAIT,
        )
        assert refused.status_code == 403
        accepted = httpx.post(
            f"http://127.0.0.1:{server.http_port}/update",
            content=b"INSERT DATA { <urn:a> <urn:b> <urn:c> }",
            headers={"Content-Type": "application/sparql-update", "Authorization": f"Bearer {TOKEN}"},
            timeout=WAIT,
        )
        assert accepted.status_code == 204
        message = receive(ws, "publish", topic="/cbrs/events")
    assert message["msg"] == {"event": "store_updated"}


# -- the command -----------------------------------------------------------------------------------


class Output:
    """A child's output lines, read by a thread so that every wait for one is bounded."""

    def __init__(self, process: subprocess.Popen[str]) -> None:
        assert process.stdout is not None
        stdout = process.stdout
        self.lines: queue.Queue[str] = queue.Queue()
        threading.Thread(target=lambda: [self.lines.put(line) for line in stdout], daemon=True).start()

    def until(self, marker: str, timeout: float) -> list[str]:
        seen: list[str] = []
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=max(0.01, deadline - time.monotonic()))
            except queue.Empty:
                break
            seen.append(line.rstrip("\n"))
            if marker in line:
                return seen
        raise AssertionError(f"no {marker!r} within {timeout} s; saw {seen}")


def test_cbrs_serve_command_serves_until_ctrl_c(tmp_path: Any) -> None:
    env = dict(os.environ, CBRS_STORE=":memory:", HOME=str(tmp_path), CBRS_QUERY_WORKERS="2")
    env.pop("CBRS_UPDATE_TOKEN", None)
    command = [sys.executable, "-m", "cbrs", "serve", "--port", "0", "--bridge-port", "0"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=env)
    try:
        output = Output(process)
        lines = output.until("Ctrl-C stops", timeout=60)
        assert "read-only" in lines[0]
        sparql_line = next(line for line in lines if line.strip().startswith("SPARQL"))
        assert "(2 query workers, 30 s timeout)" in sparql_line
        sparql_url = sparql_line.split()[1]
        bridge_url = next(line.split()[-1] for line in lines if line.strip().startswith("rosbridge"))
        assert sparql_url.startswith("http://127.0.0.1:") and bridge_url.startswith("ws://127.0.0.1:")
        answer = httpx.get(sparql_url, params={"query": "ASK { ?s ?p ?o }"}, timeout=WAIT)
        assert answer.json()["boolean"] is True
        browser_url = next(line.split()[-1] for line in lines if line.strip().startswith("browser"))
        assert "<h1>Overview</h1>" in httpx.get(browser_url, timeout=WAIT).text  # where a new user looks first
        with connect(bridge_url, open_timeout=WAIT) as ws:
            assert call(ws, "/rosapi/get_param_names", {})["result"] is True
        process.send_signal(signal.SIGINT)
        assert process.wait(timeout=30) == 0
        assert output.until("stopped", timeout=5)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait(5)


def test_bridge_admits_its_own_pages_and_clients_without_origin_but_not_other_sites(server: Server) -> None:
    url = f"ws://127.0.0.1:{server.bridge_port}"
    with connect(url, open_timeout=WAIT) as ws:  # roslibpy, node, a sensor board: no Origin header
        assert call(ws, "/rosapi/get_time", {})["result"] is True
    own = f"http://127.0.0.1:{server.http_port}"
    with connect(url, origin=Origin(own), open_timeout=WAIT) as ws:  # a page this server served
        assert call(ws, "/rosapi/get_time", {})["result"] is True
    with pytest.raises(InvalidStatus) as refused:
        connect(url, origin=Origin("http://evil.example"), open_timeout=WAIT)
    assert refused.value.response.status_code == 403


def test_stopping_the_server_ends_open_event_streams(fresh_bundled_kb: KnowledgeBase) -> None:
    running = Server(fresh_bundled_kb, ServeConfig(port=0, bridge_port=0))
    running.start()
    received: list[str] = []

    def listen() -> None:
        url = f"http://127.0.0.1:{running.http_port}/tasks/events"
        with httpx.stream("GET", url, timeout=WAIT) as response:
            for line in response.iter_lines():
                received.append(line)

    listener = threading.Thread(target=listen, daemon=True)
    listener.start()
    deadline = time.monotonic() + WAIT
    while not any("hello" in line for line in received) and time.monotonic() < deadline:
        time.sleep(0.05)
    running.stop(timeout=WAIT)
    listener.join(WAIT)
    assert not listener.is_alive()
    assert [line for line in received if line][-1] == 'data: {"event":"end","reason":"closing"}'


def test_stop_closes_the_http_listener_with_a_kept_alive_connection_open(fresh_bundled_kb: KnowledgeBase) -> None:
    """Granian's threads, the loop and the adapter's threads all end; the port no longer answers."""
    threads = threading.active_count()
    running = Server(fresh_bundled_kb, ServeConfig(port=0, bridge_port=0))
    running.start()
    port = running.http_port
    kept = httpx.Client(timeout=WAIT)  # one connection, kept alive across both requests below
    try:
        assert kept.get(f"http://127.0.0.1:{port}/healthz").status_code == 200  # through Flask
        lookup = kept.get(f"http://127.0.0.1:{port}/sparql", params={"query": "ASK {}"})  # the ASGI front
        assert lookup.json()["boolean"] is True
        running.stop(timeout=WAIT)
        with pytest.raises(httpx.ConnectError):
            httpx.get(f"http://127.0.0.1:{port}/healthz", timeout=WAIT)
    finally:
        kept.close()
    assert_threads_end(threads, WAIT)


def test_one_long_query_leaves_the_server_answering_others_and_is_stopped_at_its_deadline(tmp_path: Path) -> None:
    endless = (  # an aggregate over a 6000 x 6000 product: minutes of work, never interrupted by Oxigraph
        "SELECT (COUNT(*) AS ?n) WHERE { { SELECT ?a WHERE { ?a ?p ?x } LIMIT 6000 } "
        "{ SELECT ?b WHERE { ?b ?q ?y } LIMIT 6000 } FILTER (?a != ?b) }"
    )
    kb = KnowledgeBase.open(tmp_path / "store")
    server = Server(kb, ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(timeout=3.0, workers=2)))
    server.start()
    try:
        port = server.http_port

        def ask(query: str, source: str) -> tuple[int, bytes]:
            connection = http.client.HTTPConnection("127.0.0.1", port, timeout=30, source_address=(source, 0))
            connection.request("GET", "/sparql?" + urllib.parse.urlencode({"query": query}))
            response = connection.getresponse()
            answer = response.status, response.read()
            connection.close()
            return answer

        long_answer: list[tuple[int, bytes]] = []
        runner = threading.Thread(target=lambda: long_answer.append(ask(endless, "127.0.0.1")))
        runner.start()
        deadline = time.monotonic() + 10
        while server.sparql._slots._value == 2 and time.monotonic() < deadline:  # type: ignore[attr-defined]
            time.sleep(0.01)  # until the long query holds its worker
        lookups = [ask("SELECT ?p ?o WHERE { home:Cup ?p ?o }", "127.0.0.2") for _ in range(5)]
        lookups.append(ask("SELECT (COUNT(*) AS ?n) WHERE { ?s a ?c }", "127.0.0.2"))  # the other worker
        assert runner.is_alive()  # all answered while the long query still ran
        assert [status for status, _ in lookups] == [200] * 6
        runner.join(30)
        status, body = long_answer[0]
        assert status == 503 and json.loads(body)["error"] == "timeout"
        assert server.sparql.processes is not None and server.sparql.processes.killed == 1
        assert ask(endless.replace("6000", "3"), "127.0.0.1")[0] == 200  # its worker slot is free again
    finally:
        server.stop()
        kb.close()


def test_the_bridge_gets_its_action_workers_from_the_setting(monkeypatch: pytest.MonkeyPatch) -> None:
    kb = KnowledgeBase.open(":memory:")
    monkeypatch.setenv("CBRS_ACTION_WORKERS", "2")
    assert Server(kb, ServeConfig(port=0, bridge_port=0)).bridge.action_workers == 2
    monkeypatch.setenv("CBRS_ACTION_WORKERS", "none")
    with pytest.raises(ValueError, match="CBRS_ACTION_WORKERS='none'"):
        ServeConfig()
    kb.close()


def test_cbrs_serve_on_a_store_url_with_a_password_does_not_print_it(
    tmp_path: Any, remote_location: str, oxigraph_server: OxigraphServer
) -> None:
    """The banner names the store; a remote store's URL may carry HTTP basic credentials (Oxigraph's
    server ignores them), and the banner ends up in terminals and logs."""
    put_quads(oxigraph_server, seeded_quads())  # a seeded server: the child need not seed it (some 3 s)
    with_password = remote_location.replace("http://", "http://robot:s3cret@", 1)
    env = dict(os.environ, CBRS_STORE=with_password, HOME=str(tmp_path), CBRS_QUERY_WORKERS="1")
    env.pop("CBRS_UPDATE_TOKEN", None)
    command = [sys.executable, "-m", "cbrs", "serve", "--port", "0", "--bridge-port", "0"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=env)
    try:
        lines = Output(process).until("Ctrl-C stops", timeout=120)
        assert "robot:***@" in lines[0] and "s3cret" not in "\n".join(lines)
    finally:
        process.terminate()
        process.wait(timeout=30)
