"""The component SDK given a bridge URL without a port: ``ws://127.0.0.1`` tries port 80, and a refused
connection used to say only "connection refused". It now says that no port was named, which was
tried, and that the bridge's default port is 9090."""

from __future__ import annotations

import socket
from typing import Any

import pytest

from cbrs.bridge_client import BridgeClosedError
from cbrs.component import Component
from tests.test_live_components import READING, thermometer


def _closed(port: int) -> bool:
    with socket.socket() as probe:
        probe.settimeout(1.0)
        return probe.connect_ex(("127.0.0.1", port)) != 0


def _component() -> Component:
    made = Component(thermometer())

    @made.handler
    def read(_: dict[str, Any]) -> dict[str, Any]:
        return READING

    return made


@pytest.mark.skipif(not _closed(80), reason="something listens on 127.0.0.1:80 here")
def test_a_url_without_a_port_refused_names_the_default_port() -> None:
    with pytest.raises(BridgeClosedError) as caught:
        _component().connect("ws://127.0.0.1", token=None)
    message = str(caught.value)
    assert "names no port, so port 80 was tried" in message
    assert "ws://HOST:9090" in message


def test_a_url_with_a_port_refused_gives_no_port_advice() -> None:
    with socket.socket() as holder:  # a port bound but not listening refuses connections
        holder.bind(("127.0.0.1", 0))
        port = holder.getsockname()[1]
        with pytest.raises(BridgeClosedError) as caught:
            _component().connect(f"ws://127.0.0.1:{port}", token=None)
    assert f"cannot reach the bridge at ws://127.0.0.1:{port}" in str(caught.value)
    assert "9090" not in str(caught.value)
