"""Follow-ups of the seventeenth blind round (docs/serving.md, "Tried by a lab's system administrator"):
what it left in files its helper did not own, each a test that failed before its fix."""

from __future__ import annotations

import logging
import os
import subprocess
import sys
from pathlib import Path

import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.app import App
from cbrs.cli import cli, main
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import StoreError
from cbrs.kb.namespaces import GraphName
from cbrs.kb.store import EmbeddedStore
from cbrs.query_workers import QueryProcesses
from cbrs.settings import setting
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app
from tests.test_blind_admin17 import _fill, _insert

DOCS = Path(__file__).resolve().parents[1] / "docs"


def test_a_library_error_as_the_store_closes_is_an_error_not_an_internal_one(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # A KnowledgeBaseError raised by the command's close (after its output) read "internal error", exit 2.
    def refuse(_: App) -> None:
        raise StoreError("/lab/store", "flushing it to disk failed: its disk is full")

    monkeypatch.setattr(App, "close", refuse)
    monkeypatch.setattr(sys, "argv", ["cbrs", "--store", ":memory:", "settings"])
    monkeypatch.delenv("CBRS_DEBUG", raising=False)
    with pytest.raises(SystemExit) as caught:
        main()
    assert caught.value.code == 1
    err = capsys.readouterr().err
    assert err == "Error: store /lab/store: flushing it to disk failed: its disk is full\n"


def test_settings_md_says_what_the_log_level_help_says_of_requests() -> None:
    # The help of cbrs serve --log-level said INFO logs a line per request (b49616a); settings.md did not.
    [row] = [
        line for line in (DOCS / "settings.md").read_text("utf-8").splitlines() if line.startswith("| `log_level`")
    ]
    help_text = setting("log_level").help
    assert "a line per HTTP request" in help_text and "WARNING leaves those out" in help_text
    assert "At `INFO` and below the log also has one line per HTTP request" in row
    assert "`WARNING` leaves those out" in row


def test_healthz_is_503_while_the_stores_disk_refuses_writes_and_reads_no_store() -> None:
    # The round: on a full disk every update failed 507 while /healthz said "ok", "writable": true.
    kb = KnowledgeBase.open(":memory:")
    store = kb.store
    assert isinstance(store, EmbeddedStore)
    token = "followups-token"
    http = create_app(SparqlService(kb, EndpointConfig(update_token=token, isolate=False))).test_client()
    auth = {"Authorization": f"Bearer {token}"}
    ok = http.get("/healthz")
    assert ok.status_code == 200 and ok.get_json()["status"] == "ok"
    disk = _fill(store)
    disk.full = True
    assert http.post("/update", data={"update": _insert(1)}, headers=auth).status_code == 507
    backend, store._open = store._open, None  # any read of the store now raises "is closed"
    failing = http.get("/healthz")
    store._open = backend
    assert failing.status_code == 503
    body = failing.get_json()
    assert body["status"] == "failing" and "disk is full" in body["error"] and "restart" in body["error"]
    assert {key: body[key] for key in ("version", "store", "writable")} == {
        key: ok.get_json()[key] for key in ("version", "store", "writable")
    }
    disk.full = False  # a write that succeeds again clears the failure (a store opened anew has none)
    assert http.post("/update", data={"update": _insert(2)}, headers=auth).status_code == 204
    assert http.get("/healthz").get_json()["status"] == "ok"
    kb.close()


def _old_store(location: Path) -> str:
    """A store whose home.ttl says 0.4.0 (as one seeded at 56ca954~1 does); the bundled version."""
    home = ox.NamedNode("https://w3id.org/cbrs/home")
    version = ox.NamedNode("http://www.w3.org/2002/07/owl#versionInfo")
    kb = KnowledgeBase.open(location)
    [bundled] = [q.object for q in kb.store.quads(home, version, None, GraphName.ONTOLOGY.node)]
    assert isinstance(bundled, ox.Literal) and bundled.value != "0.4.0"
    kb.store.replace(
        [ox.Quad(home, version, bundled, GraphName.ONTOLOGY.node)],
        [ox.Quad(home, version, ox.Literal("0.4.0"), GraphName.ONTOLOGY.node)],
    )
    kb.close()
    return bundled.value


def test_a_command_that_upgrades_the_store_says_so(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    # The round: cbrs query on an old store upgraded it (home.ttl 0.4.0 -> 0.5.0) without a word.
    location = tmp_path / "old"
    bundled = _old_store(location)
    caplog.set_level(logging.WARNING, logger="cbrs.kb.upgrade")  # a command's log: nothing at INFO
    upgraded = CliRunner().invoke(cli, ["--store", str(location), "services"])
    assert upgraded.exit_code == 0, upgraded.output
    assert upgraded.stderr == (
        f"note: upgraded the store at {location} to this cbrs's bundled ontologies: home.ttl 0.4.0 -> {bundled}\n"
    )
    again = CliRunner().invoke(cli, ["--store", str(location), "services"])
    assert again.exit_code == 0 and again.stderr == ""


def test_an_upgrade_the_log_says_is_not_said_twice(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    # cbrs serve logs the upgrade at INFO (its log is its standard error): no note besides.
    location = tmp_path / "old"
    bundled = _old_store(location)
    caplog.set_level(logging.INFO, logger="cbrs.kb.upgrade")
    upgraded = CliRunner().invoke(cli, ["--store", str(location), "services"])
    assert upgraded.exit_code == 0 and upgraded.stderr == ""
    assert f"home.ttl 0.4.0 -> {bundled}" in caplog.text


def _ended_pid() -> int:
    """The PID of a process that has ended (and been waited for)."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait(timeout=30)
    return child.pid


def test_query_snapshots_name_their_store_and_process_and_a_dead_ones_are_removed(tmp_path: Path) -> None:
    # The round: a SIGKILLed server left .cbrs-query-snapshots-XXXXXXXX beside the store, hard links to old
    # store files holding disk space, named so that nobody could tell whose it was.
    store = EmbeddedStore.open(tmp_path / "labstore")
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        left = tmp_path / f".cbrs-query-snapshots-labstore-{_ended_pid()}-0a1b2c3d"
        mine_before = tmp_path / f".cbrs-query-snapshots-labstore-{os.getpid()}-0a1b2c3e"  # a restart, same PID
        kept = [
            tmp_path / f".cbrs-query-snapshots-labstore-{live.pid}-0a1b2c3f",  # a live server's
            tmp_path / f".cbrs-query-snapshots-labstore-2-{_ended_pid()}-0a1b2c40",  # store labstore-2's
            tmp_path / ".cbrs-query-snapshots-0a1b2c41",  # an older cbrs's: whose, it does not say
        ]
        for folder in (left, mine_before, *kept):
            (folder / "snapshot-1").mkdir(parents=True)
        processes = QueryProcesses(store, size=1, memory=0)
        try:
            root = processes._root
            assert root.parent == tmp_path
            assert root.name.startswith(f".cbrs-query-snapshots-labstore-{os.getpid()}-")
            assert not left.exists() and not mine_before.exists()
            assert all(folder.exists() for folder in kept)
            again = QueryProcesses(store, size=1, memory=0)  # a second in this process leaves the first's
            assert root.exists() and again._root != root
            again.close()
        finally:
            processes.close()
        assert not root.exists()
    finally:
        live.kill()
        live.wait(timeout=10)
        store.close()
