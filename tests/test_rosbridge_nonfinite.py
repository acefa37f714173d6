"""NaN and infinities in rosbridge messages: what the server reads, what each client gets.

ROS drivers put them in messages all the time (a LaserScan's ``inf`` range is "no return", REP 117; an
Imu's unknown covariance is NaN), and JSON has no numbers for them. The server reads Python's tokens
(``NaN``, ``Infinity``, ``-Infinity``: what roslibpy's json.dumps writes, what rosbridge_suite's
json.loads reads) and writes them in JSON text as ``Bridge(non_finite=)`` says: ``null`` by default (as
rosbridge_suite writes a ROS float field; roslibjs's JSON.parse reads nothing else) or the tokens.
CBOR carries the floats themselves. roslibpy runs in a child process (this file run as a script, as in
tests/test_rosbridge_roslibpy.py), roslibjs under node (skipped where node or it is missing); every
wait is bounded and everything is on loopback.

    python -m tests.test_rosbridge_nonfinite PORT    (from the repository's root)
"""

from __future__ import annotations

import array
import json
import math
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import ExitStack
from pathlib import Path
from typing import Any

import cbor2
import numpy
import pytest
from websockets.sync.client import ClientConnection, connect

from cbrs.rosbridge import Bridge, RunningBridge, protocol, wire
from tests.helpers_roslibjs import needs_roslibjs, node_inline
from tests.helpers_threads import assert_threads_end
from tests.test_rosbridge_roslibpy import _until

WAIT = 5.0  # seconds any single step may take
ROOT = Path(__file__).parent.parent
INF, NAN = float("inf"), float("nan")


def spelled(value: Any) -> Any:
    """``value`` with every float as its repr ('inf', '-inf', 'nan', '1.5'), so NaN compares equal."""
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, dict):
        return {key: spelled(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [spelled(item) for item in value]
    return value


# -- roslibpy, in a child process -----------------------------------------------------------------


def run_client(port: int) -> dict[str, Any]:
    """What roslibpy users get: the server's scan, a scan relayed from another roslibpy client, a parameter."""
    import roslibpy

    results: dict[str, Any] = {}
    a = roslibpy.Ros("127.0.0.1", port)
    b = roslibpy.Ros("127.0.0.1", port)
    a.run(timeout=WAIT)
    b.run(timeout=WAIT)

    scans: list[Any] = []
    roslibpy.Topic(b, "/test/scan", "sensor_msgs/LaserScan").subscribe(scans.append)
    b.get_topics()  # answered after the subscribe: it is in place
    roslibpy.Service(b, "/test/go", "std_srvs/Empty").call(roslibpy.ServiceRequest({}), timeout=WAIT)
    _until(lambda: bool(scans))
    results["scan"] = spelled(scans)

    relayed: list[Any] = []
    roslibpy.Topic(b, "/relay", "sensor_msgs/LaserScan").subscribe(relayed.append)
    talker = roslibpy.Topic(a, "/relay", "sensor_msgs/LaserScan")
    talker.advertise()
    # json.dumps writes the tokens: roslibpy sends {"ranges": [Infinity, -Infinity, NaN, 0.5]}
    message = roslibpy.Message({"ranges": [INF, -INF, NAN, 0.5]})
    results["relayed_heard"] = _until(lambda: bool(relayed), step=lambda: talker.publish(message))
    results["relayed"] = spelled(relayed[:1])

    a.set_param("/scan/range_max", INF)  # roslibpy sends the value as json.dumps text: "Infinity"
    results["param"] = spelled(b.get_param("/scan/range_max"))
    a.close()
    b.close()
    return results


def scan_bridge(non_finite: str | None = None) -> Bridge:
    """A bridge whose /test/go publishes a LaserScan-shaped message on /test/scan."""
    bridge = Bridge(call_timeout=WAIT) if non_finite is None else Bridge(call_timeout=WAIT, non_finite=non_finite)
    bridge.add_topic("/test/scan", "sensor_msgs/LaserScan")

    def go(args: dict[str, Any]) -> dict[str, Any]:
        bridge.publish("/test/scan", SCAN)
        return {}

    bridge.add_service("/test/go", "std_srvs/Empty", go)
    return bridge


#: A LaserScan as a driver sends it (REP 117: +inf no return, -inf too close, NaN an erroneous reading)
SCAN = {
    "header": {"frame_id": "laser", "stamp": {"sec": 3, "nanosec": 0}},
    "range_min": 0.1,
    "range_max": INF,
    "ranges": array.array("f", [1.5, INF, -INF, NAN]),
    "intensities": [0.5, NAN],
}
SCAN_AS_NULL = {
    "header": {"frame_id": "laser", "stamp": {"sec": 3, "nanosec": 0}},
    "range_min": "0.1",
    "range_max": None,
    "ranges": ["1.5", None, None, None],
    "intensities": ["0.5", None],
}
SCAN_AS_FLOATS = {
    **SCAN_AS_NULL,
    "range_max": "inf",
    "ranges": ["1.5", "inf", "-inf", "nan"],
    "intensities": ["0.5", "nan"],
}


@pytest.mark.parametrize("non_finite", ["null", "tokens"])
def test_roslibpy_gets_null_or_the_floats_and_its_own_tokens_are_relayed(non_finite: str) -> None:
    pytest.importorskip("roslibpy")
    bridge = scan_bridge(non_finite)
    threads = threading.active_count()
    with bridge.start(port=0) as running:
        command = [sys.executable, "-m", "tests.test_rosbridge_nonfinite", str(running.port)]
        child = subprocess.run(command, capture_output=True, text=True, timeout=60, cwd=ROOT)
    assert child.returncode == 0, child.stderr
    results = json.loads(child.stdout.strip().splitlines()[-1])
    if non_finite == "null":
        assert results == {
            "scan": [SCAN_AS_NULL],
            "relayed_heard": True,
            "relayed": [{"ranges": [None, None, None, "0.5"]}],
            "param": None,
        }
    else:  # Python's json reads the tokens back: every value as it was
        assert results == {
            "scan": [SCAN_AS_FLOATS],
            "relayed_heard": True,
            "relayed": [{"ranges": ["inf", "-inf", "nan", "0.5"]}],
            "param": "inf",
        }
    assert math.isinf(bridge.params.get("/scan/range_max"))  # the store keeps the float either way
    assert _until(lambda: threading.active_count() == threads)


# -- raw websocket clients ------------------------------------------------------------------------

#: RFC 8746 little-endian float32 / float64 typed-array tags (written out here, not taken from the code)
FLOAT_TAGS = {85: "<f", 86: "<d"}


def untag(value: Any) -> Any:
    """Decoded CBOR with each float typed array as ("float32" | "float64", [floats])."""
    if isinstance(value, cbor2.CBORTag):
        letter = FLOAT_TAGS[value.tag]
        size = struct.calcsize(letter)
        numbers = struct.unpack(f"{letter[0]}{len(value.value) // size}{letter[1]}", value.value)
        return ("float32" if size == 4 else "float64", list(numbers))
    if isinstance(value, dict):
        return {key: untag(item) for key, item in value.items()}
    if isinstance(value, list):
        return [untag(item) for item in value]
    return value


class Raw:
    """A client that sends text as given and reads frames as they come (CBOR or JSON), bounded."""

    def __init__(self, running: RunningBridge) -> None:
        self._stack = ExitStack()
        self.ws: ClientConnection = self._stack.enter_context(connect(running.url, open_timeout=WAIT, close_timeout=1))
        self._kept: list[tuple[Any, str | bytes]] = []  # messages passed over while waiting for another op

    def send(self, text: str) -> None:
        self.ws.send(text)

    def op(self, op: str) -> tuple[Any, str | bytes]:
        """The first message with ``op`` not yet taken (statuses skipped): decoded, and the frame as it came."""
        for index, kept in enumerate(self._kept):
            if kept[0]["op"] == op:
                return self._kept.pop(index)
        deadline = time.monotonic() + WAIT
        while True:
            frame = self.ws.recv(timeout=max(0.01, deadline - time.monotonic()))
            message = cbor2.loads(frame) if isinstance(frame, bytes) else json.loads(frame)
            if message["op"] == op:
                return message, frame
            if message["op"] != "status":
                self._kept.append((message, frame))

    def sync(self) -> None:
        """Return once the server has handled what this client sent before."""
        self.send('{"op": "call_service", "service": "/rosapi/get_time", "id": "sync"}')
        self.op("service_response")

    def close(self) -> None:
        self._stack.close()


Serve = Callable[[Bridge], Callable[[], Raw]]


@pytest.fixture
def serve() -> Iterator[Serve]:
    """Start a bridge: a factory of its clients, all closed (and the bridge stopped) after the test."""
    started: list[RunningBridge] = []
    clients: list[Raw] = []
    threads = threading.active_count()

    def start(bridge: Bridge) -> Callable[[], Raw]:
        running = bridge.start(port=0)
        started.append(running)

        def make() -> Raw:
            clients.append(Raw(running))
            return clients[-1]

        return make

    yield start
    for client in clients:
        client.close()
    for running in started:
        assert running.stop(timeout=5.0)
    assert_threads_end(threads, WAIT)


def subscribe(client: Raw, topic: str, compression: str = "none") -> None:
    client.send(json.dumps({"op": "subscribe", "topic": topic, "compression": compression}))
    client.sync()


def test_a_scan_the_server_publishes_reaches_json_as_null_and_cbor_as_the_floats(serve: Serve) -> None:
    bridge = scan_bridge()
    bridge.add_topic("/test/latched", "sensor_msgs/Imu", latch=True)
    imu = {"orientation_covariance": [NAN, 0.0, 0.0], "linear_acceleration": {"x": 0.0, "y": -INF, "z": 9.8}}
    bridge.publish("/test/latched", imu)
    client = serve(bridge)
    plain, binary = client(), client()
    subscribe(plain, "/test/scan")
    subscribe(binary, "/test/scan", "cbor")
    plain.sync()
    plain.send('{"op": "call_service", "service": "/test/go", "id": "go"}')
    message, frame = plain.op("publish")
    assert spelled(message["msg"]) == SCAN_AS_NULL
    assert isinstance(frame, str) and "NaN" not in frame and "Infinity" not in frame  # JSON.parse reads it
    message, frame = binary.op("publish")
    assert isinstance(frame, bytes)
    assert spelled(untag(message["msg"])) == {
        **SCAN_AS_FLOATS,
        "ranges": ["float32", ["1.5", "inf", "-inf", "nan"]],  # a typed array, as rosbridge_suite packs float32[]
    }
    # latched before anyone subscribed: the late CBOR subscriber gets the floats, the JSON one null
    subscribe(binary, "/test/latched", "cbor")
    assert spelled(binary.op("publish")[0]["msg"]) == spelled(imu)
    subscribe(plain, "/test/latched")
    late = plain.op("publish")[0]["msg"]
    assert late == {"orientation_covariance": [None, 0.0, 0.0], "linear_acceleration": {"x": 0.0, "y": None, "z": 9.8}}


def test_with_tokens_json_subscribers_get_python_s_nan_and_infinity(serve: Serve) -> None:
    client = serve(scan_bridge("tokens"))
    plain = client()
    subscribe(plain, "/test/scan")
    plain.send('{"op": "call_service", "service": "/test/go", "id": "go"}')
    message, frame = plain.op("publish")
    assert '"ranges":[1.5,Infinity,-Infinity,NaN]' in str(frame)  # what rosapi's and Python's json.dumps write
    assert spelled(message["msg"]) == SCAN_AS_FLOATS


@pytest.mark.parametrize("non_finite", ["null", "tokens"])
def test_a_client_s_tokens_are_relayed_to_json_and_cbor_subscribers_and_kept_when_latched(
    serve: Serve, non_finite: str
) -> None:
    client = serve(Bridge(non_finite=non_finite))
    talker, plain, binary = client(), client(), client()
    talker.send('{"op": "advertise", "topic": "/scan", "type": "sensor_msgs/LaserScan", "latch": true}')
    talker.sync()
    subscribe(plain, "/scan")
    subscribe(binary, "/scan", "cbor")
    # as roslibpy writes it (json.dumps), and as roslibjs writes the same (JSON.stringify): null
    talker.send('{"op": "publish", "topic": "/scan", "msg": {"ranges": [1.5, Infinity, -Infinity, NaN, null]}}')
    floats = ["1.5", "inf", "-inf", "nan", None]
    text = plain.op("publish")[1]
    if non_finite == "null":
        assert text == '{"op":"publish","topic":"/scan","msg":{"ranges":[1.5,null,null,null,null]}}'
    else:
        assert text == '{"op":"publish","topic":"/scan","msg":{"ranges":[1.5,Infinity,-Infinity,NaN,null]}}'
    assert spelled(binary.op("publish")[0]["msg"]) == {"ranges": floats}
    late = client()  # the latched message, to a CBOR subscriber that came after it: still the floats
    subscribe(late, "/scan", "cbor")
    assert spelled(late.op("publish")[0]["msg"]) == {"ranges": floats}


def test_service_values_and_parameters_follow_the_same_rule(serve: Serve) -> None:
    bridge = Bridge(params={"/scan/range_max": INF})
    bridge.add_service("/test/pose", "test/Pose", lambda args: {"covariance": [NAN, 1.0], "echo": args})
    client = serve(bridge)
    me = client()
    me.send('{"op": "call_service", "service": "/test/pose", "id": 1, "args": {"x": -Infinity}}')
    assert me.op("service_response")[0]["values"] == {"covariance": [None, 1.0], "echo": {"x": None}}
    me.send('{"op": "call_service", "service": "/rosapi/get_param", "id": 2, "args": {"name": "/scan/range_max"}}')
    assert me.op("service_response")[0]["values"]["value"] == "null"  # roslibjs JSON.parses the value too
    # a parameter's value is JSON text inside the message: roslibpy writes NaN there as json.dumps does
    me.send('{"op": "call_service", "service": "/rosapi/set_param", "args": {"name": "/k", "value": "[NaN, 2]"}}')
    me.op("service_response")
    assert spelled(bridge.params.get("/k")) == ["nan", 2]


def test_what_must_still_be_refused_is() -> None:
    with pytest.raises(ValueError, match="non_finite must be one of null, tokens, not 'strings'"):
        Bridge(non_finite="strings")
    bridge = Bridge()
    bridge.add_topic("/t", "x/Y")
    with pytest.raises(ValueError, match="not JSON compliant"):  # a float key: no field has such a name
        bridge.publish("/t", {NAN: 1.0})
    loop: list[Any] = []
    loop.append(loop)
    with pytest.raises(ValueError, match="Circular reference"):  # the encoder's own error, not a recursion
        bridge.publish("/t", {"loop": loop})


def test_encode_says_when_its_text_lost_a_number_and_copies_arrays_of_floats() -> None:
    assert protocol.encode({"x": [1.0, 2]}) == ('{"x":[1.0,2]}', True)
    assert protocol.encode({"x": [1.0, INF, "NaN"]}) == ('{"x":[1.0,null,"NaN"]}', False)
    assert protocol.encode({"x": [-INF, NAN]}, "tokens") == ('{"x":[-Infinity,NaN]}', True)
    assert protocol.encode_decoded(protocol.decode('{"op":"p","x":[NaN,1]}', 100)) == ('{"op":"p","x":[null,1]}', False)
    assert protocol.finite({"f": numpy.float64(NAN), "a": numpy.array([1.0, INF]), "i": array.array("i", [1])}) == {
        "f": None,
        "a": [1.0, None],
        "i": array.array("i", [1]),  # no float in it: left to the encoder
    }
    text, exact = wire.typed_encode({"r": array.array("d", [NAN, 2.0]), "b": b"\x01"})
    assert (text, exact) == ('{"r":[null,2.0],"b":"AQ=="}', False)


# -- roslibjs under node --------------------------------------------------------------------------

#: Subscribes to the server's scan as JSON and as CBOR and to /relay as CBOR, calls /test/go (the server
#: publishes its scan, and a Python client publishes Python's tokens on /relay), publishes a scan with
#: NaN and Infinity itself on /relay, and prints what its callbacks got, non-finite numbers spelled out.
ROSLIBJS = """
import { Ros, Service, Topic } from "roslib";
import { bounded } from "./bounded.mjs";
setTimeout(() => { console.error("gave up after 30 s"); process.exit(2); }, 30000).unref();
const url = `ws://127.0.0.1:${Number(process.argv[1])}`;
const connect = () => bounded("connect", 5000, (resolve, reject) => {
  const ros = new Ros({ url });
  ros.on("connection", () => resolve(ros));
  ros.on("error", (error) => reject(new Error(`connect: ${error?.message ?? error}`)));
});
const spell = (value) => {
  if (typeof value === "number") return Number.isFinite(value) ? value : String(value);
  if (ArrayBuffer.isView(value)) return { typed: value.constructor.name, values: Array.from(value, spell) };
  if (Array.isArray(value)) return value.map(spell);
  if (value !== null && typeof value === "object") {
    return Object.fromEntries(Object.entries(value).map(([key, item]) => [key, spell(item)]));
  }
  return value;
};
const [plain, cbor, talker] = [await connect(), await connect(), await connect()];
const heard = { scan_json: [], scan_cbor: [], relay_cbor: [] };
const listen = (ros, name, compression, into) =>
  new Topic({ ros, name, messageType: "sensor_msgs/LaserScan", compression }).subscribe((m) => into.push(spell(m)));
listen(plain, "/test/scan", "none", heard.scan_json);
listen(cbor, "/test/scan", "cbor", heard.scan_cbor);
listen(cbor, "/relay", "cbor", heard.relay_cbor);
const call = (ros, name) => bounded(`call ${name}`, 5000, (resolve, reject) =>
  new Service({ ros, name, serviceType: "any" }).callService({}, resolve, reject));
await call(plain, "/rosapi/get_time");
await call(cbor, "/rosapi/get_time");
await call(plain, "/test/go");
const relay = new Topic({ ros: talker, name: "/relay", messageType: "sensor_msgs/LaserScan" });
relay.publish({ ranges: [NaN, Infinity, -Infinity, 0.5] });  // JSON.stringify sends null for each
const full = () => heard.scan_json.length && heard.scan_cbor.length && heard.relay_cbor.length >= 2;
const deadline = Date.now() + 5000;
while (!full() && Date.now() < deadline) await new Promise((resolve) => setTimeout(resolve, 20));
console.log(JSON.stringify(heard));
process.exit(0);
"""


@needs_roslibjs
def test_roslibjs_gets_null_in_json_and_the_floats_in_cbor() -> None:
    bridge = Bridge(call_timeout=WAIT)
    bridge.add_topic("/test/scan", "sensor_msgs/LaserScan")

    def go(args: dict[str, Any]) -> dict[str, Any]:
        bridge.publish("/test/scan", SCAN)
        with connect(f"ws://127.0.0.1:{port[0]}", open_timeout=WAIT, close_timeout=1) as python:  # roslibpy's text
            python.send('{"op": "advertise", "topic": "/relay", "type": "sensor_msgs/LaserScan"}')
            python.send('{"op": "publish", "topic": "/relay", "msg": {"ranges": [NaN, Infinity, -Infinity, 0.5]}}')
            python.send('{"op": "call_service", "service": "/rosapi/get_time", "id": "sync"}')
            while json.loads(python.recv(timeout=WAIT))["op"] != "service_response":
                pass
        return {}

    bridge.add_service("/test/go", "std_srvs/Empty", go)
    port: list[int] = []
    threads = threading.active_count()
    with bridge.start(port=0) as running:
        port.append(running.port)
        heard = node_inline(ROSLIBJS, running.port)
    assert heard["scan_json"] == [
        {
            "header": {"frame_id": "laser", "stamp": {"sec": 3, "nanosec": 0}},
            "range_min": 0.1,
            "range_max": None,
            "ranges": [1.5, None, None, None],
            "intensities": [0.5, None],
        }
    ]
    assert heard["scan_cbor"] == [
        {
            "header": {"frame_id": "laser", "stamp": {"sec": 3, "nanosec": 0}},
            "range_min": 0.1,
            "range_max": "Infinity",
            "ranges": {"typed": "Float32Array", "values": [1.5, "Infinity", "-Infinity", "NaN"]},
            "intensities": [0.5, "NaN"],
        }
    ]
    # from the Python client: the floats; from roslibjs itself: the nulls JSON.stringify wrote
    assert sorted(heard["relay_cbor"], key=json.dumps) == sorted(
        [{"ranges": ["NaN", "Infinity", "-Infinity", 0.5]}, {"ranges": [None, None, None, 0.5]}], key=json.dumps
    )
    assert_threads_end(threads, WAIT)


#: Subscribes, calls /go (the server publishes a message with Infinity, then one without) and reports
#: what its callback and its error listener got, and whether the connection still answers.
ROSLIBJS_TOKENS = """
import { Ros, Service, Topic } from "roslib";
import { bounded } from "./bounded.mjs";
setTimeout(() => { console.error("gave up after 30 s"); process.exit(2); }, 30000).unref();
const ros = new Ros({ url: `ws://127.0.0.1:${Number(process.argv[1])}` });
const errors = [];
ros.on("error", (error) => errors.push(String(error?.message ?? error)));
await bounded("connect", 5000, (resolve) => ros.on("connection", resolve));
const got = [];
new Topic({ ros, name: "/t", messageType: "x/Y" }).subscribe((message) => got.push(message));
const call = (name) => bounded(`call ${name}`, 5000, (resolve, reject) =>
  new Service({ ros, name, serviceType: "any" }).callService({}, resolve, reject));
await call("/rosapi/get_time");
await call("/go");
const deadline = Date.now() + 5000;
while (!got.length && Date.now() < deadline) await new Promise((resolve) => setTimeout(resolve, 20));
await call("/rosapi/get_time");
console.log(JSON.stringify({ got, errors }));
process.exit(0);
"""


@needs_roslibjs
def test_roslibjs_drops_a_message_with_tokens_and_says_so() -> None:
    """Why ``null`` is the default: JSON.parse refuses the tokens, so roslibjs loses the whole message."""
    bridge = Bridge(call_timeout=WAIT, non_finite="tokens")
    bridge.add_topic("/t", "x/Y")

    def go(args: dict[str, Any]) -> dict[str, Any]:
        bridge.publish("/t", {"r": [1.0, INF]})
        bridge.publish("/t", {"r": [2.0]})
        return {}

    bridge.add_service("/go", "x/Go", go)
    with bridge.start(port=0) as running:
        heard = node_inline(ROSLIBJS_TOKENS, running.port)
    assert heard["got"] == [{"r": [2]}]  # the first is lost; the connection and later messages are not
    (error,) = heard["errors"]
    assert "Infinity" in error and "is not valid JSON" in error


if __name__ == "__main__":
    print(json.dumps(run_client(int(sys.argv[1]))), flush=True)
