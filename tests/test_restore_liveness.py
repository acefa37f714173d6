"""A restore keeps the liveness of the components live now: which session holds a component and its lease
are the server's present state, which no backup holds (docs/backup.md, "Live components").

Found by a lab's integrator: a backup restored by URL into a running ``cbrs serve`` brought back the
``cbrs:registeredBy`` of the session that had registered a live component when the backup was taken, so
``GET /components`` named a session that no longer existed beside the live lease and availability."""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterator
from pathlib import Path

import httpx
import pyoxigraph as ox
import pytest
from click.testing import CliRunner

import cbrs.kb.backup
from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.liveness import RESTORED_REASON
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.vocab import CBRS
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig
from tests.test_live_components import TOKEN, eventually, live_server, sdk_thermometer, thermometer, url

THERMOMETER = PREFIXES["svc"] + "ReadRoomTemperature_Thermometer07"


def _described(iri: str) -> str:
    """A second live component's description: the thermometer's, renamed, on a service of its own."""
    return thermometer(service="/hygrometer/read").replace("Thermometer07", iri)


def test_a_restore_by_url_keeps_the_session_that_holds_a_live_component(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The lab's steps: export by URL, the component registers again from another session (the server
    restarted, or the program did), restore by URL, ``GET /components``."""
    endpoint = EndpointConfig(update_token=TOKEN, isolate=False)
    server = Server(KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0, endpoint=endpoint))
    server.start()
    try:
        location = f"http://127.0.0.1:{server.http_port}"
        monkeypatch.setenv("CBRS_UPDATE_TOKEN", TOKEN)
        backup = tmp_path / "served.nq"
        runner = CliRunner()
        with sdk_thermometer().connect(url(server), TOKEN):
            first = server.kb.liveness.states()[THERMOMETER].registered_by
            exported = runner.invoke(cli, ["--store", location, "export", str(backup)])
            assert exported.exit_code == 0, exported.output
        assert eventually(lambda: not server.kb.liveness.states()[THERMOMETER].live)
        with sdk_thermometer().connect(url(server), TOKEN):
            now = server.kb.liveness.states()[THERMOMETER]
            assert now.live and now.registered_by != first
            restored = runner.invoke(cli, ["--store", location, "restore", str(backup), "--yes"])
            assert restored.exit_code == 0, restored.output
            (shown,) = httpx.get(f"{location}/components", timeout=10).json()
            assert shown["component"] == THERMOMETER and shown["available"] is True
            assert shown["registeredBy"] == now.registered_by  # the live session, not the backup's
    finally:
        server.stop()


LAPSED = """
DELETE { GRAPH graph:liveness { ?c cbrs:leaseUntil ?until } }
INSERT { GRAPH graph:liveness { ?c cbrs:leaseUntil "2001-01-01T00:00:00+00:00"^^xsd:dateTime } }
WHERE { GRAPH graph:liveness { ?c cbrs:leaseUntil ?until } }
"""
"""An update that says every lease ended long ago: what a restore's old copy of the liveness writes."""


def test_a_write_that_says_a_held_lease_ended_is_corrected_before_it_is_answered() -> None:
    """The flake of the restore by URL above: the restore read the liveness, took seconds to write the
    store (a loaded machine), and put back a lease that had ended meanwhile, though the server had renewed
    it; the server wrote it again only at its next renewal's store write. Now the server states the leases
    it holds again as soon as another's write says otherwise. A long lease: its own renewal writes the
    store only after 30 s, so nothing else would correct it here."""
    with live_server() as server, sdk_thermometer().connect(url(server), TOKEN, heartbeat=1.0, ttl=60.0):
        held = server.kb.liveness.states()[THERMOMETER]
        server.sparql.update(LAPSED, TOKEN)  # as over HTTP: the listeners are told before it is answered
        now = server.kb.liveness.states()[THERMOMETER]
        assert now.live and now.registered_by == held.registered_by
        assert now.lease_until is not None and now.lease_until > dt.datetime.now(dt.UTC) + dt.timedelta(seconds=30)


def test_a_restore_by_url_written_after_the_program_came_back_keeps_its_new_session(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The component's program reconnects while a restore by URL is being written: the restore's copy of
    the liveness, read before, names the session that has gone; the store ends up naming the live one."""
    endpoint = EndpointConfig(update_token=TOKEN, isolate=False)
    server = Server(KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0, endpoint=endpoint))
    server.start()
    try:
        location = f"http://127.0.0.1:{server.http_port}"
        monkeypatch.setenv("CBRS_UPDATE_TOKEN", TOKEN)
        backup, runner = tmp_path / "liveness.nq", CliRunner()
        first = sdk_thermometer().connect(url(server), TOKEN, ttl=60.0)
        before = server.kb.liveness.states()[THERMOMETER].registered_by
        exported = runner.invoke(cli, ["--store", location, "export", "--graph", "liveness", str(backup)])
        assert exported.exit_code == 0, exported.output
        came_back = []
        write = cbrs.kb.backup._replace_remote

        def reconnected_meanwhile(*args: object, **kwargs: object) -> None:
            first.stop()  # the liveness to write was read: the program goes and comes back
            assert eventually(lambda: not server.kb.liveness.states()[THERMOMETER].live)
            came_back.append(sdk_thermometer().connect(url(server), TOKEN, ttl=60.0))
            write(*args, **kwargs)  # type: ignore[arg-type]

        monkeypatch.setattr(cbrs.kb.backup, "_replace_remote", reconnected_meanwhile)
        try:
            restored = runner.invoke(cli, ["--store", location, "restore", str(backup), "--graph", "liveness", "--yes"])
            assert restored.exit_code == 0, restored.output
            assert len(came_back) == 1
            (shown,) = httpx.get(f"{location}/components", timeout=10).json()
            now = server.kb.liveness.states()[THERMOMETER]
            assert shown["available"] is True and shown["registeredBy"] == now.registered_by
            assert now.live and now.registered_by not in (None, before)
        finally:
            for connected in came_back:
                connected.stop()
    finally:
        server.stop()


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    opened = KnowledgeBase.open(":memory:")
    opened.registry.register(thermometer(), "<registration>")
    opened.registry.register(_described("Hygrometer02"), "<registration>")
    yield opened
    opened.close()


def _facts(kb: KnowledgeBase, component: str) -> dict[str, str]:
    quads = kb.store.quads(ox.NamedNode(component), graph=GraphName.LIVENESS.node)
    return {quad.predicate.value: quad.object.value for quad in quads}


def test_the_components_live_now_keep_their_facts_and_the_backups_leases_are_not_taken(
    kb: KnowledgeBase, tmp_path: Path
) -> None:
    hygrometer = PREFIXES["svc"] + "ReadRoomTemperature_Hygrometer02"
    kb.liveness.renew(THERMOMETER, 600, registered_by="cbrs session client 1")
    kb.liveness.renew(hygrometer, 600, registered_by="cbrs session client 2")
    backup = tmp_path / "taken.nq"
    kb.export(backup)
    kb.liveness.expire(THERMOMETER, "its session closed")  # the program went
    kb.liveness.renew(THERMOMETER, 600, registered_by="cbrs session client 3")  # and came back
    kb.liveness.expire(hygrometer, "its session closed")  # this one went and stays away
    live = _facts(kb, THERMOMETER)
    report = kb.restore(backup)
    assert _facts(kb, THERMOMETER) == live and report.live_kept == (THERMOMETER,)
    states = kb.liveness.states()
    assert states[THERMOMETER].live and states[THERMOMETER].registered_by == "cbrs session client 3"
    # the backup's lease of the hygrometer, 10 minutes long, is no lease: no session holds it now
    assert not states[hygrometer].live and states[hygrometer].reason == RESTORED_REASON
    assert states[hygrometer].registered_by == "cbrs session client 2" and report.live_ended == (hygrometer,)
    assert hygrometer not in {a.iri for a in kb.advertisements()}  # not matched nor planned


def test_a_component_live_now_that_the_backup_does_not_describe_loses_its_liveness(
    kb: KnowledgeBase, tmp_path: Path
) -> None:
    backup = tmp_path / "before.nq"
    kb.export(backup)
    newer = PREFIXES["svc"] + "ReadRoomTemperature_Barometer03"
    kb.registry.register(thermometer(service="/barometer/read").replace("Thermometer07", "Barometer03"), "<r>")
    kb.liveness.renew(newer, 600, registered_by="cbrs session client 4")
    kb.restore(backup)
    assert not kb.registry.is_registered(newer) and newer not in kb.liveness.states()


def test_a_restore_of_other_graphs_leaves_the_liveness_alone(kb: KnowledgeBase, tmp_path: Path) -> None:
    backup = tmp_path / "map.nq"
    kb.export(backup)
    kb.liveness.renew(THERMOMETER, 600, registered_by="cbrs session client 5")
    live = set(kb.store.quads(graph=GraphName.LIVENESS.node))
    report = kb.restore(backup, graphs=["map"])
    assert set(kb.store.quads(graph=GraphName.LIVENESS.node)) == live and report.live_kept == ()


def test_a_restore_of_the_liveness_graph_alone_keeps_the_live_sessions(kb: KnowledgeBase, tmp_path: Path) -> None:
    kb.liveness.renew(THERMOMETER, 600, registered_by="cbrs session client 6")
    backup = tmp_path / "liveness.nq"
    kb.export(backup, graphs=["liveness"])
    kb.liveness.renew(THERMOMETER, 600, registered_by="cbrs session client 7")
    kb.restore(backup, graphs=["liveness"])
    assert kb.liveness.states()[THERMOMETER].registered_by == "cbrs session client 7"
    until = kb.liveness.states()[THERMOMETER].lease_until
    assert until is not None and until > dt.datetime.now(dt.UTC)
    quads = list(kb.store.quads(ox.NamedNode(THERMOMETER), ox.NamedNode(CBRS.registeredBy), None, None))
    assert len(quads) == 1
