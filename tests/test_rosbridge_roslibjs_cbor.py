"""roslibjs (the npm package ``roslib``), unchanged, subscribing with ``compression: "cbor"``.

tests/js/cbor.mjs subscribes in node and prints what roslibjs handed its callbacks, each typed array
named by its class. roslibjs decodes CBOR with the npm cbor2 package, which reads RFC 8746 typed-array
tags into JavaScript typed arrays (64-bit ones into BigInt arrays) and byte strings into Uint8Arrays,
as it reads rosbridge_suite's. Needs node and ``npm ci --prefix tests/js``, like
tests/test_rosbridge_roslibjs.py; without them the test is skipped. The script runs as a child process
on loopback, every wait in it bounded, killed by its PID if it outlives its timeout.
"""

from __future__ import annotations

import array
import struct
import threading
from typing import Any

import numpy

from cbrs.rosbridge import Bridge
from tests.helpers_roslibjs import ROSLIBJS_MARKS, node
from tests.helpers_threads import assert_threads_end

pytestmark = ROSLIBJS_MARKS


def typed(kind: str, values: list[Any]) -> dict[str, Any]:
    return {"typed": kind, "values": values}


def float32(values: list[float]) -> list[float]:
    return [struct.unpack("<f", struct.pack("<f", value))[0] for value in values]


SCAN = {
    "header": {"frame_id": "laser ☃", "stamp": {"sec": 12, "nanosec": 5}},
    "ranges": array.array("f", [0.5, 1.25, 0.1]),
    "intensities": numpy.array([0.1, 2.0], dtype=numpy.float64),
    "ids": array.array("i", [-7, 70000]),
    "counts": array.array("H", [1, 65535]),
    "small": array.array("b", [-1, 2]),
    "wide": array.array("q", [-(2**62), 2**53 + 1]),
    "image": b"\x00\x10\xff",
    "pixels": numpy.arange(3, dtype=numpy.uint8),
    "flags": numpy.array([True, False]),
    "plain": [1, 2.5],
}


def test_roslibjs_reads_cbor_typed_arrays_byte_strings_and_relayed_json() -> None:
    bridge = Bridge(call_timeout=5.0)
    bridge.add_topic("/test/scan", "sensor_msgs/LaserScan")
    bridge.add_topic("/test/latched", "nav_msgs/OccupancyGrid", latch=True)
    bridge.publish("/test/latched", {"data": array.array("b", [0, 100, -1]), "info": {"resolution": 0.05}})

    def go(args: dict[str, Any]) -> dict[str, Any]:
        bridge.publish("/test/scan", SCAN)
        return {}

    bridge.add_service("/test/go", "std_srvs/Empty", go)
    threads = threading.active_count()
    with bridge.start(port=0) as running:
        heard = node("cbor.mjs", running.port)
    assert heard["scan"] == [
        {
            "header": {"frame_id": "laser ☃", "stamp": {"sec": 12, "nanosec": 5}},
            "ranges": typed("Float32Array", float32([0.5, 1.25, 0.1])),
            "intensities": typed("Float64Array", [0.1, 2.0]),
            "ids": typed("Int32Array", [-7, 70000]),
            "counts": typed("Uint16Array", [1, 65535]),
            "small": typed("Int8Array", [-1, 2]),
            # int64 as BigInt, exact past 2**53 (a JSON number there would not be)
            "wide": typed("BigInt64Array", [{"bigint": str(-(2**62))}, {"bigint": str(2**53 + 1)}]),
            "image": typed("Uint8Array", [0, 16, 255]),  # bytes: a byte string, as rosbridge sends uint8[]
            "pixels": typed("Uint8Array", [0, 1, 2]),
            "flags": [True, False],
            "plain": [1, 2.5],
        }
    ]
    (as_json,) = heard["scan_json"]
    # JavaScript's numbers lose the int64s' low digits, and print -2**62 in 17 digits: compared as doubles
    assert [float(x) for x in as_json.pop("wide")] == [float(-(2**62)), float(2**53 + 1)]
    assert heard["scan_json"] == [  # the same message to a JSON subscriber: lists, and bytes as base64
        {
            "header": {"frame_id": "laser ☃", "stamp": {"sec": 12, "nanosec": 5}},
            "ranges": float32([0.5, 1.25, 0.1]),
            "intensities": [0.1, 2.0],
            "ids": [-7, 70000],
            "counts": [1, 65535],
            "small": [-1, 2],
            "image": "ABD/",
            "pixels": [0, 1, 2],
            "flags": [True, False],
            "plain": [1, 2.5],
        }
    ]
    assert heard["latched"] == [{"data": typed("Int8Array", [0, 100, -1]), "info": {"resolution": 0.05}}]
    assert heard["chatter"] == [  # a client's JSON, relayed as CBOR: plain arrays, values as sent
        {"data": "snow ☃", "n": 1, "x": 1.5, "list": [1, 2.5, "a", None, [True]], "nested": {"deep": {"k": -3}}}
    ]
    assert_threads_end(threads, 5.0)
