"""A fleet on one store: several cbrs servers on one `oxigraph serve`, and commands against a running server.

A component registered through one server is matched through the other; the CLI reaches a server by
its base URL (the token from the environment), and a command that finds a served on-disk store locked
says which URL to use. Every wait is a bounded poll."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.bridge_client import BridgeClient
from cbrs.cli import cli
from cbrs.component import Component
from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig
from tests.test_live_components import READING, THERMOMETER, eventually, thermometer

TOKEN = "fleet-test-token"


def serve(location: str) -> Server:
    endpoint = EndpointConfig(update_token=TOKEN, isolate=False)
    kb = KnowledgeBase.open(location, remote_timeout=30.0)
    server = Server(kb, ServeConfig(port=0, bridge_port=0, endpoint=endpoint, component_lease=1.0))
    server.start()
    return server


@pytest.fixture
def fleet(remote_location: str) -> Iterator[tuple[Server, Server]]:
    first = serve(remote_location)
    second = serve(remote_location)
    try:
        yield first, second
    finally:
        second.stop()
        first.stop()


def best_for_room_temperature(server: Server) -> str:
    with BridgeClient(f"ws://127.0.0.1:{server.bridge_port}") as client:
        ranking = client.call_sync("/cbrs/match", {"requirement": "RoomTemperature", "top": 1})
    return str(ranking["candidates"][0]["advertisement"])


def test_a_component_registered_through_one_server_is_matched_by_the_other(fleet: tuple[Server, Server]) -> None:
    first, second = fleet
    assert best_for_room_temperature(second) != THERMOMETER
    component = Component(thermometer())
    component.handler(lambda request: READING)
    with component.connect(f"ws://127.0.0.1:{first.bridge_port}", TOKEN):
        assert eventually(lambda: best_for_room_temperature(second) == THERMOMETER)
    # its session closed on the first server: the second reads that from the store too
    assert eventually(lambda: best_for_room_temperature(second) != THERMOMETER)
    assert not second.kb.liveness.states()[THERMOMETER].live


def test_the_cli_reaches_a_running_server_by_its_url_and_a_locked_store_names_it(tmp_path: Path) -> None:
    store = str(tmp_path / "store")
    server = serve(store)
    try:
        url = f"http://127.0.0.1:{server.http_port}"
        locked = CliRunner().invoke(cli, ["--store", store, "query", "ASK { ?s ?p ?o }"])
        assert locked.exit_code != 0 and f"--store {url}" in locked.output
        asked = CliRunner().invoke(cli, ["--store", url, "query", "SELECT ?d WHERE { ?s cbrs:deviceName ?d } LIMIT 1"])
        assert asked.exit_code == 0, asked.output
        description = tmp_path / "thermometer.ttl"
        description.write_text(thermometer(), encoding="utf-8")
        anonymous = CliRunner().invoke(
            cli, ["--store", url, "register", str(description)], env={"CBRS_UPDATE_TOKEN": ""}
        )
        assert anonymous.exit_code != 0 and not server.kb.registry.is_registered(THERMOMETER)
        registered = CliRunner().invoke(
            cli, ["--store", url, "register", str(description)], env={"CBRS_UPDATE_TOKEN": TOKEN}
        )
        assert registered.exit_code == 0, registered.output
        assert server.kb.registry.is_registered(THERMOMETER)
    finally:
        server.stop()
    assert not (Path(store) / "cbrs-served-at.txt").exists()  # the server forgot its URL when it stopped
