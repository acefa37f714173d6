"""Clients that misbehave, on purpose or not: each is refused with a status naming what was wrong, its
memory stays bounded, and the other clients and the server carry on.

One server for most tests, with small per-client limits so that reaching them is cheap; loopback only,
every wait bounded.
"""

from __future__ import annotations

import json
import logging
import socket
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from websockets.exceptions import ConnectionClosed

from cbrs.rosbridge import Bridge, GoalHandle, RunningBridge, server, session
from tests.test_rosbridge import WAIT, Client, client_maker

NAMES, CALLS = 20, 4


@pytest.fixture(scope="module")
def gate() -> Iterator[threading.Event]:
    """Holds the blocking handlers until set; set at the end so the server can stop."""
    event = threading.Event()
    yield event
    event.set()


@pytest.fixture(scope="module")
def running(gate: threading.Event) -> Iterator[RunningBridge]:
    bridge = Bridge(call_timeout=WAIT, max_names_per_client=NAMES, max_calls_per_client=CALLS, service_workers=8)
    bridge.params.max_bytes = 4000

    def wait(args: dict[str, Any]) -> dict[str, Any]:
        gate.wait(WAIT)
        return {"waited": True}

    def wait_goal(goal: GoalHandle) -> dict[str, Any]:
        gate.wait(WAIT)
        return {}

    bridge.add_service("/slow", "demo/Slow", wait)
    bridge.add_service("/echo", "demo/Echo", lambda args: args)
    bridge.add_action("/slow_goal", "demo/action/Slow", wait_goal)
    with bridge.start(port=0) as served:
        yield served
        gate.set()


@pytest.fixture
def client(running: RunningBridge) -> Iterator[Callable[[], Client]]:
    with client_maker(running.url) as make:
        yield make


def test_a_client_holding_too_many_names_is_refused_the_next_one(client: Callable[[], Client]) -> None:
    greedy, other = client(), client()
    for n in range(NAMES - 2):
        greedy.send(op="subscribe", topic=f"/many/{n}")
    greedy.send(op="advertise", topic="/many/pub", type="std_msgs/String")
    greedy.send(op="advertise_service", service="/many/srv", type="demo/Srv")
    greedy.send(op="subscribe", topic="/many/0", id="again")  # a name it holds: no new one
    greedy.send(op="subscribe", topic="/many/one_more", id="over")
    status = greedy.expect("status")
    assert (status["level"], status["id"]) == ("error", "over")
    assert "holds 20 topics, services and actions already (max_names_per_client)" in status["msg"]
    greedy.send(op="advertise_action", action="/many/act", type="demo/Act", id="act")
    assert "max_names_per_client" in greedy.expect("status")["msg"]
    other.send(op="subscribe", topic="/many/one_more")  # the limit is per client
    other.sync()
    greedy.send(op="unsubscribe", topic="/many/1")
    greedy.send(op="subscribe", topic="/many/one_more", id="now")
    greedy.sync()
    greedy.nothing()


def test_a_client_with_too_many_calls_in_flight_is_refused_and_others_are_answered(
    client: Callable[[], Client], gate: threading.Event
) -> None:
    gate.clear()
    flooder, other = client(), client()
    try:
        for n in range(CALLS + 2):
            flooder.send(op="call_service", service="/slow", id=f"f{n}")
        refused = [flooder.expect("service_response") for _ in range(2)]
        assert sorted(answer["id"] for answer in refused) == [f"f{CALLS}", f"f{CALLS + 1}"]
        assert all(answer["result"] is False for answer in refused)
        assert "has 4 calls waiting for answers already (max_calls_per_client)" in refused[0]["values"]
        assert flooder.call("/rosapi/get_time")["result"] is True  # rosapi answers at once: not counted
        other.send(op="call_service", service="/echo", id="o", args={"x": 1})
        assert other.expect("service_response")["values"] == {"x": 1}
    finally:
        gate.set()
    answered = [flooder.expect("service_response") for _ in range(CALLS)]
    assert all(answer["values"] == {"waited": True} for answer in answered)
    assert flooder.call("/echo", {"y": 2})["values"] == {"y": 2}  # answered calls no longer count


def test_a_client_with_too_many_goals_in_progress_is_refused(
    client: Callable[[], Client], gate: threading.Event
) -> None:
    gate.clear()
    me = client()
    try:
        for n in range(CALLS + 1):
            me.send(op="send_action_goal", action="/slow_goal", action_type="demo/action/Slow", id=f"g{n}")
        status = me.expect("status")
        refused = me.expect("action_result")
        assert (refused["id"], refused["result"], refused["status"]) == (f"g{CALLS}", False, 0)
        assert "goals in progress already (max_calls_per_client)" in refused["values"]
        assert status["id"] == f"g{CALLS}"
    finally:
        gate.set()
    assert sorted(me.expect("action_result")["id"] for _ in range(CALLS)) == [f"g{n}" for n in range(CALLS)]


def test_parameters_past_the_store_limit_are_refused_and_what_was_set_stays(client: Callable[[], Client]) -> None:
    me = client()
    refused = None
    for n in range(100):
        answer = me.call("/rosapi/set_param", {"name": f"/flood/p{n}", "value": json.dumps("x" * 200)})
        if answer["result"] is False:
            refused = n, answer["values"]
            break
    assert refused is not None, "the store took 100 values of 200 characters past its 4000"
    assert f"parameter '/flood/p{refused[0]}' would bring the parameters to" in refused[1]
    assert "past the limit of 4000: delete some first" in refused[1]
    assert me.call("/rosapi/get_param", {"name": "/flood/p0"})["values"]["value"] == json.dumps("x" * 200)
    me.call("/rosapi/delete_param", {"name": "/flood"})
    assert me.call("/rosapi/set_param", {"name": "/flood/again", "value": "1"})["result"] is True
    me.call("/rosapi/delete_param", {"name": "/flood"})


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        pytest.param({"name": 5}, "field 'name' must be a string, not number", id="object"),
        pytest.param([5], "field 'name' must be a string, not number", id="list"),
        pytest.param({"name": "/a", "value": "{nope"}, "value must be JSON-encoded", id="not-json"),
        pytest.param({"name": "/a", "value": "[" * 5000 + "]" * 5000}, "value is nested too deeply", id="deep"),
    ],
)
def test_a_call_with_args_of_the_wrong_types_fails_naming_the_field(
    client: Callable[[], Client], args: Any, reason: str
) -> None:
    answer = client().call("/rosapi/set_param", args)
    assert answer["result"] is False
    assert reason in answer["values"]
    assert len(answer["values"]) < 400  # the offending value is not echoed whole


def test_a_provider_that_vanishes_without_closing_fails_its_pending_calls(
    running: RunningBridge, client: Callable[[], Client]
) -> None:
    caller = client()
    host, port = running.url.removeprefix("ws://").split(":")
    raw = socket.create_connection((host, int(port)), timeout=WAIT)
    try:
        key = "dGhlIHNhbXBsZSBub25jZQ=="
        raw.sendall(
            f"GET / HTTP/1.1\r\nHost: {host}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
            f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n".encode()
        )
        assert raw.recv(4096).startswith(b"HTTP/1.1 101")
        _send_masked(raw, {"op": "advertise_service", "service": "/ghost", "type": "demo/Ghost"})
        for _ in range(50):  # bounded: until the server lists the service
            if "/ghost" in caller.call("/rosapi/services")["values"]["services"]:
                break
        caller.send(op="call_service", service="/ghost", id="c1")
        caller.send(op="call_service", service="/ghost", id="c2")
        caller.sync()
    finally:
        # linger on, 0 s: close sends a reset, without a close frame
        raw.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, b"\x01\x00\x00\x00\x00\x00\x00\x00")
        raw.close()
    answers = sorted((caller.expect("service_response") for _ in range(2)), key=lambda m: m["id"])
    reason = "the provider of '/ghost' disconnected"
    assert [(a["id"], a["result"], a["values"]) for a in answers] == [("c1", False, reason), ("c2", False, reason)]


def _send_masked(sock: socket.socket, message: dict[str, Any]) -> None:
    """One masked text frame, as a client must send it (RFC 6455), with a zero mask."""
    payload = json.dumps(message).encode()
    assert len(payload) < 126
    sock.sendall(bytes([0x81, 0x80 | len(payload)]) + b"\x00\x00\x00\x00" + payload)


def test_a_client_that_never_reads_its_replies_is_disconnected(
    running: RunningBridge,
    client: Callable[[], Client],
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
) -> None:
    monkeypatch.setattr(session, "REPLY_BACKLOG", 20)
    other = client()
    reader = Client(running.url, small_buffers=True)
    try:
        big = "x" * 200_000
        with caplog.at_level(logging.WARNING, logger="cbrs.rosbridge"):
            for n in range(60):  # replies of 200 kB each that nobody reads: the socket fills, then the backlog
                reader.send(op="call_service", service="/echo", id=n, args={"data": big})
            deadline = time.monotonic() + 30.0  # bounded: until the server has given up on it, however loaded
            while time.monotonic() < deadline:
                other.sync()
                if any("disconnected: 20 replies" in record.getMessage() for record in caplog.records):
                    break
        assert any("disconnected: 20 replies" in record.getMessage() for record in caplog.records)
        with pytest.raises(ConnectionClosed):
            for _ in range(200):  # what was sent before the server gave up, then the end
                reader.ws.recv(timeout=WAIT)
        assert other.call("/echo", {"still": "here"})["values"] == {"still": "here"}
    finally:
        reader.close()


def test_a_frame_past_the_transport_limit_closes_only_that_connection(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(server, "transport_limit", lambda bridge: 1 << 16)
    bridge = Bridge(max_message_bytes=1 << 14)
    with bridge.start(port=0) as running:
        big, other = Client(running.url), Client(running.url)
        try:
            big.send(op="publish", topic="/a", msg={"data": "x" * 30_000})  # past the message limit: a status
            assert "exceeds the limit of 16384 bytes" in big.expect("status")["msg"]
            big.send(op="publish", topic="/a", msg={"data": "x" * 100_000})  # past the frame limit: closed
            with pytest.raises(ConnectionClosed) as closed:
                big.recv()
            assert closed.value.rcvd is not None and closed.value.rcvd.code == 1009
            assert other.call("/rosapi/get_time")["result"] is True
        finally:
            big.close()
            other.close()


def test_a_flood_of_bad_messages_at_level_none_costs_nothing_to_read(client: Callable[[], Client]) -> None:
    me = client()
    me.send(op="set_level", level="none")
    for n in range(2000):
        me.ws.send(f'{{"op": "dance", "id": {n}}}' if n % 2 else "{not json")
    assert me.call("/echo", {"after": "flood"})["values"] == {"after": "flood"}
    me.nothing()


def test_a_subscriber_that_never_reads_many_topics_is_disconnected_past_the_total_bound(
    client: Callable[[], Client], running: RunningBridge, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(session, "QUEUED_BYTES", 4 << 20)  # each queue stays within its own 16 MiB
    publisher, other = client(), client()
    reader = Client(running.url, small_buffers=True)
    try:
        topics = [f"/wide/{n}" for n in range(8)]
        for topic in topics:
            reader.send(op="subscribe", topic=topic)
            publisher.send(op="advertise", topic=topic, type="std_msgs/String")
        reader.sync()
        publisher.sync()
        chunk = "x" * 200_000
        for _ in range(8):  # 64 messages of 200 kB, 12.8 MB in all, 1.6 MB per queue
            for topic in topics:
                publisher.send(op="publish", topic=topic, msg={"data": chunk})
        publisher.sync()
        with pytest.raises(ConnectionClosed):
            for _ in range(100):  # what left before the server gave up on it, then the end
                reader.ws.recv(timeout=WAIT)
        assert other.call("/echo", {"fine": True})["values"] == {"fine": True}
    finally:
        reader.close()


def test_the_bytes_a_session_holds_are_its_queues_and_replies() -> None:
    aborted: list[str] = []

    async def send(frame: Any) -> None:
        return None

    me = session.Session("s", send, aborted.append, backlog=5)
    me.subscribe("/a", "/a", None, 0, 0)
    me.subscribe("/b", "/b", "q", 1000, 2)
    for n in range(8):
        me.offer("/a", "a" * (n + 1))
        me.offer("/b", "b" * 10)
    me.reply("r" * 7)

    def held() -> int:
        return sum(queue.size for queue in me.queues.values()) + 7

    assert me.pending_bytes == held() == (4 + 5 + 6 + 7 + 8) + 2 * 10 + 7
    me.subscribe("/a", "/a", "short", 0, 1)  # a second request with a shorter queue: the longest applies
    me.unsubscribe("/a", None, every=False)
    assert me.pending_bytes == held() == 8 + 2 * 10 + 7
    me.unsubscribe("/b", None, every=True)
    assert me.pending_bytes == held() == 8 + 7
    assert not aborted
