"""A live component whose lease lapses while it executes a call: the call fails at once, with why, as
when its provider disconnects; its late answer acts on nothing. Loopback only; every wait bounded."""

from __future__ import annotations

import threading
from typing import Any

import pytest

from cbrs.actions.remote import RemoteCallError
from cbrs.bridge_client import BridgeClient
from cbrs.server import Server
from tests.test_live_components import READING, THERMOMETER, TOKEN, server, thermometer, url

__all__ = ["server"]  # the fixture, used by name


def test_a_call_in_flight_fails_when_its_components_lease_lapses(server: Server) -> None:
    release = threading.Event()

    def stuck(request: dict[str, Any]) -> dict[str, Any]:
        release.wait(10.0)  # a blocked driver: no answer while the lease runs out
        return READING

    with BridgeClient(url(server), TOKEN) as component, BridgeClient(url(server), TOKEN) as caller:
        component.provide("/thermometer07/read", "cbrs_msgs/RoomTemperature", stuck)
        # registered without heartbeats: its lease lapses after 0.5 s
        registered = component.call_sync("/cbrs/register", {"description": thermometer(), "ttl": 0.5})
        assert registered["components"] == [THERMOMETER]
        call = caller.call("/thermometer07/read", {}, timeout=20.0)
        try:
            with pytest.raises(RemoteCallError, match="lease lapsed while '/thermometer07/read' was executing"):
                call.result(timeout=5.0)  # well before the call's own 20 s
            assert not server.kb.liveness.states()[THERMOMETER].live
        finally:
            release.set()
