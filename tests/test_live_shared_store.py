"""Servers sharing one store hear nothing of each other's writes: what another server (or a program
writing the store itself) does to a live component's liveness is seen at a look at the liveness graph,
every ``SHARED_LOOK`` seconds, not at the lease's next store write (half a lease and a beat: up to 30 s
with the minute-long lease here). An Oxigraph server on loopback is the store."""

from __future__ import annotations

import logging
from collections.abc import Iterator

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig
from tests.test_live_components import THERMOMETER, TOKEN, eventually, sdk_thermometer, url
from tests.test_restore_liveness import LAPSED


@pytest.fixture
def shared(remote_location: str) -> Iterator[Server]:
    """A server on the remote store; the tests write the store as another server or program would."""
    endpoint = EndpointConfig(update_token=TOKEN, isolate=False)
    server = Server(KnowledgeBase.open(remote_location), ServeConfig(port=0, bridge_port=0, endpoint=endpoint))
    server.start()
    try:
        yield server
    finally:
        server.stop()


def test_a_component_deregistered_through_another_process_loses_its_lease_within_a_look(
    shared: Server, remote_location: str
) -> None:
    """`cbrs --store URL deregister` of a live component, URL the shared store (as through another server):
    the server holding its lease ended it only when half the lease had passed and a beat wrote the store,
    and until then took its calls' answers."""
    with sdk_thermometer().connect(url(shared), TOKEN, heartbeat=1.0, ttl=60.0):
        assert shared.live.live() == [THERMOMETER]
        removed = CliRunner().invoke(cli, ["--store", remote_location, "deregister", THERMOMETER])
        assert removed.exit_code == 0, removed.output
        assert eventually(lambda: not shared.live.live(), seconds=10.0)  # a look: 1 s; the lease's write: 30 s


def test_a_lease_another_writer_says_ended_is_written_again_within_a_look(
    shared: Server, remote_location: str, caplog: pytest.LogCaptureFixture
) -> None:
    """A restore by URL of the shared store through another server, or any update of graph:liveness there."""
    caplog.set_level(logging.INFO, logger="cbrs.live_components")
    with sdk_thermometer().connect(url(shared), TOKEN, heartbeat=1.0, ttl=60.0):
        other = KnowledgeBase.open(remote_location)
        try:
            other.update(LAPSED)  # the server's next look writes it again (it may come before the next line)
            assert eventually(lambda: other.liveness.states()[THERMOMETER].live, seconds=10.0)
            said = f"{THERMOMETER}: the store said otherwise of its lease; written again"
            assert eventually(lambda: said in caplog.text, seconds=10.0)  # logged once the lease is written
        finally:
            other.close()
