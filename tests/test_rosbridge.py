"""The rosbridge v2 server: its queue and parameter bookkeeping, then every op over a real websocket.

Protocol tests talk JSON to ``Bridge.start(port=0)`` on loopback with the websockets sync client; every
receive has a timeout, so a missing answer fails the test instead of hanging it.
"""

from __future__ import annotations

import asyncio
import itertools
import json
import socket
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from typing import Any

import pytest
from websockets.asyncio.client import connect as ws_connect
from websockets.asyncio.server import ServerConnection
from websockets.asyncio.server import serve as ws_serve
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect

from cbrs.rosbridge import Bridge, ParamStore, RosbridgeError, RunningBridge, ServiceError, UnknownTopicError
from cbrs.rosbridge.outbox import TopicQueue
from cbrs.rosbridge.server import send_frames
from cbrs.rosbridge.session import WRITE_BATCH, WRITE_BATCH_CHARS, Session
from cbrs.rosbridge.workers import WorkerPool
from tests.helpers_threads import assert_threads_end

WAIT = 3.0  # seconds any single answer may take before a test fails


# -- the per-subscriber queue, on a hand-stepped clock -------------------------------------------


def drain(queue: TopicQueue, now: float) -> list[str]:
    """What a client that reads instantly receives at time ``now``."""
    out = []
    while (ready := queue.ready_at()) is not None and ready <= now:
        out.append(queue.pop(now))
    return out


def test_pass_through_sends_everything_in_order_within_the_backlog() -> None:
    queue = TopicQueue(backlog=5)
    queue.add(None, 0, 0)
    for seq in range(1, 4):
        queue.push(seq, f"m{seq}")
    assert drain(queue, 0.0) == ["m1", "m2", "m3"]
    for seq in range(1, 9):  # a reader 8 messages behind with a backlog of 5 loses the 3 oldest
        queue.push(seq, f"n{seq}")
    assert drain(queue, 0.0) == ["n4", "n5", "n6", "n7", "n8"]
    assert queue.dropped == 3


def test_throttle_sends_one_message_per_window_and_keeps_the_latest() -> None:
    queue = TopicQueue(backlog=100)
    queue.add(None, 500, 0)
    queue.push(1, "a")
    assert drain(queue, 10.0) == ["a"]  # the first message goes at once, and opens a window
    for seq, text in enumerate(["b", "c", "d"], start=2):
        queue.push(seq, text)
    assert drain(queue, 10.4) == []  # still inside the window
    assert queue.ready_at() == pytest.approx(10.5)
    assert drain(queue, 10.5) == ["d"]  # only the latest of the window, when it ends
    assert drain(queue, 20.0) == []


def test_queue_length_keeps_the_newest_and_drains_at_the_throttle_rate() -> None:
    queue = TopicQueue(backlog=100)
    queue.add("s1", 100, 3)
    for seq in range(1, 8):
        queue.push(seq, f"m{seq}")
    assert queue.dropped == 4
    assert drain(queue, 0.0) == ["m5"]
    assert drain(queue, 0.05) == []
    assert drain(queue, 0.1) == ["m6"]
    assert drain(queue, 0.2) == ["m7"]


def test_queue_length_without_throttle_only_matters_for_a_slow_reader() -> None:
    queue = TopicQueue(backlog=100)
    queue.add(None, 0, 1)
    for seq in range(1, 5):  # the reader is busy while four messages arrive
        queue.push(seq, f"m{seq}")
    assert drain(queue, 0.0) == ["m4"]


def test_several_requests_merge_to_the_fastest_rate_and_the_longest_queue() -> None:
    queue = TopicQueue(backlog=100)
    queue.add("slow", 1000, 1)
    queue.add("fast", 100, 4)
    assert (queue.throttle, queue.capacity) == (0.1, 4)
    assert queue.remove("fast")
    assert (queue.throttle, queue.capacity) == (1.0, 1)
    assert not queue.remove("fast")


# -- the writer's bursts and the websocket's batched frames -----------------------------------------


def test_the_writer_sends_what_is_due_in_bursts_in_order_and_leaves_a_throttled_message_for_its_window() -> None:
    async def scenario() -> tuple[list[list[str]], list[str]]:
        bursts: list[list[str]] = []
        singles: list[str] = []

        async def send(text: str) -> None:
            singles.append(text)

        async def send_many(texts: list[str]) -> None:
            bursts.append(texts)

        clock = [10.0]
        session = Session("s", send, lambda reason: None, 1000, lambda: clock[0], send_many=send_many)
        session.subscribe("/fast", "/fast", None, 0, 0)
        session.subscribe("/slow", "/slow", None, 500, 2)  # one message per 500 ms, two kept
        for n in range(WRITE_BATCH + 10):
            session.offer("/fast", f"f{n}")
            if n == 3:
                session.reply("reply")
            if n in (1, 5):  # the first goes at once; the second waits for the end of the window
                session.offer("/slow", f"s{n}")
        writer = asyncio.create_task(session.run())
        await asyncio.sleep(0.01)
        clock[0] = 10.5
        session.offer("/fast", "last")  # wakes the writer after the window ended
        await asyncio.sleep(0.01)
        session.close()
        await writer
        return bursts, singles

    bursts, singles = asyncio.run(scenario())
    fast = [f"f{n}" for n in range(WRITE_BATCH + 10)]
    assert bursts[0] == [*fast[:2], "s1", *fast[2:4], "reply", *fast[4 : WRITE_BATCH - 2]]
    assert bursts[1] == fast[WRITE_BATCH - 2 :]  # the rest of what was due; s5 waits for its window
    assert bursts[2:] == [["s5", "last"]]
    assert singles == []


def test_a_burst_over_the_character_bound_is_split_and_a_lone_message_goes_alone() -> None:
    async def scenario() -> tuple[list[int], list[str]]:
        sizes: list[int] = []
        singles: list[str] = []

        async def send(text: str) -> None:
            singles.append(text)

        async def send_many(texts: list[str]) -> None:
            sizes.append(len(texts))

        session = Session("s", send, lambda reason: None, 1000, send_many=send_many)
        session.subscribe("/big", "/big", None, 0, 0)
        for _ in range(5):
            session.offer("/big", "x" * (WRITE_BATCH_CHARS // 2))
        writer = asyncio.create_task(session.run())
        await asyncio.sleep(0.01)
        session.offer("/big", "alone")
        await asyncio.sleep(0.01)
        session.close()
        await writer
        return sizes, singles

    sizes, singles = asyncio.run(scenario())
    assert sizes == [2, 2]  # two halves reach the bound; then the fifth message, alone, and later "alone"
    assert len(singles) == 2 and singles[-1] == "alone"


def test_frames_sent_in_one_write_arrive_as_separate_messages_in_order() -> None:
    texts = [f'{{"n":{n},"data":"é{"x" * n}"}}' for n in range(300)]

    async def scenario() -> tuple[list[str], bool]:
        got: list[str] = []
        closed = asyncio.Event()
        refused = False

        async def handler(websocket: ServerConnection) -> None:
            nonlocal refused
            await send_frames(websocket, texts[:1])
            await send_frames(websocket, texts[1:])
            await closed.wait()
            try:
                await send_frames(websocket, texts[:2])
            except ConnectionClosed:
                refused = True

        async with ws_serve(handler, "127.0.0.1", 0, compression=None) as server:
            port = server.sockets[0].getsockname()[1]
            async with ws_connect(f"ws://127.0.0.1:{port}", compression=None) as client:
                while len(got) < len(texts):
                    got.append(str(await asyncio.wait_for(client.recv(), WAIT)))
            closed.set()
            await asyncio.sleep(0.1)
        return got, refused

    got, refused = asyncio.run(scenario())
    assert got == texts
    assert refused  # a closed connection raises as websockets' own send does


# -- the parameter store --------------------------------------------------------------------------


def test_param_store_is_a_tree_of_json_values() -> None:
    params = ParamStore({"/robot/speed": 0.5, "name": "r1"})
    params.set("/robot/arm", {"joints": 7})
    assert params.get("/robot") == {"speed": 0.5, "arm": {"joints": 7}}
    assert params.get("robot/arm/joints") == 7
    assert params.names() == ["/name", "/robot/arm/joints", "/robot/speed"]
    assert params.has("/robot/arm") and not params.has("/robot/leg")
    assert params.get("/robot/leg", None) is None
    with pytest.raises(KeyError):
        params.get("/robot/leg")
    assert params.search("speed") is None and params.search("name") == "/name"
    copy = params.get("/robot")
    copy["speed"] = 9
    assert params.get("/robot/speed") == 0.5  # values are copied out
    assert params.delete("/robot/arm") and not params.delete("/robot/arm")
    with pytest.raises(ValueError, match="must be JSON"):
        params.set("/bad", {1, 2})


def test_worker_pool_runs_jobs_side_by_side_and_joins() -> None:
    pool = WorkerPool(3)
    together = threading.Barrier(3, timeout=WAIT)  # broken (an error) unless all three jobs run at once
    passed: list[int] = []
    for n in range(3):
        pool.submit(lambda n=n: passed.append(together.wait() * 0 + n))
    deadline = time.monotonic() + WAIT
    while len(passed) < 3 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert sorted(passed) == [0, 1, 2]
    pool.shutdown()
    assert pool.join(WAIT) == 0
    with pytest.raises(RuntimeError, match="shut down"):
        pool.submit(lambda: None)


# -- over a websocket -------------------------------------------------------------------------------


class Client:
    """A rosbridge client over the websockets sync client, with bounded waits."""

    def __init__(self, url: str, small_buffers: bool = False) -> None:
        self._stack = ExitStack()
        sock = None
        if small_buffers:  # a reader that can fall behind: small kernel buffer, one frame queued at most
            host, port = url.removeprefix("ws://").split(":")
            sock = socket.socket()
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 64 * 1024)
            sock.settimeout(WAIT)
            sock.connect((host, int(port)))
        websocket = connect(url, sock=sock, open_timeout=WAIT, close_timeout=1, max_queue=1 if small_buffers else 16)
        self.ws: ClientConnection = self._stack.enter_context(websocket)

    def send(self, **message: Any) -> None:
        self.ws.send(json.dumps(message))

    def recv(self, timeout: float = WAIT) -> dict[str, Any]:
        message = json.loads(self.ws.recv(timeout=timeout))
        assert isinstance(message, dict)
        return message

    def expect(self, op: str, timeout: float = WAIT) -> dict[str, Any]:
        message = self.recv(timeout)
        assert message["op"] == op, message
        return message

    def nothing(self, wait: float = 0.2) -> None:
        with pytest.raises(TimeoutError):
            print("unexpected:", self.ws.recv(timeout=wait))

    def call(self, service: str, args: Any = None, **extra: Any) -> dict[str, Any]:
        """Call a service and return its service_response (checked to echo the id)."""
        message: dict[str, Any] = {"op": "call_service", "service": service, "id": f"call-{service}", **extra}
        if args is not None:
            message["args"] = args
        self.ws.send(json.dumps(message))
        answer = self.expect("service_response", timeout=WAIT + float(extra.get("timeout", 0)))
        assert answer["id"] == message["id"]
        return answer

    def sync(self) -> None:
        """Return once the server has handled everything this client sent before."""
        assert self.call("/rosapi/get_time")["result"] is True

    def close(self) -> None:
        self._stack.close()


@contextmanager
def client_maker(url: str) -> Iterator[Callable[[], Client]]:
    """Clients of the bridge at ``url``, made on demand and each closed at the end."""
    opened: list[Client] = []

    def make() -> Client:
        opened.append(Client(url))
        return opened[-1]

    try:
        yield make
    finally:
        for each in opened:
            each.close()


@pytest.fixture
def bridge() -> Bridge:
    bridge = Bridge(call_timeout=WAIT, params={"/robot/speed": 0.5})
    bridge.add_service("/test/add", "test/Add", lambda args: {"sum": args["a"] + args["b"]})
    bridge.add_topic("/test/events", "test/Event")
    return bridge


@pytest.fixture
def server(bridge: Bridge) -> Iterator[RunningBridge]:
    threads = threading.active_count()
    running = bridge.start(port=0)
    yield running
    assert running.stop(timeout=5.0)
    assert_threads_end(threads, WAIT)


@pytest.fixture
def client(server: RunningBridge) -> Iterator[Callable[[], Client]]:
    """A factory of clients, all closed before the server stops."""
    with client_maker(server.url) as make:
        yield make


BAD_FRAMES = [
    pytest.param("{not json", "not valid JSON", None, id="not-json"),
    pytest.param("[1, 2]", "must be a JSON object, not array", None, id="array"),
    pytest.param('"publish"', "must be a JSON object, not string", None, id="string"),
    pytest.param('{"id": "x1"}', "no 'op' field", "x1", id="no-op"),
    pytest.param('{"op": 7}', "field 'op' must be a string, not number", None, id="op-not-string"),
    pytest.param('{"op": "dance", "id": 3}', "unknown op 'dance'; this server supports advertise", 3, id="unknown-op"),
    pytest.param('{"op": "fragment", "id": "f"}', "fragment: missing required field 'data'", "f", id="fragment"),
    pytest.param(
        '{"op": "png", "data": "x"}', "png: PNG-compressed messages from a client are not supported", None, id="png"
    ),
    pytest.param(
        '{"op": "advertise", "topic": "/a", "id": "p"}', "advertise: missing required field 'type'", "p", id="missing"
    ),
    pytest.param(
        '{"op": "subscribe", "topic": 5}',
        "subscribe: field 'topic' must be a string, not number",
        None,
        id="wrong-type",
    ),
    pytest.param(
        '{"op": "subscribe", "topic": "/a", "throttle_rate": "fast"}',
        "field 'throttle_rate' must be an integer, not string",
        None,
        id="wrong-int",
    ),
    pytest.param('{"op": "subscribe", "topic": "/a", "queue_length": -1}', "must not be negative", None, id="negative"),
    pytest.param(
        '{"op": "call_service", "service": "/a", "args": "x"}',
        "field 'args' must be an object or an array, not string",
        None,
        id="wrong-args",
    ),
    pytest.param(
        '{"op": "set_level", "level": "debug"}', "level must be one of none, error, warning, info", None, id="bad-level"
    ),
    pytest.param(
        '{"op": "advertise", "topic": "", "type": "std_msgs/String"}', "topic must not be empty", None, id="empty-name"
    ),
    pytest.param(
        '{"op": "advertise", "topic": "/a", "type": "x", "id": [1]}',
        "'id' must be a string or an integer",
        None,
        id="bad-id",
    ),
    pytest.param(
        '{"op": "publish", "topic": "/nobody", "msg": {}}', "'/nobody' is not advertised", None, id="unknown-topic"
    ),
    pytest.param(
        '{"op": "service_response", "service": "/a", "id": "q", "result": true}',
        "no call with id 'q'",
        "q",
        id="stray-response",
    ),
    pytest.param(
        '{"op": "advertise_service", "service": "rosapi/topics", "type": "x"}',
        "provided by the server",
        None,
        id="taken-service",
    ),
    # NaN and infinities are read (Python's tokens, as roslibpy sends them) but no protocol field takes one
    pytest.param(
        '{"op": "subscribe", "topic": "/nan", "id": 1, "throttle_rate": NaN}',
        "field 'throttle_rate' must be an integer, not number",
        1,
        id="nan-field",
    ),
    pytest.param(
        '{"op": "call_service", "service": "/test/add", "id": "t", "timeout": Infinity}',
        "call_service: timeout must be a finite number of seconds (0: the server's), not inf",
        "t",
        id="infinite-timeout",
    ),
    pytest.param("[" * 100_000 + "]" * 100_000, "nested too deeply", None, id="nested"),
    pytest.param('{"op": "set_level", "level": "info"} and', "not valid JSON: Extra data", None, id="two"),
    pytest.param(  # white space around a message is JSON: it is read
        ' {"op": "publish", "topic": "/nobody", "msg": {}}\n', "'/nobody' is not advertised", None, id="spaced"
    ),
    pytest.param(b"\x82\xa2op", "binary frames are not supported", None, id="binary"),
    pytest.param(
        '{"op": "publish", "topic": "/a", "msg": {"data": "' + "x" * (1 << 20) + '"}}',
        "exceeds the limit of 1048576 bytes (max_message_bytes)",
        None,
        id="oversize",
    ),
]


@pytest.mark.parametrize(("frame", "reason", "message_id"), BAD_FRAMES)
def test_a_bad_message_gets_a_status_error_and_the_connection_stays_up(
    client: Callable[[], Client], frame: str | bytes, reason: str, message_id: Any
) -> None:
    me = client()
    me.ws.send(frame)
    status = me.expect("status")
    assert status["level"] == "error"
    assert reason in status["msg"]
    assert status.get("id") == message_id
    if '"call_service"' in str(frame) and message_id is not None:  # the caller waits for an answer: it gets one
        answer = me.expect("service_response")
        assert (answer["id"], answer["result"]) == (message_id, False)
        assert reason in answer["values"]
    assert me.call("/test/add", {"a": 1, "b": 2})["values"] == {"sum": 3}  # the same connection still works


def test_the_message_limit_is_configurable() -> None:
    bridge = Bridge(max_message_bytes=100)
    with bridge.start(port=0) as running:
        me = Client(running.url)
        me.send(op="publish", topic="/a", msg={"data": "x" * 100})
        assert "exceeds the limit of 100 bytes" in me.expect("status")["msg"]
        me.send(op="advertise", topic="/a", type="std_msgs/String")
        me.sync()
        me.close()


def test_publish_reaches_subscribers_in_order_under_their_own_spelling(client: Callable[[], Client]) -> None:
    talker, listener, other = client(), client(), client()
    listener.send(op="subscribe", topic="chatter", type="std_msgs/String")
    other.send(op="subscribe", topic="/chatter")
    listener.sync()
    other.sync()
    talker.send(op="advertise", topic="/chatter", type="std_msgs/String")
    for n in range(200):
        talker.send(op="publish", topic="/chatter", msg={"data": str(n)})
    for reader, spelling in [(listener, "chatter"), (other, "/chatter")]:
        messages = [reader.expect("publish") for _ in range(200)]
        assert {m["topic"] for m in messages} == {spelling}
        assert [m["msg"]["data"] for m in messages] == [str(n) for n in range(200)]
    talker.nothing()  # a publisher that does not subscribe gets nothing back


def test_a_client_latched_message_waits_for_the_first_subscriber_as_sent(client: Callable[[], Client]) -> None:
    talker, listener = client(), client()
    talker.send(op="advertise", topic="/pose", type="test/Pose", latch=True)
    sent = {"name": "Küche ✓", "xy": [1.5, -2, 1e-9], "deep": {"a": [None, True, {"b": ""}]}, "big": 2**70}
    talker.send(op="publish", topic="/pose", msg=sent)  # nobody subscribes yet
    talker.sync()
    listener.send(op="subscribe", topic="/pose")
    assert listener.expect("publish")["msg"] == sent


def test_advertise_conflicts_and_unknown_unadvertise(client: Callable[[], Client]) -> None:
    me = client()
    me.send(op="advertise", topic="/odom", type="nav_msgs/Odometry")
    me.send(op="advertise", topic="/odom", type="std_msgs/String", id="a2")
    assert me.expect("status") == {
        "op": "status",
        "level": "error",
        "msg": "advertise: topic '/odom' already has type 'nav_msgs/Odometry', not 'std_msgs/String'",
        "id": "a2",
    }
    me.send(op="subscribe", topic="/odom", type="std_msgs/String")
    assert "has type 'nav_msgs/Odometry'" in me.expect("status")["msg"]
    me.send(op="unadvertise", topic="/never")
    me.nothing()  # a warning, and the default level is error
    me.send(op="set_level", level="warning")
    me.send(op="unadvertise", topic="/never", id="u")
    assert me.expect("status") == {
        "op": "status",
        "level": "warning",
        "msg": "unadvertise: this client does not advertise '/never'",
        "id": "u",
    }
    me.send(op="set_level", level="info")
    me.send(op="subscribe", topic="/odom", id="s")
    assert me.expect("status") == {"op": "status", "level": "info", "msg": "subscribed to /odom", "id": "s"}
    me.send(op="set_level", level="none")
    me.send(op="publish", topic="/nobody", msg={})
    me.nothing()


def test_unsubscribe_by_id_and_all(client: Callable[[], Client]) -> None:
    talker, listener = client(), client()
    talker.send(op="advertise", topic="/t", type="std_msgs/Int32")
    talker.sync()
    listener.send(op="subscribe", topic="/t", id="one")
    listener.send(op="subscribe", topic="/t", id="two")
    listener.sync()
    talker.send(op="publish", topic="/t", msg={"data": 1})
    assert listener.expect("publish")["msg"] == {"data": 1}
    listener.nothing()  # two subscriptions of one client: each message once
    listener.send(op="unsubscribe", topic="/t", id="one")
    listener.sync()
    talker.send(op="publish", topic="/t", msg={"data": 2})
    assert listener.expect("publish")["msg"] == {"data": 2}
    listener.send(op="unsubscribe", topic="/t")
    listener.sync()
    talker.send(op="publish", topic="/t", msg={"data": 3})
    talker.sync()
    listener.nothing()


def test_a_slow_subscriber_with_queue_length_1_gets_only_the_latest(client: Callable[[], Client]) -> None:
    talker, listener = client(), client()
    talker.send(op="advertise", topic="/pose", type="geometry_msgs/Pose")
    listener.send(op="subscribe", topic="/pose", throttle_rate=600, queue_length=1)
    listener.sync()
    talker.send(op="publish", topic="/pose", msg={"n": 1})
    assert listener.expect("publish")["msg"] == {"n": 1}  # opens a 600 ms window
    for n in range(2, 11):
        talker.send(op="publish", topic="/pose", msg={"n": n})
    talker.sync()
    assert listener.expect("publish")["msg"] == {"n": 10}
    listener.nothing(0.8)


def test_a_queue_drains_its_newest_messages_at_the_throttle_rate(client: Callable[[], Client]) -> None:
    talker, listener = client(), client()
    talker.send(op="advertise", topic="/scan", type="sensor_msgs/LaserScan")
    listener.send(op="subscribe", topic="/scan", throttle_rate=300, queue_length=3)
    listener.sync()
    talker.send(op="publish", topic="/scan", msg={"n": 1})
    assert listener.expect("publish")["msg"] == {"n": 1}
    for n in range(2, 11):
        talker.send(op="publish", topic="/scan", msg={"n": n})
    talker.sync()
    times, seen = [], []
    for _ in range(3):
        seen.append(listener.expect("publish")["msg"]["n"])
        times.append(time.monotonic())
    assert seen == [8, 9, 10]
    assert min(b - a for a, b in itertools.pairwise(times)) > 0.2
    listener.nothing(0.4)


def test_a_reader_that_does_not_read_keeps_only_its_queue(server: RunningBridge, client: Callable[[], Client]) -> None:
    """No throttle: the queue fills only while the socket is full, and then keeps the newest."""
    talker, listener = client(), Client(server.url, small_buffers=True)
    talker.send(op="advertise", topic="/map", type="nav_msgs/OccupancyGrid")
    listener.send(op="subscribe", topic="/map", queue_length=1)
    listener.sync()
    blob = "x" * (512 * 1024)
    for n in range(1, 65):  # 32 MiB: far more than loopback socket buffers hold
        talker.send(op="publish", topic="/map", msg={"n": n, "data": blob})
    talker.sync()
    seen = []
    while not seen or seen[-1] != 64:
        seen.append(listener.expect("publish")["msg"]["n"])
    listener.close()
    assert seen == sorted(seen) and len(seen) < 64


def test_a_topic_the_server_takes_over_refuses_its_client_publisher(
    bridge: Bridge, client: Callable[[], Client]
) -> None:
    talker, listener = client(), client()
    listener.send(op="subscribe", topic="/test/taken")
    listener.sync()
    talker.send(op="advertise", topic="/test/taken", type="test/State")
    talker.send(op="publish", topic="/test/taken", msg={"n": 1})
    assert listener.expect("publish")["msg"] == {"n": 1}
    bridge.add_topic("/test/taken", "test/State")
    talker.send(op="publish", topic="test/taken", msg={"n": 2}, id="late")
    status = talker.expect("status")
    assert "belongs to this server" in status["msg"] and status["id"] == "late"
    listener.nothing()


def test_server_topics_publish_from_any_thread_and_latch(bridge: Bridge, client: Callable[[], Client]) -> None:
    bridge.add_topic("/test/state", "test/State", latch=True)
    bridge.publish("/test/state", {"state": "idle"})
    me = client()
    me.send(op="subscribe", topic="/test/state")
    assert me.expect("publish")["msg"] == {"state": "idle"}  # latched before anyone subscribed
    me.send(op="subscribe", topic="/test/events")
    me.sync()
    workers = [
        threading.Thread(target=lambda k=k: [bridge.publish("/test/events", {"k": k, "i": i}) for i in range(50)])
        for k in range(4)
    ]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join(WAIT)
    got = [me.expect("publish")["msg"] for _ in range(200)]
    for k in range(4):
        assert [m["i"] for m in got if m["k"] == k] == list(range(50))
    with pytest.raises(UnknownTopicError, match="add_topic"):
        bridge.publish("/test/nothing", {})
    with pytest.raises(TypeError):
        bridge.publish("/test/events", [1, 2])  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="not JSON compliant"):  # a NaN value is written; a NaN key is no name
        bridge.publish("/test/events", {float("nan"): 1})


def test_server_services_answer_or_fail_with_the_reason(bridge: Bridge, client: Callable[[], Client]) -> None:
    def refuse(args: dict[str, Any]) -> dict[str, Any]:
        raise ServiceError(f"robot {args.get('robot')!r} is not in the home")

    def crash(args: dict[str, Any]) -> dict[str, Any]:
        raise ValueError("bad value")

    bridge.add_service("/test/refuse", "test/Refuse", refuse)
    bridge.add_service("/test/crash", "test/Crash", crash)
    bridge.add_service("/test/list", "test/List", lambda args: [1])  # type: ignore[arg-type, return-value]
    bridge.add_service("/test/slow", "test/Slow", lambda args: time.sleep(args["s"]) or {"slept": args["s"]})
    me = client()
    ok = me.call("test/add", {"a": 2, "b": 3})
    assert ok == {
        "op": "service_response",
        "service": "test/add",
        "values": {"sum": 5},
        "result": True,
        "id": "call-test/add",
    }
    assert me.call("/test/refuse", {"robot": "r2"})["values"] == "robot 'r2' is not in the home"
    assert me.call("/test/crash")["values"] == "internal error: ValueError: bad value"
    assert me.call("/test/list")["values"] == "internal error: TypeError: the handler returned list, not a dict"
    assert me.call("/test/nothing") == {
        "op": "service_response",
        "service": "/test/nothing",
        "values": "service '/test/nothing' does not exist",
        "result": False,
        "id": "call-/test/nothing",
    }
    assert "args as an object of named fields" in me.call("/test/add", [1, 2])["values"]
    late = me.call("/test/slow", {"s": 1.0}, timeout=0.2)
    assert (late["result"], late["values"]) == (False, "service '/test/slow' did not answer within 0.2 s")
    start = time.monotonic()  # handlers run on worker threads, side by side
    for n in range(3):
        me.send(op="call_service", service="/test/slow", args={"s": 0.4}, id=n)
    assert sorted(me.expect("service_response")["id"] for _ in range(3)) == [0, 1, 2]
    assert time.monotonic() - start < 1.0
    with pytest.raises(RosbridgeError, match="already provided"):
        bridge.add_service("/test/add", "test/Add", lambda args: {})
    bridge.remove_service("/test/refuse")
    assert me.call("/test/refuse")["values"] == "service '/test/refuse' does not exist"


def test_services_provided_by_a_client_are_relayed(client: Callable[[], Client]) -> None:
    provider, caller = client(), client()
    provider.send(op="advertise_service", service="/arm/grasp", type="arm/Grasp")
    provider.sync()
    caller.send(op="call_service", service="arm/grasp", args={"object": "cup"}, id="g1")
    request = provider.expect("call_service")
    assert request["service"] == "/arm/grasp" and request["args"] == {"object": "cup"}
    assert request["id"] != "g1"
    provider.send(op="service_response", service="/arm/grasp", id=request["id"], values={"ok": True}, result=True)
    assert caller.expect("service_response") == {
        "op": "service_response",
        "service": "arm/grasp",
        "values": {"ok": True},
        "result": True,
        "id": "g1",
    }
    caller.send(op="call_service", service="/arm/grasp", args={"object": "pen"}, id=7)
    request = provider.expect("call_service")
    provider.send(op="service_response", service="/arm/grasp", id=request["id"], values="no pen", result=False)
    assert caller.expect("service_response")["values"] == "no pen"
    provider.send(op="service_response", service="/arm/grasp", id=request["id"], values={}, result=True)
    assert "no call with id" in provider.expect("status")["msg"]  # answered once only
    caller.send(op="call_service", service="/arm/grasp", id="t", timeout=0.2)
    provider.expect("call_service")
    assert caller.expect("service_response")["values"] == "service '/arm/grasp' did not answer within 0.2 s"
    services = caller.call("/rosapi/services")["values"]["services"]
    assert "/arm/grasp" in services and "/test/add" in services and "/rosapi/get_param" in services


@pytest.mark.parametrize("leave", ["disconnect", "unadvertise"])
def test_pending_calls_fail_when_the_provider_goes(client: Callable[[], Client], leave: str) -> None:
    provider, caller = client(), client()
    provider.send(op="advertise_service", service="/cam/locate", type="cam/Locate")
    provider.sync()
    caller.send(op="call_service", service="/cam/locate", id="c1")
    caller.send(op="call_service", service="/cam/locate", id="c2")
    provider.expect("call_service")
    provider.expect("call_service")
    if leave == "disconnect":
        provider.close()
        reason = "the provider of '/cam/locate' disconnected"
    else:
        provider.send(op="unadvertise_service", service="/cam/locate")
        reason = "service '/cam/locate' was unadvertised by its provider"
    answers = sorted((caller.expect("service_response") for _ in range(2)), key=lambda m: m["id"])
    assert [(a["id"], a["result"], a["values"]) for a in answers] == [("c1", False, reason), ("c2", False, reason)]
    assert caller.call("/cam/locate")["values"] == "service '/cam/locate' does not exist"


def test_a_client_may_not_take_a_server_service_but_may_take_over_a_client_one(client: Callable[[], Client]) -> None:
    first, second, caller = client(), client(), client()
    first.send(op="advertise_service", service="/test/add", type="test/Add")
    assert "provided by the server" in first.expect("status")["msg"]
    first.send(op="advertise_service", service="/x", type="x/X")
    first.sync()
    second.send(op="advertise_service", service="/x", type="x/X")
    second.sync()
    caller.send(op="call_service", service="/x", id="c")
    request = second.expect("call_service")
    first.nothing()
    second.send(op="service_response", service="/x", id=request["id"], values={"by": 2}, result=True)
    assert caller.expect("service_response")["values"] == {"by": 2}
    first.close()  # the first provider leaving does not withdraw the service from the second
    assert caller.call("/rosapi/service_type", {"service": "/x"})["values"] == {"type": "x/X"}


def test_rosapi_lists_topics_services_and_nodes(client: Callable[[], Client]) -> None:
    me, other = client(), client()
    me.send(op="advertise", topic="/chatter", type="std_msgs/String")
    other.send(op="subscribe", topic="/imu", type="sensor_msgs/Imu")
    other.send(op="subscribe", topic="/untyped")
    other.send(op="advertise_service", service="/light/on", type="std_srvs/Trigger")
    me.sync()
    other.sync()
    topics = me.call("rosapi/topics")["values"]
    assert dict(zip(topics["topics"], topics["types"], strict=True)) == {
        "/chatter": "std_msgs/String",
        "/imu": "sensor_msgs/Imu",
        "/test/events": "test/Event",
        "/untyped": "",
    }
    assert me.call("/rosapi/topics_for_type", {"type": "sensor_msgs/Imu"})["values"] == {"topics": ["/imu"]}
    assert me.call("/rosapi/topic_type", {"topic": "chatter"})["values"] == {"type": "std_msgs/String"}
    assert me.call("/rosapi/topic_type", {"topic": "/none"})["values"] == {"type": ""}
    assert me.call("/rosapi/service_type", {"service": "/test/add"})["values"] == {"type": "test/Add"}
    assert me.call("/rosapi/services_for_type", {"type": "std_srvs/Trigger"})["values"] == {"services": ["/light/on"]}
    assert me.call("/rosapi/nodes")["values"] == {"nodes": ["/cbrs_rosbridge", "/rosapi"]}
    assert me.call("/rosapi/topic_type")["values"] == "missing field 'topic'"
    now = me.call("/rosapi/get_time")["values"]["time"]
    assert abs(now["secs"] + now["nsecs"] / 1e9 - time.time()) < 5 and now["sec"] == now["secs"]
    other.close()
    deadline = time.monotonic() + WAIT  # a client's topics and services go with it
    while "/imu" in me.call("/rosapi/topics")["values"]["topics"] and time.monotonic() < deadline:
        time.sleep(0.02)
    assert me.call("/rosapi/topics")["values"]["topics"] == ["/chatter", "/test/events"]
    assert "/light/on" not in me.call("/rosapi/services")["values"]["services"]


def test_parameters_as_roslibpy_and_roslibjs_send_them(bridge: Bridge, client: Callable[[], Client]) -> None:
    me = client()
    assert me.call("/rosapi/set_param", {"name": "/arm/gain", "value": json.dumps([1, 2.5])})["result"]
    assert me.call("rosapi/get_param", {"name": "arm/gain"})["values"]["value"] == "[1, 2.5]"
    assert bridge.params.get("/arm/gain") == [1, 2.5]
    assert json.loads(me.call("/rosapi/get_param", {"name": "/robot/speed"})["values"]["value"]) == 0.5
    unset = me.call("/rosapi/get_param", {"name": "/nope"})["values"]
    assert unset == {"value": "null", "successful": False, "reason": "parameter '/nope' is not set"}
    with_default = me.call("/rosapi/get_param", {"name": "/nope", "default": '"d"'})["values"]
    assert json.loads(with_default["value"]) == "d" and with_default["successful"]
    assert me.call("/rosapi/has_param", {"name": "/arm"})["values"] == {"exists": True}
    assert me.call("/rosapi/get_param_names")["values"] == {"names": ["/arm/gain", "/robot/speed"]}
    assert me.call("/rosapi/search_param", {"name": "gain"})["values"] == {"global_name": ""}
    assert me.call("/rosapi/search_param", {"name": "arm"})["values"] == {"global_name": "/arm"}
    bad = me.call("/rosapi/set_param", {"name": "/x", "value": "hello"})
    assert not bad["result"] and "must be JSON-encoded" in bad["values"]
    assert me.call("/rosapi/delete_param", {"name": "/arm/gain"})["result"]
    assert me.call("/rosapi/has_param", {"name": "/arm/gain"})["values"] == {"exists": False}
    bridge.params.set("/from/python", {"on": True})
    assert json.loads(me.call("/rosapi/get_param", {"name": "/from"})["values"]["value"]) == {"python": {"on": True}}


def test_stop_closes_connections_and_a_second_serve_is_refused(bridge: Bridge) -> None:
    threads = threading.active_count()
    running = bridge.start(port=0)
    with pytest.raises(RosbridgeError, match="already being served"):
        bridge.start(port=0)
    me = Client(running.url)
    me.sync()
    assert running.stop(timeout=5.0)
    with pytest.raises(ConnectionClosed):
        me.recv()
    me.close()
    again = bridge.start(port=0)  # a stopped bridge can be served again
    Client(again.url).close()
    assert again.stop()
    assert_threads_end(threads, WAIT)


def test_stop_does_not_wait_for_ever_on_a_stuck_handler() -> None:
    bridge = Bridge()
    release, entered = threading.Event(), threading.Event()

    def stuck(args: object) -> dict[str, object]:
        entered.set()
        release.wait(WAIT)
        return {}

    bridge.add_service("/stuck", "x/Stuck", stuck)
    running = bridge.start(port=0)
    me = Client(running.url)
    me.send(op="call_service", service="/stuck", id=1)
    assert entered.wait(WAIT)  # the handler runs (a read call may still wait for its worker under load)
    start = time.monotonic()
    assert running.stop(timeout=0.3) is False  # the handler thread is still busy
    assert time.monotonic() - start < 1.5
    release.set()
    me.close()


def test_a_busy_port_is_reported() -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        with pytest.raises(OSError):
            Bridge().start(port=taken.getsockname()[1])


def test_bad_settings_are_refused() -> None:
    with pytest.raises(ValueError, match="call_timeout"):
        Bridge(call_timeout=0)
    with pytest.raises(ValueError, match="non-empty"):
        Bridge().add_topic("", "x/Y")
