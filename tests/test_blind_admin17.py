"""The seventeenth blind round: a lab's system administrator ran ``cbrs serve`` for months from README and
docs/ alone (docs/serving.md, "Tried by a lab's system administrator"). Each test is a fault found then.

A full disk is a real engine's error text handed back by a stand-in for the store's Oxigraph backend (the
round filled a small tmpfs; a test cannot mount one), so the store's handling of it is what is tested.
"""

from __future__ import annotations

import io
import json
import logging
import threading
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pyoxigraph as ox
import pytest

from cbrs.cli_serve import _redact_in_log
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import GraphName
from cbrs.kb.store import EmbeddedStore, StoreDiskError
from cbrs.server import ServeConfig, Server
from cbrs.settings import setting
from cbrs.sparql_service import EndpointConfig
from tests.helpers_threads import assert_threads_end

TOKEN = "admin17-token-0123456789abcdef"
FULL = "IO error: No space left on device: While appending to file: {}/000024.log: No space left on device"


def _insert(n: int) -> str:
    """A one-triple update of a lab's own graph, the ``n``-th."""
    return f'INSERT DATA {{ GRAPH <urn:lab:admin> {{ <urn:lab:a> <urn:lab:b> "{n}" }} }}'


class _Disk:
    """The store's backend with a switch: while ``full``, writes and flushes fail as on a full disk (only
    the flush, when ``flushes_only``: the write went into the log before the disk filled)."""

    def __init__(self, backend: ox.Store, location: str) -> None:
        self.backend = backend
        self.location = location
        self.full = False
        self.flushes_only = False

    def _refuse(self, flush: bool) -> None:
        if self.full and (flush or not self.flushes_only):
            raise OSError(FULL.format(self.location))

    def update(self, *args: Any, **kwargs: Any) -> None:
        self._refuse(flush=False)
        self.backend.update(*args, **kwargs)

    def flush(self) -> None:
        self._refuse(flush=True)
        self.backend.flush()

    def __getattr__(self, name: str) -> Any:
        return getattr(self.backend, name)


def _fill(store: EmbeddedStore) -> _Disk:
    disk = _Disk(store._backend, store.location)
    store._open = disk  # type: ignore[assignment]
    return disk


@pytest.fixture
def kb(tmp_path: Path) -> Iterator[KnowledgeBase]:
    opened = KnowledgeBase.open(tmp_path / "store")
    yield opened
    opened.close()


def test_a_flush_on_a_full_disk_says_what_is_kept_and_the_store_still_closes(kb: KnowledgeBase) -> None:
    # The round: every command that had written ended "internal error: OSError: IO error: No space left
    # on device" at its close (cbrs restore after "restored 8105 triples", cbrs serve after "stopped").
    store = kb.store
    assert isinstance(store, EmbeddedStore)
    kb.update(_insert(1))
    disk = _fill(store)
    disk.full = True
    with pytest.raises(StoreDiskError) as raised:
        store.flush()
    assert "disk is full" in str(raised.value) and "write-ahead log and is kept" in str(raised.value)
    assert raised.value.http_status == 507
    store.close()  # no error: what was committed is in the log, and the engine (and its lock) let go
    assert store._open is None


def test_a_write_on_a_full_disk_is_507_says_to_restart_and_is_reported_once(kb: KnowledgeBase) -> None:
    store = kb.store
    assert isinstance(store, EmbeddedStore)
    told: list[StoreDiskError] = []
    store.on_failure = told.append
    disk = _fill(store)
    disk.full = True
    for n in range(2):
        with pytest.raises(StoreDiskError) as raised:
            store.update(_insert(n))
        assert raised.value.http_status == 507
        assert "nothing of this write was kept" in str(raised.value) and "restart" in str(raised.value)
    assert len(told) == 1 and store.failure is not None  # the first of a run, for the log
    disk.full = False
    store.update(_insert(3))
    assert store.failure is None
    disk.full = True
    with pytest.raises(StoreDiskError):
        store.update(_insert(4))
    assert len(told) == 2


def test_a_store_on_a_read_only_file_system_says_how_to_read_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The round mounted the store read-only: cbrs query and cbrs export said only the engine's "IO error:
    # While open a file for appending: .../LOG: Read-only file system", though neither writes.
    location = tmp_path / "store"
    location.mkdir()

    def read_only(path: str) -> ox.Store:
        raise OSError(f"IO error: While open a file for appending: {path}/LOG: Read-only file system")

    monkeypatch.setattr(ox, "Store", read_only)
    with pytest.raises(StoreDiskError) as raised:
        EmbeddedStore.open(location)
    assert "read-only" in str(raised.value) and "cp -a" in str(raised.value)


def test_a_restore_onto_a_full_disk_fails_before_it_says_restored(kb: KnowledgeBase, tmp_path: Path) -> None:
    backup = tmp_path / "lab.nq"
    kb.update(_insert(7))
    kb.export(backup)
    store = kb.store
    assert isinstance(store, EmbeddedStore)
    disk = _fill(store)
    disk.full = disk.flushes_only = True
    with pytest.raises(StoreDiskError, match="flushing it to disk failed"):
        kb.restore(backup)


@pytest.fixture
def served(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> Iterator[Server]:
    caplog.set_level(logging.INFO)  # before the listener is made: it logs requests when INFO is on
    threads = threading.active_count()
    opened = KnowledgeBase.open(tmp_path / "served")
    running = Server(opened, ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN)))
    running.start()
    yield running
    running.stop(timeout=10)
    opened.close()
    assert_threads_end(threads, 10)


def _post_update(server: Server, text: str, token: str) -> tuple[int, bytes]:
    request = urllib.request.Request(
        f"http://127.0.0.1:{server.http_port}/update",
        data=urllib.parse.urlencode({"update": text}).encode(),
        headers={"Authorization": f"Bearer {token}"},
    )
    try:
        with urllib.request.urlopen(request, timeout=10) as answer:
            return answer.status, answer.read()
    except urllib.error.HTTPError as error:
        return error.code, error.read()


def _access_lines(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [record.getMessage() for record in caplog.records if record.name == "granian.access"]


def test_every_request_is_logged_without_the_token_and_a_full_disk_once(
    served: Server, caplog: pytest.LogCaptureFixture
) -> None:
    # The round: the log held "rosbridge serving on ..." and nothing of the requests, not the writes nor
    # the refused ones (settings.md's log_level says "requests refused" are logged); then a full disk
    # failed every update with 500 and wrote nothing in the log.
    assert _post_update(served, _insert(1), TOKEN)[0] == 204
    assert _post_update(served, _insert(2), "a-wrong-token")[0] == 403
    store = served.kb.store
    assert isinstance(store, EmbeddedStore)
    _fill(store).full = True
    for n in (3, 4):
        status, body = _post_update(served, _insert(n), TOKEN)
        assert status == 507 and b"disk is full" in body
    lines = _access_lines(caplog)
    for wanted in ('"POST /update" 204', '"POST /update" 403', '"POST /update" 507'):
        assert any(wanted in line for line in lines), (wanted, lines)
    assert all(line.startswith("127.0.0.1 ") and line.endswith(" ms") for line in lines), lines
    assert TOKEN not in caplog.text
    full = [r for r in caplog.records if r.levelno >= logging.ERROR and "disk is full" in r.getMessage()]
    assert len(full) == 1, [r.getMessage() for r in full]  # the first of the run, not one per request


def test_the_token_is_kept_out_of_the_log_at_debug() -> None:
    # The round at --log-level debug: the websockets library logged the bridge's auth frame, the token in it.
    root = logging.getLogger()
    written = io.StringIO()
    handler = logging.StreamHandler(written)
    root.addHandler(handler)
    frames = logging.getLogger("websockets.server")
    level = frames.level
    frames.setLevel(logging.DEBUG)
    try:
        _redact_in_log(TOKEN)
        frame = json.dumps({"op": "auth", "mac": TOKEN})
        frames.debug("< TEXT %r [%d bytes]", frame, len(frame))
    finally:
        root.removeHandler(handler)
        frames.setLevel(level)
    assert TOKEN not in written.getvalue() and '"mac": "***"' in written.getvalue()


def test_an_upgrade_names_the_versions_it_went_from_and_to(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    # The round upgraded a store seeded by cbrs at 56ca954~1: the log said "home.ttl, qudt.ttl merged",
    # not from which version to which.
    location = tmp_path / "old"
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
    caplog.set_level(logging.INFO, logger="cbrs.kb.upgrade")
    KnowledgeBase.open(location).close()
    assert f"home.ttl 0.4.0 -> {bundled.value}" in caplog.text


@pytest.mark.parametrize(
    ("name", "raw", "said"), [("port", "abc", "a whole number"), ("query_timeout", "5s", "a number")]
)
def test_a_setting_that_is_no_number_is_refused_in_words(name: str, raw: str, said: str) -> None:
    # The round's service file had CBRS_PORT=abc: "invalid literal for int() with base 10: 'abc'".
    item = setting(name)
    with pytest.raises(ValueError) as raised:
        item.resolve(environ={item.env: raw})
    assert str(raised.value) == f"environment variable {item.env}={raw!r}: {raw!r} is not {said}"


@pytest.mark.parametrize("name", ["query_timeout", "check_timeout", "component_lease"])
def test_a_positive_setting_refuses_not_a_number(name: str) -> None:
    # CBRS_CHECK_TIMEOUT=nan was taken: "nan" parses as a float, and NaN <= 0 is false
    item = setting(name)
    with pytest.raises(ValueError, match="nan must be positive"):
        item.resolve(environ={item.env: "nan"})


EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"


def test_the_service_files_name_only_options_and_settings_cbrs_serve_has() -> None:
    # docs/examples/lab17_cbrs.service and lab17_cbrs.env, the round's unit for a lab's server
    from cbrs.cli_serve import serve
    from cbrs.settings import SETTINGS

    unit = (EXAMPLES / "lab17_cbrs.service").read_text("utf-8")
    [start] = [line.split("=", 1)[1].split() for line in unit.splitlines() if line.startswith("ExecStart=")]
    assert start[1:2] == ["serve"], start
    options = {name for param in serve.params for name in param.opts}
    assert [word for word in start if word.startswith("--") and word not in options] == []
    environment = {}
    for line in (EXAMPLES / "lab17_cbrs.env").read_text("utf-8").splitlines():
        if line.strip() and not line.startswith("#"):
            name, _, value = line.partition("=")
            environment[name] = value
    by_variable = {item.env: item for item in SETTINGS}
    assert sorted(set(environment) - set(by_variable)) == []
    for name in environment:
        by_variable[name].resolve(environ=environment)  # each value is one the setting takes
