"""``cbrs run --bridge``: a run from the command line calls components that live in other processes.

A live thermometer (the SDK, in this process) is connected to a server's bridge; ``cbrs run`` against the
server's store reaches it only through that bridge, and says so when it was not given one. Loopback only.
"""

from __future__ import annotations

import json
from typing import Any

import pytest
from click.testing import CliRunner

from cbrs.actions.remote_errors import RemoteCallError
from cbrs.bridge_client import BridgeClient
from cbrs.cli import cli
from cbrs.kb.namespaces import PREFIXES
from cbrs.server import Server
from cbrs.sim.services import SKILLS
from tests.test_live_components import READING, THERMOMETER, TOKEN, eventually, sdk_thermometer, server, url

__all__ = ["server"]  # the fixture, used by name
WORLD = PREFIXES["world"]


def run(server: Server, *options: str) -> Any:
    store = f"http://127.0.0.1:{server.http_port}"
    arguments = ["--store", store, "run", "req:RoomTemperature", *options]
    return CliRunner().invoke(cli, arguments, env={"CBRS_UPDATE_TOKEN": TOKEN})


def test_a_run_calls_a_live_component_through_the_bridge_it_is_given(
    server: Server, monkeypatch: pytest.MonkeyPatch
) -> None:
    # a home whose only room thermometer is the lab's: the bundled sensor board's simulated temperature
    # (sim.room_quantities) would answer the run without a bridge
    monkeypatch.delitem(SKILLS, "MeasureTemperature")
    calls: list[dict[str, Any]] = []
    tables: list[dict[str, Any]] = []  # what a device's program read from the run's load cell meanwhile
    device = BridgeClient(url(server), TOKEN)

    def read(request: dict[str, Any]) -> dict[str, Any]:
        calls.append(request)
        tables.append(device.call_sync("/sim/load", {"place": "KitchenTable"}))
        return READING

    with device, sdk_thermometer(read).connect(url(server), TOKEN):
        without = run(server)
        assert without.exit_code == 1 and calls == []
        assert "svc:ReadRoomTemperature_Thermometer07 is a component in another process" in without.output
        assert "--bridge ws://HOST:PORT" in without.output

        through = run(server, "--bridge", url(server))
        assert through.exit_code == 0, through.output
        assert calls == [{}]
        assert "svc:ReadRoomTemperature_Thermometer07" in through.output and "succeeded" in through.output
        # the run's own world answered the device on the server's bridge (docs/components.md), and only
        # while it ran
        (table,) = tables
        assert table["resting"] == [WORLD + "Cup", WORLD + "Pen"] and table["load_kg"] > 0
        with pytest.raises(RemoteCallError, match="does not exist"):
            device.call_sync("/sim/load", {"place": "KitchenTable"})


def test_a_bridge_that_is_no_websocket_or_does_not_answer_is_a_usage_error(server: Server) -> None:
    not_ws = run(server, "--bridge", f"http://127.0.0.1:{server.bridge_port}")
    assert not_ws.exit_code == 2 and "is not a websocket URL" in not_ws.output
    nobody = run(server, "--bridge", "ws://127.0.0.1:9")  # the discard port: nothing listens
    assert nobody.exit_code == 2 and "cannot reach the bridge at ws://127.0.0.1:9" in nobody.output


def test_services_says_whether_a_live_component_can_be_invoked_now(server: Server) -> None:
    store = f"http://127.0.0.1:{server.http_port}"
    listed = CliRunner().invoke(cli, ["--store", store, "services"])
    assert listed.exit_code == 0 and " live" not in listed.output.splitlines()[0]  # none yet: no column
    with sdk_thermometer().connect(url(server), TOKEN):
        while_connected = CliRunner().invoke(cli, ["--store", store, "services"]).output
        as_json = CliRunner().invoke(cli, ["--store", store, "services", "--json"]).output
    line = next(x for x in while_connected.splitlines() if "Thermometer07" in x)
    assert line.rstrip().endswith("available")
    assert {"available": True, "reason": None} in [item.get("live") for item in json.loads(as_json)]
    assert eventually(lambda: not server.kb.liveness.states()[THERMOMETER].live)  # the session closed
    after = CliRunner().invoke(cli, ["--store", store, "services"]).output
    line = next(x for x in after.splitlines() if "Thermometer07" in x)
    assert "unavailable: " in line and "1 live component(s) unavailable now" in after


def test_a_live_component_deregistered_from_the_command_line_is_listed_no_more_at_once(server: Server) -> None:
    store = f"http://127.0.0.1:{server.http_port}"
    with sdk_thermometer().connect(url(server), TOKEN):
        assert server.kb.liveness.states()[THERMOMETER].live
        removed = CliRunner().invoke(
            cli, ["--store", store, "deregister", THERMOMETER], env={"CBRS_UPDATE_TOKEN": TOKEN}
        )
        assert removed.exit_code == 0, removed.output
        assert THERMOMETER not in server.kb.liveness.states()  # before its next heartbeat
        listed = CliRunner().invoke(cli, ["--store", store, "services"]).output
        assert "Thermometer07" not in listed
