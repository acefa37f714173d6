"""The largest message a rosbridge client may send is a setting of ``cbrs serve``
(``CBRS_BRIDGE_MAX_MESSAGE_BYTES``): a lab whose cameras send raw images raises it, and the bridge takes
a message that the default of 1 MiB refuses."""

from __future__ import annotations

import json

import pytest
from websockets.sync.client import connect

from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from tests.test_serve import WAIT, receive

BIG = "x" * (1536 * 1024)  # 1.5 MiB: past the default, within the 2 MiB set below


@pytest.mark.parametrize("limit", [None, 2 * 1024 * 1024], ids=["default", "raised"])
def test_a_message_past_the_default_is_taken_when_the_setting_allows_it(
    limit: int | None, monkeypatch: pytest.MonkeyPatch
) -> None:
    if limit is not None:
        monkeypatch.setenv("CBRS_BRIDGE_MAX_MESSAGE_BYTES", str(limit))
    kb = KnowledgeBase.open(":memory:")
    server = Server(kb, ServeConfig(port=0, bridge_port=0))
    server.start()
    try:
        url = f"ws://127.0.0.1:{server.bridge_port}"
        with connect(url, open_timeout=WAIT, close_timeout=WAIT, max_size=4 * 1024 * 1024) as ws:  # it gets it back
            ws.send(json.dumps({"op": "subscribe", "topic": "/big", "type": "std_msgs/String"}))
            ws.send(json.dumps({"op": "advertise", "topic": "/big", "type": "std_msgs/String"}))
            ws.send(json.dumps({"op": "publish", "topic": "/big", "msg": {"data": BIG}}))
            if limit is None:
                status = receive(ws, "status", level="error")
                assert "max_message_bytes" in status["msg"] and "1048576" in status["msg"]
            else:
                assert receive(ws, "publish", topic="/big")["msg"]["data"] == BIG
    finally:
        server.stop(timeout=10.0)
        kb.close()


def test_the_setting_refuses_a_limit_that_is_not_positive(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CBRS_BRIDGE_MAX_MESSAGE_BYTES", "0")
    with pytest.raises(ValueError, match="CBRS_BRIDGE_MAX_MESSAGE_BYTES"):
        ServeConfig()
