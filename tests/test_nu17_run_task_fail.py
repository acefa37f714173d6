"""/cbrs/run_task takes a live component to fail (`fail`), as `cbrs run --fail` does: a lab tests that its
remote thermometer fails over to its second one through the server. It was refused, "no simulated
component". One run in the simulated home; the components are the SDK's, on loopback."""

from __future__ import annotations

from typing import Any

from cbrs.bridge_client import BridgeClient
from cbrs.component import Component
from cbrs.server import Server
from tests.test_live_components import READING, THERMOMETER, TOKEN, server, thermometer, url

__all__ = ["server"]  # the fixture, used by name


def answering(description: str, calls: list[str], name: str) -> Component:
    made = Component(description)

    def read(request: dict[str, Any]) -> dict[str, Any]:
        calls.append(name)
        return READING

    made.handler(read)
    return made


def test_a_run_told_to_fail_a_live_component_fails_over_to_another(server: Server) -> None:
    calls: list[str] = []
    first = answering(thermometer(), calls, "first")
    second = answering(thermometer("/thermometer08/read").replace("Thermometer07", "Thermometer08"), calls, "second")
    with (
        first.connect(url(server), TOKEN),
        second.connect(url(server), TOKEN),
        BridgeClient(url(server), TOKEN, timeout=60) as client,
    ):
        run = client.call_sync("/cbrs/run_task", {"task": "RoomTemperature", "fail": [THERMOMETER], "wait": True})
    assert run["status"] == "succeeded", run["result"]["execution"]["reason"]
    attempts = [a for step in run["result"]["execution"]["steps"] for a in step["attempts"]]
    assert [a["outcome"] for a in attempts if a["component"] == THERMOMETER] == ["failed"]
    assert "injected" in next(a["reason"] for a in attempts if a["component"] == THERMOMETER)
    assert calls == ["second"]  # the injected fault stands in for the first one's call
