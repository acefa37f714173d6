"""rosbridge's CBOR compression: a ``compression: "cbor"`` subscriber gets each ``publish`` as one binary
frame of CBOR, as rosbridge_suite sends it, with typed arrays (RFC 8746 tags, little-endian) and byte
strings where the server's message says what an array holds; ``cbor-raw`` is refused (no ROS
serialization here); a client's binary frame is read as UTF-8 JSON, as rosbridge_suite reads it, and
CBOR or BSON from a client is refused. roslibjs decoding it is in tests/test_rosbridge_roslibjs_cbor.py.
"""

from __future__ import annotations

import array
import asyncio
import base64
import json
import struct
import time
from collections.abc import Iterator
from typing import Any

import cbor2
import numpy
import pytest
from websockets.asyncio.client import connect as ws_connect
from websockets.asyncio.server import ServerConnection
from websockets.asyncio.server import serve as ws_serve
from websockets.sync.client import ClientConnection, connect

from cbrs.rosbridge import Bridge, RunningBridge
from cbrs.rosbridge.bridge import BINARY_REFUSED
from cbrs.rosbridge.outbox import TopicQueue
from cbrs.rosbridge.server import send_frames
from cbrs.rosbridge.session import Session
from cbrs.rosbridge.wire import _tagged, cbor_values

WAIT = 10.0

#: RFC 8746's little-endian typed-array tags, written out here (not taken from the code under test):
#: tag -> (struct format letter, element kind)
TAGS = {
    69: ("H", "uint16"),
    70: ("I", "uint32"),
    71: ("Q", "uint64"),
    72: ("b", "int8"),
    77: ("h", "int16"),
    78: ("i", "int32"),
    79: ("q", "int64"),
    85: ("f", "float32"),
    86: ("d", "float64"),
}


def untag(value: Any) -> Any:
    """A decoded CBOR value with each typed array read as ("kind", [numbers]) and bytes kept as bytes."""
    if isinstance(value, cbor2.CBORTag):
        letter, kind = TAGS[value.tag]
        data = value.value
        assert isinstance(data, bytes) and len(data) % struct.calcsize(letter) == 0
        return kind, list(struct.unpack(f"<{len(data) // struct.calcsize(letter)}{letter}", data))
    if isinstance(value, dict):
        return {key: untag(item) for key, item in value.items()}
    if isinstance(value, list):
        return [untag(item) for item in value]
    return value


def decoded(frame: str | bytes) -> Any:
    """A binary frame's CBOR (a text frame fails the test)."""
    assert isinstance(frame, bytes), frame
    return cbor2.loads(frame)


def frames(ws: ClientConnection, quiet: float = 0.3) -> list[str | bytes]:
    """Every frame that arrives until none has for ``quiet`` seconds (bounded)."""
    got: list[str | bytes] = []
    while len(got) < 1000:
        try:
            got.append(ws.recv(timeout=quiet))
        except TimeoutError:
            break
    return got


def send(ws: ClientConnection, **message: Any) -> None:
    ws.send(json.dumps(message))


def sync(ws: ClientConnection) -> list[str | bytes]:
    """Everything before the answer to a call: the server has handled what was sent before it."""
    send(ws, op="call_service", service="/rosapi/get_time", id="sync")
    before: list[str | bytes] = []
    deadline = time.monotonic() + WAIT
    while time.monotonic() < deadline:
        frame = ws.recv(timeout=WAIT)
        if isinstance(frame, str) and json.loads(frame).get("id") == "sync":
            return before
        before.append(frame)
    raise AssertionError("no answer to the sync call")


def bson(document: dict[str, str]) -> bytes:
    """A BSON document of strings (the only kind the tests send)."""
    body = b"".join(
        b"\x02" + key.encode() + b"\x00" + struct.pack("<i", len(value.encode()) + 1) + value.encode() + b"\x00"
        for key, value in document.items()
    )
    return struct.pack("<i", 4 + len(body) + 1) + body + b"\x00"


@pytest.fixture
def bridge() -> Iterator[tuple[Bridge, RunningBridge]]:
    served = Bridge(max_message_bytes=64 * 1024)
    served.add_topic("/test/scan", "test/Scan")
    served.add_topic("/test/latched", "test/Scan", latch=True)
    with served.start(port=0) as running:
        yield served, running


def typed() -> dict[str, Any]:
    """Arrays and bytes of every kind the server may publish (new ones on every call)."""
    return {
        "u8": array.array("B", [0, 7, 255]),
        "i8": array.array("b", [-128, 0, 127]),
        "u16": array.array("H", [0, 65535]),
        "i16": array.array("h", [-32768, 5]),
        "u32": array.array("I", [4_000_000_000]),
        "i32": array.array("i", [-2_000_000_000, 1]),
        "u64": array.array("Q", [2**64 - 1]),
        "i64": array.array("q", [-(2**63), 2**53 + 1]),
        "f32": array.array("f", [0.5, -1.25, 0.1]),
        "f64": array.array("d", [0.1, -2.5e300]),
        "np_f32": numpy.array([1.5, 2.25], dtype=numpy.float32),
        "np_be_i32": numpy.array([1, -2, 70000], dtype=">i4"),  # big-endian in memory: sent little-endian
        "np_u8": numpy.arange(4, dtype=numpy.uint8),
        "np_strided": numpy.arange(10, dtype=numpy.int16)[::3],
        "np_bool": numpy.array([True, False]),
        "raw": b"\x00\x01\xfe\xff",
        "raw_mutable": bytearray(b"ab"),
        "empty": array.array("d"),
    }


def test_a_cbor_subscriber_gets_typed_arrays_and_byte_strings_as_rosbridge_sends_them(
    bridge: tuple[Bridge, RunningBridge],
) -> None:
    served, running = bridge
    arrays = typed()
    message = {
        **arrays,
        "header": {"frame_id": "base_link ☃", "stamp": {"sec": 5, "nanosec": 7}},
        "ranges": [1.0, 2.5],  # plain lists stay plain arrays, their ints and floats as they are
        "counts": [1, 2, 3],
        "points": ({"x": 1, "y": 0.5},),  # a tuple is an array, as in JSON
        "ok": True,
        "none": None,
    }
    with connect(running.url, open_timeout=WAIT) as cbor, connect(running.url, open_timeout=WAIT) as plain:
        send(cbor, op="subscribe", topic="test/scan", compression="cbor", id="s1")
        send(plain, op="subscribe", topic="/test/scan")
        sync(cbor), sync(plain)
        served.publish("/test/scan", message)
        message["header"]["frame_id"] = "changed after publish"  # the publisher's dict is its own again
        arrays["f64"][0] = 9.0  # the message sent holds a copy
        (binary,) = frames(cbor)
        (text,) = frames(plain)
    assert isinstance(binary, bytes) and isinstance(text, str)
    decoded = cbor2.loads(binary)
    assert set(decoded) == {"op", "topic", "msg"} and decoded["op"] == "publish"
    assert decoded["topic"] == "test/scan"  # under the name the subscriber used, as in JSON
    msg = untag(decoded["msg"])
    f32 = [struct.unpack("<f", struct.pack("<f", x))[0] for x in (0.5, -1.25, 0.1)]
    assert msg == {
        "u8": b"\x00\x07\xff",  # uint8 as a byte string, as rosbridge sends uint8[]
        "i8": ("int8", [-128, 0, 127]),
        "u16": ("uint16", [0, 65535]),
        "i16": ("int16", [-32768, 5]),
        "u32": ("uint32", [4_000_000_000]),
        "i32": ("int32", [-2_000_000_000, 1]),
        "u64": ("uint64", [2**64 - 1]),
        "i64": ("int64", [-(2**63), 2**53 + 1]),
        "f32": ("float32", f32),
        "f64": ("float64", [0.1, -2.5e300]),
        "np_f32": ("float32", [1.5, 2.25]),
        "np_be_i32": ("int32", [1, -2, 70000]),
        "np_u8": b"\x00\x01\x02\x03",
        "np_strided": ("int16", [0, 3, 6, 9]),
        "np_bool": [True, False],  # rosbridge sends bool[] as a plain array
        "raw": b"\x00\x01\xfe\xff",
        "raw_mutable": b"ab",
        "empty": ("float64", []),
        "header": {"frame_id": "base_link ☃", "stamp": {"sec": 5, "nanosec": 7}},
        "ranges": [1.0, 2.5],
        "counts": [1, 2, 3],
        "points": [{"x": 1, "y": 0.5}],
        "ok": True,
        "none": None,
    }
    # the types survive: ints stay ints and floats floats (1.0 is no 1), as JSON readers see them
    assert [type(x) for x in msg["ranges"]] == [float, float] and [type(x) for x in msg["counts"]] == [int] * 3
    assert type(msg["points"][0]["x"]) is int and type(msg["header"]["stamp"]["sec"]) is int
    # the JSON subscriber reads the same message: arrays as lists, bytes as base64 (rosbridge's uint8[])
    published = json.loads(text)["msg"]
    assert published["f32"] == f32 and published["i64"] == [-(2**63), 2**53 + 1]
    assert published["u8"] == [0, 7, 255] and published["np_bool"] == [True, False]
    assert base64.b64decode(published["raw"]) == b"\x00\x01\xfe\xff" and published["raw_mutable"] == "YWI="
    assert published["header"]["frame_id"] == "base_link ☃" and published["empty"] == []


def test_client_messages_reach_a_cbor_subscriber_with_their_values_and_types(
    bridge: tuple[Bridge, RunningBridge],
) -> None:
    _, running = bridge
    message = {"data": "snow ☃", "n": 1, "x": 1.0, "big": 2**70, "list": [1, 2.5, "a", None, [True]], "o": {}}
    with (
        connect(running.url, open_timeout=WAIT) as talker,
        connect(running.url, open_timeout=WAIT) as cbor,
        connect(running.url, open_timeout=WAIT) as twice,
    ):
        send(talker, op="advertise", topic="/chatter", type="std_msgs/String")
        send(cbor, op="subscribe", topic="/chatter", compression="cbor")
        send(twice, op="subscribe", topic="chatter", compression="cbor", id="a")
        send(twice, op="subscribe", topic="chatter", compression="png", id="b")  # CBOR wins, as in rosbridge
        sync(talker), sync(cbor), sync(twice)
        for n in range(3):
            send(talker, op="publish", topic="/chatter", msg={**message, "seq": n})
        got, got_twice = frames(cbor), frames(twice)
        send(twice, op="unsubscribe", topic="chatter", id="a")  # only the png request is left
        sync(twice)
        send(talker, op="publish", topic="/chatter", msg=message)
        (png,) = frames(twice)
    assert [decoded(frame) for frame in got] == [
        {"op": "publish", "topic": "/chatter", "msg": {**message, "seq": n}} for n in range(3)
    ]
    assert [decoded(frame)["topic"] for frame in got_twice] == ["chatter"] * 3
    first = decoded(got[0])["msg"]
    assert type(first["x"]) is float and type(first["n"]) is int and first["big"] == 2**70
    assert isinstance(png, str) and json.loads(png)["op"] == "png"


def test_a_latched_message_reaches_a_late_cbor_subscriber_with_its_typed_arrays(
    bridge: tuple[Bridge, RunningBridge],
) -> None:
    served, running = bridge
    served.publish("/test/latched", {"ranges": array.array("f", [0.5, 1.5]), "id": 3})
    with connect(running.url, open_timeout=WAIT) as talker, connect(running.url, open_timeout=WAIT) as late:
        send(late, op="subscribe", topic="/test/latched", compression="cbor")
        latched = [frame for frame in sync(late) if isinstance(frame, bytes)]
        send(talker, op="advertise", topic="/map", type="nav_msgs/OccupancyGrid", latch=True)
        send(talker, op="publish", topic="/map", msg={"data": [0, 100, -1], "resolution": 0.05}, latch=True)
        sync(talker)
        send(late, op="subscribe", topic="/map", compression="cbor")
        latched += [frame for frame in sync(late) if isinstance(frame, bytes)]
    assert [untag(cbor2.loads(frame)) for frame in latched] == [
        {"op": "publish", "topic": "/test/latched", "msg": {"ranges": ("float32", [0.5, 1.5]), "id": 3}},
        {"op": "publish", "topic": "/map", "msg": {"data": [0, 100, -1], "resolution": 0.05}},
    ]


def test_cbor_raw_is_refused_naming_the_topic_and_nothing_is_subscribed(
    bridge: tuple[Bridge, RunningBridge],
) -> None:
    served, running = bridge
    with connect(running.url, open_timeout=WAIT) as ws:
        send(ws, op="set_level", level="warning")
        send(ws, op="subscribe", topic="/test/scan", compression="cbor-raw", id="raw")
        (status,) = [json.loads(frame) for frame in sync(ws)]
        served.publish("/test/scan", {"data": 1})
        after = frames(ws)
    assert status["level"] == "error" and status["id"] == "raw"
    assert "cbor-raw" in status["msg"] and "'/test/scan'" in status["msg"] and "ROS serialization" in status["msg"]
    assert "compression 'cbor'" in status["msg"]  # what to do instead
    assert after == []


def test_an_unknown_compression_gets_json_and_a_warning_and_cbor_with_fragments_goes_whole(
    bridge: tuple[Bridge, RunningBridge],
) -> None:
    served, running = bridge
    long = "z" * 5000
    with connect(running.url, open_timeout=WAIT) as zstd, connect(running.url, open_timeout=WAIT) as cbor:
        send(zstd, op="set_level", level="warning")
        send(cbor, op="set_level", level="warning")
        send(zstd, op="subscribe", topic="/test/scan", compression="zstd", id="z")
        send(cbor, op="subscribe", topic="/test/scan", compression="cbor", fragment_size=300, id="f")
        (unknown,) = [json.loads(frame) for frame in sync(zstd)]
        (whole,) = [json.loads(frame) for frame in sync(cbor)]
        served.publish("/test/scan", {"data": long})
        (as_json,) = frames(zstd)
        (as_cbor,) = frames(cbor)
    assert unknown["level"] == "warning" and "'zstd' is not supported; sending JSON" in unknown["msg"]
    assert whole["level"] == "warning" and whole["id"] == "f" and "goes whole" in whole["msg"]
    assert json.loads(as_json)["msg"] == {"data": long}
    assert isinstance(as_cbor, bytes) and cbor2.loads(as_cbor)["msg"] == {"data": long}


def test_a_binary_frame_of_utf8_json_is_read_as_rosbridge_suite_reads_it(bridge: tuple[Bridge, RunningBridge]) -> None:
    _, running = bridge
    with connect(running.url, open_timeout=WAIT) as ws:
        ws.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "b ☃"}).encode("utf-8"))
        answer = json.loads(ws.recv(timeout=WAIT))
    assert answer["op"] == "service_response" and answer["id"] == "b ☃" and answer["result"] is True


@pytest.mark.parametrize(
    "frame",
    [
        pytest.param(cbor2.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "c"}), id="cbor"),
        # BSON of {"op": "set_level", "level": "info"}: valid UTF-8, but with NULs no JSON text has
        pytest.param(bson({"op": "set_level", "level": "info"}), id="bson"),
        pytest.param(b"\xff\xfe{}", id="not-utf8"),
    ],
)
def test_cbor_or_bson_from_a_client_is_refused_and_the_connection_stays_up(
    bridge: tuple[Bridge, RunningBridge], frame: bytes
) -> None:
    _, running = bridge
    with connect(running.url, open_timeout=WAIT) as ws:
        ws.send(frame)
        (status,) = [json.loads(text) for text in sync(ws)]
    assert status == {"op": "status", "level": "error", "msg": BINARY_REFUSED}
    assert "CBOR or BSON from a client is not read" in BINARY_REFUSED


@pytest.mark.parametrize(
    ("value", "said"),
    [
        (array.array("u", "text"), "typecode 'u'"),
        (numpy.zeros((2, 2)), "one dimension, not shape (2, 2)"),
        (numpy.zeros(2, dtype=numpy.float16), "float16"),
        (numpy.array(["a"]), "<U1"),
        (object(), "not JSON serializable"),
    ],
)
def test_a_server_message_with_an_array_rosbridge_has_no_form_for_is_refused(
    bridge: tuple[Bridge, RunningBridge], value: Any, said: str
) -> None:
    served, _ = bridge
    with pytest.raises(TypeError, match=said.replace("(", r"\(").replace(")", r"\)")):
        served.publish("/test/scan", {"data": value})


def test_the_copy_for_cbor_writes_keys_as_json_does() -> None:
    assert cbor_values({7: [2], 2.5: (b"x",), False: None, None: "n", "s": array.array("B", [1])}) == {
        "7": [2],
        "2.5": [b"x"],
        "false": None,
        "null": "n",
        "s": b"\x01",
    }
    assert json.loads(json.dumps({7: 0, 2.5: 0, False: 0, None: 0})) == {"7": 0, "2.5": 0, "false": 0, "null": 0}


def test_cbor_frames_count_their_bytes_in_the_queue_bound_and_go_out_as_binary() -> None:
    queue = TopicQueue(backlog=100, max_bytes=1000)
    for seq in range(5):
        queue.push(seq, bytes(400))
    assert len(queue) == 2 and queue.size == 800 and queue.dropped == 3  # the newest kept, within the bound

    sent: list[list[str | bytes]] = []

    async def main() -> None:
        async def one(frame: str | bytes) -> None:
            sent.append([frame])

        async def many(batch: list[str | bytes]) -> None:
            sent.append(list(batch))

        session = Session("s", one, lambda reason: None, 1000, send_many=many)
        session.subscribe("/a", "/a", None, 0, 0, "cbor", None)
        session.subscribe("/b", "/b", None, 0, 0, "png", None)
        assert session.cbor == {"/a"}
        session.offer("/a", b"\xa1\x61a\x01")
        session.offer("/b", '{"op":"publish","topic":"/b","msg":{}}')
        writer = asyncio.get_running_loop().create_task(session.run())
        for _ in range(50):
            if sent:
                break
            await asyncio.sleep(0.01)
        session.close()
        await writer

    asyncio.run(main())
    (batch,) = sent
    assert batch[0] == b"\xa1\x61a\x01"  # CBOR goes as it is, whole, as a binary frame
    assert isinstance(batch[1], str) and json.loads(batch[1])["op"] == "png"


def test_send_frames_sends_text_and_cbor_in_order_each_as_its_kind_of_frame() -> None:
    sent: list[str | bytes] = ['{"op":"status"}', b"\xa1\x61a\x01", b"\xa0", '{"op":"x"}']

    async def main() -> list[str | bytes]:
        async def handler(websocket: ServerConnection) -> None:
            await send_frames(websocket, sent[:3])  # framed together, then the last through send
            await send_frames(websocket, sent[3:])
            await websocket.wait_closed()

        async with ws_serve(handler, "127.0.0.1", 0, compression=None) as server:
            port = server.sockets[0].getsockname()[1]
            async with ws_connect(f"ws://127.0.0.1:{port}", compression=None) as client:
                return [await asyncio.wait_for(client.recv(), WAIT) for _ in sent]

    assert asyncio.run(main()) == sent  # str arrives as str (a text frame), bytes as bytes (binary)


def test_typed_arrays_are_sent_little_endian_from_a_big_endian_machine_too() -> None:
    big = struct.pack(">2d", 1.5, -2.0)
    assert _tagged("f", 8, big, swap=True) == cbor2.CBORTag(86, struct.pack("<2d", 1.5, -2.0))
    assert _tagged("i", 1, b"\xff\x01", swap=True) == cbor2.CBORTag(72, b"\xff\x01")
    assert _tagged("u", 1, b"\xff", swap=True) == b"\xff"
