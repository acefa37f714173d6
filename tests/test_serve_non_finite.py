"""``cbrs serve``'s bridge writes a client's NaN and infinities as the ``bridge_non_finite`` setting says.

One client publishes a LaserScan-like message with Python's tokens (as roslibpy writes them), another
subscribed reads the text the server relays. Loopback only; every wait bounded.
"""

from __future__ import annotations

import json
import math
import threading
from collections.abc import Iterator

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.rosbridge import protocol
from cbrs.server import ServeConfig, Server
from cbrs.settings import NON_FINITE
from tests.helpers_threads import assert_threads_end
from tests.test_serve import bridge, receive

WAIT = 10.0
SCAN = '{"op":"publish","topic":"/lab/scan","msg":{"ranges":[1.5,Infinity,-Infinity,NaN]}}'


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    opened = KnowledgeBase.open(":memory:")
    yield opened
    opened.close()


def relayed(kb: KnowledgeBase, non_finite: str) -> str:
    """The text a JSON subscriber gets of SCAN on a server with ``bridge_non_finite`` set so."""
    threads = threading.active_count()
    server = Server(kb, ServeConfig(port=0, bridge_port=0, bridge_non_finite=non_finite))
    server.start()
    try:
        with bridge(server) as publisher, bridge(server) as subscriber:
            publisher.send(json.dumps({"op": "advertise", "topic": "/lab/scan", "type": "sensor_msgs/LaserScan"}))
            subscriber.send(json.dumps({"op": "subscribe", "topic": "/lab/scan", "type": "sensor_msgs/LaserScan"}))
            subscriber.send(json.dumps({"op": "call_service", "id": "sync", "service": "/rosapi/topics"}))
            receive(subscriber, "service_response", id="sync")  # the subscription is in place
            publisher.send(SCAN)
            text = ""
            for _ in range(20):  # bounded: the scan is the next publish, status messages aside
                text = str(subscriber.recv(timeout=WAIT))
                if '"op":"publish"' in text.replace(" ", ""):
                    break
            return text
    finally:
        server.stop(timeout=WAIT)
        assert_threads_end(threads, WAIT)


def test_the_default_writes_null_as_rosbridge_suite_does(kb: KnowledgeBase) -> None:
    message = json.loads(relayed(kb, "null"))  # strict JSON: JSON.parse in a browser reads it too
    assert message["msg"]["ranges"] == [1.5, None, None, None]


def test_tokens_keep_the_values_for_python_clients(kb: KnowledgeBase) -> None:
    text = relayed(kb, "tokens")
    assert "Infinity" in text and "NaN" in text
    ranges = json.loads(text)["msg"]["ranges"]
    assert ranges[:3] == [1.5, math.inf, -math.inf] and math.isnan(ranges[3])


def test_the_settings_choices_are_the_bridges() -> None:
    assert NON_FINITE == protocol.NON_FINITE


def test_a_bad_setting_is_refused_naming_the_variable(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CBRS_BRIDGE_NON_FINITE", "zero")
    with pytest.raises(ValueError, match=r"CBRS_BRIDGE_NON_FINITE.*null, tokens"):
        ServeConfig()
