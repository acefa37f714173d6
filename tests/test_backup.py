"""cbrs export and cbrs restore (kb/backup.py): a store written to a file and put back quad for quad, on the
embedded store and on an Oxigraph server and Virtuoso; a file that is not a whole export, does not parse, or
whose write fails leaves the store as it was."""

from __future__ import annotations

import io
import json
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs

import httpx
import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs import __version__, cli_notes, cli_store
from cbrs.cli import cli
from cbrs.kb import KnowledgeBase, RdfParseError, Store, StoreError
from cbrs.kb.backup import (
    EXPORT_GRAPH,
    REQUIRED,
    BackupError,
    NotAnExportError,
    UnknownExportFormatError,
    export_store,
    read_backup,
    store_graphs,
)
from cbrs.kb.namespaces import GraphName
from cbrs.kb.remote_store import Endpoints, RemoteStore
from cbrs.kb.staged_writes import STAGING
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig
from tests.conftest import DATA, MINI_FILES, OxigraphServer, VirtuosoServer
from tests.test_live_components import TOKEN

CHANGE = 'INSERT DATA { GRAPH graph:services { <http://example.org/lab#Cam9> rdfs:label "a ninth camera" } }'


@pytest.fixture(scope="module")
def seeded() -> Iterator[KnowledgeBase]:
    """One seeded in-memory store for the module; each test puts it back as it found it."""
    kb = KnowledgeBase.open(":memory:")
    yield kb
    kb.close()


@pytest.fixture(scope="module")
def exported(seeded: KnowledgeBase, tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("backup") / "store.nq"
    seeded.export(path)
    return path


def _change(kb: KnowledgeBase) -> None:
    kb.update(CHANGE)
    kb.update("DROP GRAPH graph:map")


@pytest.mark.parametrize("name", ["store.nq", "store.trig", "store.nq.gz", "store.trig.gz"])
def test_export_change_restore_gives_the_same_quads(seeded: KnowledgeBase, tmp_path: Path, name: str) -> None:
    before = seeded.store.dump()
    report = seeded.export(tmp_path / name)
    assert report.total == seeded.store.count() and set(report.triples) == {
        g.iri for g in (*REQUIRED, GraphName.ENTAILED)
    }
    _change(seeded)
    assert seeded.store.dump() != before
    restored = seeded.restore(tmp_path / name)
    assert seeded.store.dump() == before
    assert restored.restored == report.triples and not restored.entailed_refreshed
    assert EXPORT_GRAPH.value not in seeded.store.graphs()
    assert [p.name for p in tmp_path.iterdir()] == [name]  # written beside its name, then moved into place


def test_a_file_cut_short_or_not_an_export_is_refused_and_the_store_left(
    seeded: KnowledgeBase, exported: Path, tmp_path: Path
) -> None:
    before = seeded.store.dump()
    lines = exported.read_bytes().splitlines(keepends=True)
    cut = tmp_path / "cut.nq"
    cut.write_bytes(b"".join(lines[: len(lines) // 2]))
    with pytest.raises(NotAnExportError, match=r"cut\.nq: not a cbrs export: it has no manifest"):
        seeded.restore(cut)
    holed = tmp_path / "holed.nq"
    holed.write_bytes(b"".join(lines[:10] + lines[20:]))
    with pytest.raises(NotAnExportError, match=r"the manifest says \d+ \(lines lost\?\)"):
        seeded.restore(holed)
    broken = tmp_path / "broken.nq"
    broken.write_bytes(b"".join(lines[:5]) + b"<http://x> <http://y> .\n" + b"".join(lines[5:]))
    with pytest.raises(RdfParseError, match=r"broken\.nq: .*nothing was restored"):
        seeded.restore(broken)
    with pytest.raises(UnknownExportFormatError, match=r"use one of \.nq, \.nq\.gz, \.trig, \.trig\.gz"):
        seeded.restore(tmp_path / "store.ttl")
    assert seeded.store.dump() == before


def test_a_partial_export_restores_its_graphs_only_or_whole_when_forced(
    seeded: KnowledgeBase, exported: Path, tmp_path: Path
) -> None:
    before = seeded.store.dump()
    services = tmp_path / "services.nq"
    seeded.export(services, graphs=["services"])
    _change(seeded)
    with pytest.raises(NotAnExportError, match="lacks cbrs's own graphs graph:ontology, graph:requirements, graph:map"):
        seeded.restore(services)
    assert read_backup(services).manifest is not None and read_backup(services).manifest.partial  # type: ignore[union-attr]
    report = seeded.restore(services, graphs=["services"])  # graph:map stays dropped; services put back
    assert report.entailed_refreshed and GraphName.MAP.iri not in seeded.store.graphs()
    assert seeded.store.count(GraphName.SERVICES) == before.count(b"/graph/services> .\n")
    forced = seeded.restore(services, force=True)
    assert set(seeded.store.graphs()) <= {GraphName.SERVICES.iri, GraphName.ENTAILED.iri} and forced.entailed_refreshed
    seeded.restore(exported)
    assert seeded.store.dump() == before


def test_the_cli_exports_asks_and_restores(tmp_path: Path) -> None:
    store, backup = tmp_path / "store", tmp_path / "lab.trig"
    runner = CliRunner()
    exported = runner.invoke(cli, ["--store", str(store), "export", str(backup)])
    assert exported.exit_code == 0, exported.output
    assert f"to {backup}: " in exported.output and "in graph:services" in exported.output
    kb = KnowledgeBase.open(store)
    before = kb.store.dump()
    kb.update(CHANGE)
    services = kb.store.count(GraphName.SERVICES)
    kb.close()
    restored = runner.invoke(cli, ["--store", str(store), "restore", str(backup), "--yes"])
    assert restored.exit_code == 0, restored.output
    line = next(line for line in restored.stdout.splitlines() if "graph:services" in line)
    assert line.split() == ["graph:services", str(services - 1), "triples", "(was", str(services), "triples)"]
    kb = KnowledgeBase.open(store)
    assert kb.store.dump() == before
    kb.close()
    plain = tmp_path / "plain.nq"
    plain.write_text("<http://example.org/a> <http://example.org/b> <http://example.org/c> <http://example.org/g> .\n")
    refused = runner.invoke(cli, ["--store", str(store), "restore", str(plain), "--yes"])
    assert refused.exit_code == 1 and "not a cbrs export" in refused.output and "--force" in refused.output
    out = runner.invoke(cli, ["--store", str(store), "export", "-", "--graph", "requirements"])
    assert out.exit_code == 0 and "<https://w3id.org/cbrs/graph/export> ." in out.stdout


@pytest.mark.parametrize(("answer", "code"), [("n\n", 1), ("y\n", 0)])
def test_a_person_at_a_terminal_is_asked_first(
    exported: Path, monkeypatch: pytest.MonkeyPatch, answer: str, code: int
) -> None:
    monkeypatch.setattr(cli_store, "_at_terminal", lambda: True)
    result = CliRunner().invoke(cli, ["--store", ":memory:", "restore", str(exported)], input=answer)
    assert result.exit_code == code, result.output
    triples = sum(read_backup(exported).triples.values())
    assert f"Replace everything in :memory: with the {triples} triples of {exported} (exported " in result.stderr
    assert (f"restored {triples} triples" in result.stdout) == (code == 0)


def _contents(kb: KnowledgeBase) -> list[str]:
    """The store's quads, sorted, but for the graphs its server keeps (Virtuoso's, whose blank node labels
    pyoxigraph refuses, so that dump() fails there)."""
    return sorted(str(q) for graph in store_graphs(kb.store) for q in kb.store.quads(graph=ox.NamedNode(graph)))


def _remote_store(location: str) -> KnowledgeBase:
    """A small store on a server, with every graph a restore asks for (the seed would take Virtuoso some
    10 s to write, and as long to restore)."""
    kb = KnowledgeBase(Store.open(location))
    kb.load(MINI_FILES)
    kb.load([DATA / "mini_map.ttl"], graph="map")
    return kb


def test_a_remote_oxigraph_store_round_trips_and_a_failed_publication_leaves_it(
    oxigraph_server: OxigraphServer, tmp_path: Path
) -> None:
    oxigraph_server.clear()
    kb = _remote_store(oxigraph_server.url)
    assert isinstance(kb.store, RemoteStore)
    kb.store.batch = 20  # several staging batches, as a large store sends
    before = _contents(kb)
    backup = tmp_path / "remote.nq"
    kb.export(backup)
    kb.update(CHANGE)
    kb.update("DELETE WHERE { GRAPH graph:map { ?thing home:x ?x } }")
    sent: list[str] = []
    send = kb.store._apply_own_update

    def failing(text: str) -> None:
        sent.append(text)
        if text.startswith("DELETE {"):
            raise StoreError(oxigraph_server.url, "publication failed (test)")
        send(text)

    changed = _contents(kb)
    kb.store._apply_own_update = failing  # type: ignore[method-assign]
    with pytest.raises(StoreError, match="publication failed"):
        kb.restore(backup)
    del kb.store._apply_own_update
    assert _contents(kb) == changed and not [g for g in kb.store.graphs() if g.startswith(STAGING)]
    assert len(sent) > 3  # batches, the publication, the drop of the staging graphs
    kb.restore(backup)
    assert _contents(kb) == before
    kb.close()


def test_a_virtuoso_store_round_trips_leaving_its_own_graphs(virtuoso_server: VirtuosoServer, tmp_path: Path) -> None:
    virtuoso_server.clear()
    kb = _remote_store(virtuoso_server.url)
    before = _contents(kb)
    backup = tmp_path / "remote.nq"
    kb.export(backup)
    kb.update(CHANGE)
    kb.restore(backup)
    assert _contents(kb) == before
    kb.close()
    assert virtuoso_server.own_graphs <= virtuoso_server.graphs()
    text = backup.read_text(encoding="utf-8")
    assert not any(f"<{graph}> ." in text for graph in virtuoso_server.own_graphs)


def test_a_load_into_virtuoso_keeps_a_decimal_without_a_point_a_decimal(
    virtuoso_server: VirtuosoServer, tmp_path: Path
) -> None:
    """Virtuoso keeps "0"^^xsd:decimal as an integer: a restore wrote "0.0", a load did not (the query after
    it answered xsd:integer where the embedded store answers xsd:decimal)."""
    virtuoso_server.clear()
    data = tmp_path / "values.ttl"
    data.write_text(
        '<http://example.org/lab#a> <http://example.org/lab#zero> "0"^^<http://www.w3.org/2001/XMLSchema#decimal> ;\n'
        '  <http://example.org/lab#five> "-5"^^<http://www.w3.org/2001/XMLSchema#decimal> .\n',
        encoding="utf-8",
    )
    kb = KnowledgeBase(Store.open(virtuoso_server.url))
    try:
        kb.load([data], graph="urn:example:values")
        rows = kb.query("SELECT ?v WHERE { GRAPH <urn:example:values> { ?s ?p ?v } }")
        assert isinstance(rows, ox.QuerySolutions)
        types = {row["v"].datatype.value for row in rows}  # type: ignore[union-attr]
        assert types == {"http://www.w3.org/2001/XMLSchema#decimal"}
        again = kb.load([data], graph="urn:example:values")
        assert again.added_quads == 0  # found as held: the existence check asks as it was written
    finally:
        kb.close()


def test_a_store_behind_cbrs_serve_is_exported_and_restored_with_its_token(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Through a running cbrs server's /sparql and /update (its token from CBRS_UPDATE_TOKEN), as a lab whose
    store a server holds (and locks) must do; without the token an update is refused, saying how."""
    endpoint = EndpointConfig(update_token=TOKEN, isolate=False)
    running = Server(KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0, endpoint=endpoint))
    running.start()
    try:
        location = f"http://127.0.0.1:{running.http_port}"
        monkeypatch.setenv("CBRS_UPDATE_TOKEN", TOKEN)
        runner = CliRunner()
        backup = tmp_path / "served.nq"
        exported = runner.invoke(cli, ["--store", location, "export", str(backup), "--graph", "requirements"])
        assert exported.exit_code == 0, exported.output  # one graph: each staged batch costs the server a check
        before = running.kb.store.dump()
        running.kb.update(CHANGE.replace("services", "requirements"))
        restored = runner.invoke(cli, ["--store", location, "restore", str(backup), "--graph", "requirements"])
        assert restored.exit_code == 0, restored.output
        assert running.kb.store.dump() == before
        monkeypatch.delenv("CBRS_UPDATE_TOKEN")
        refused = runner.invoke(cli, ["--store", location, "update", CHANGE])
        assert refused.exit_code == 1 and "CBRS_UPDATE_TOKEN" in refused.stderr
    finally:
        running.stop()


def test_a_restore_into_a_new_directory_does_not_seed_it_first(
    exported: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    seeded: list[str] = []
    monkeypatch.setattr(KnowledgeBase, "_seed_kept", lambda kb, cache: seeded.append(kb.store.location))
    refused = CliRunner().invoke(cli, ["--store", str(tmp_path / "bad"), "restore", str(DATA / "mini_map.ttl")])
    assert refused.exit_code == 1 and not (tmp_path / "bad").exists()  # refused before a store was made
    plain = tmp_path / "plain.nq"
    plain.write_text("<http://example.org/a> <http://example.org/b> <http://example.org/c> <http://example.org/g> .\n")
    refused = CliRunner().invoke(cli, ["--store", str(tmp_path / "bad"), "restore", str(plain)])
    assert refused.exit_code == 1 and not (tmp_path / "bad").exists()
    assert "it lacks cbrs's own graphs graph:ontology" in refused.stderr and "cbrs load FILE adds" in refused.stderr
    monkeypatch.setattr(cli_notes, "_at_terminal", lambda: True)  # no "a new store, seeded" note for a person
    result = CliRunner().invoke(cli, ["--store", str(tmp_path / "new"), "restore", str(exported), "--yes"])
    assert result.exit_code == 0, result.output
    assert seeded == [] and "graph:services" in result.stdout and "(was absent)" in result.stdout
    assert "there was no store" not in result.stderr
    store = Store.open(tmp_path / "new")
    assert store.count() == sum(read_backup(exported).triples.values())
    store.close()


def test_a_restore_says_what_is_wrong_in_words_a_person_reads(
    seeded: KnowledgeBase, exported: Path, tmp_path: Path
) -> None:
    with pytest.raises(UnknownExportFormatError, match=r"a \.ttl file is no cbrs export: cbrs load adds it"):
        read_backup(DATA / "mini_map.ttl")
    cut = tmp_path / "cut.nq"
    cut.write_bytes(exported.read_bytes()[:-40])  # the last line cut in the middle
    with pytest.raises(RdfParseError) as broken:
        read_backup(cut)
    assert str(broken.value).count("line") == 1 and str(broken.value).endswith("nothing was restored")
    before = seeded.store.dump()
    lines = exported.read_bytes().splitlines(keepends=True)
    no_entailed = tmp_path / "no-entailed.nq"
    no_entailed.write_bytes(b"".join(line for line in lines if b"/graph/entailed> ." not in line))
    report = seeded.restore(no_entailed, force=True)  # its manifest still lists graph:entailed
    assert report.entailed_refreshed and report.restored[GraphName.ENTAILED.iri] == seeded.store.count(
        GraphName.ENTAILED
    )
    assert report.restored[GraphName.ENTAILED.iri] > 0
    seeded.restore(exported)
    assert seeded.store.dump() == before


def test_gzip_is_told_by_content_and_a_graph_restore_counts_entailed_before_and_after(
    seeded: KnowledgeBase, exported: Path, tmp_path: Path
) -> None:
    plain = tmp_path / "piped.nq.gz"  # what `cbrs export - > piped.nq.gz` leaves: N-Quads, not gzip
    plain.write_bytes(exported.read_bytes())
    packed = tmp_path / "packed.nq"
    seeded.export(tmp_path / "packed.nq.gz")
    packed.write_bytes((tmp_path / "packed.nq.gz").read_bytes())
    assert read_backup(plain).triples == read_backup(packed).triples == read_backup(exported).triples
    before = seeded.store.dump()
    entailed = seeded.store.count(GraphName.ENTAILED)
    report = seeded.restore(exported, graphs=["map"])
    assert report.entailed_refreshed and report.before[GraphName.ENTAILED.iri] == entailed
    assert report.restored[GraphName.ENTAILED.iri] == entailed and seeded.store.dump() == before


def test_export_and_restore_say_what_they_did_as_json(exported: Path, tmp_path: Path) -> None:
    runner = CliRunner()
    out = runner.invoke(cli, ["--store", ":memory:", "export", "--json", str(tmp_path / "lab.trig")])
    assert out.exit_code == 0, out.output
    said = json.loads(out.stdout)
    assert said["format"] == "trig" and said["total"] == sum(g["triples"] for g in said["graphs"])
    back = runner.invoke(cli, ["--store", ":memory:", "restore", "--json", str(exported), "--graph", "map"])
    assert back.exit_code == 0, back.output
    restored = json.loads(back.stdout)
    rows = {row["graph"].rsplit("/", 1)[1]: (row["triples"], row["before"]) for row in restored["graphs"]}
    assert restored["entailed_refreshed"] and rows["map"] == (rows["map"][1], rows["map"][1])
    assert restored["restored"] == rows["map"][0] and {g["graph"] for g in restored["left"]} >= {GraphName.SERVICES.iri}


def _cutting_server(data: ox.Store, most: int) -> httpx.MockTransport:
    """A SPARQL endpoint that, as Virtuoso does with ResultSetMaxRows, sends at most ``most`` rows of an
    answer and says so only in its X-SPARQL-MaxRows header."""

    def answer(request: httpx.Request) -> httpx.Response:
        text = parse_qs(request.content.decode("utf-8"))["query"][0]
        result = data.query(text)
        assert isinstance(result, ox.QuerySolutions)
        said = json.loads(result.serialize(format=ox.QueryResultsFormat.JSON) or b"{}")
        headers = {"Server": "Virtuoso/07.20.3229 (Linux)", "Content-Type": "application/sparql-results+json"}
        if len(said["results"]["bindings"]) > most:
            said["results"]["bindings"] = said["results"]["bindings"][:most]
            headers["X-SPARQL-MaxRows"] = str(most)
        return httpx.Response(200, headers=headers, content=json.dumps(said).encode("utf-8"))

    return httpx.MockTransport(answer)


def test_an_export_from_a_server_that_cuts_answers_short_holds_every_triple(tmp_path: Path) -> None:
    data = ox.Store()
    graph = ox.NamedNode("urn:example:lab")
    data.extend(
        ox.Quad(ox.NamedNode(f"urn:example:s{i}"), ox.NamedNode("urn:example:p"), ox.Literal(i), graph)
        for i in range(25)
    )
    store = RemoteStore(
        "http://virtuoso.test/sparql", Endpoints("http://virtuoso.test/sparql", "http://virtuoso.test/sparql")
    )
    store._client = httpx.Client(transport=_cutting_server(data, 10))
    try:
        report = export_store(store, tmp_path / "lab.nq")
    finally:
        store.close()
    assert report.triples == {graph.value: 25}
    assert sorted(read_backup(tmp_path / "lab.nq").quads[graph.value], key=str) == sorted(data, key=str)


def test_an_export_that_a_server_sent_short_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    data = ox.Store()
    graph = ox.NamedNode("urn:example:lab")
    data.extend(
        ox.Quad(ox.NamedNode(f"urn:example:s{i}"), ox.NamedNode("urn:example:p"), ox.Literal(i), graph)
        for i in range(5)
    )
    store = RemoteStore("http://other.test/sparql", Endpoints("http://other.test/sparql", "http://other.test/sparql"))
    store._client = httpx.Client(transport=_cutting_server(data, 100))
    monkeypatch.setattr(store, "count", lambda graph=None: 6)  # one triple more than it sends: a silent cut
    try:
        with pytest.raises(BackupError, match=r"sent 5 of the 6 triples of urn:example:lab .* nothing was exported"):
            export_store(store, tmp_path / "lab.nq")
    finally:
        store.close()
    assert list(tmp_path.iterdir()) == []


def test_an_export_to_a_reader_that_stops_says_so(seeded: KnowledgeBase, monkeypatch: pytest.MonkeyPatch) -> None:
    class Stopped(io.RawIOBase):  # `cbrs export - | head`: the pipe closes after a few lines
        def writable(self) -> bool:
            return True

        def write(self, data: Any) -> int:
            raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(sys, "stdout", io.TextIOWrapper(io.BufferedWriter(Stopped())))
    with pytest.raises(BackupError, match=r"standard output was closed before the export ended .* no whole export"):
        seeded.export("-")


def test_a_file_of_another_cbrs_version_is_restored_and_said_so(exported: Path, tmp_path: Path) -> None:
    older = tmp_path / "older.nq"
    text = exported.read_text(encoding="utf-8")
    version = f'<https://w3id.org/cbrs/export#cbrsVersion> "{__version__}"'
    assert version in text
    older.write_text(text.replace(version, '<https://w3id.org/cbrs/export#cbrsVersion> "0.0.9"'), encoding="utf-8")
    result = CliRunner().invoke(cli, ["--store", ":memory:", "restore", str(older)])
    assert result.exit_code == 0, result.output
    assert f"exported by cbrs 0.0.9, this is {__version__}: the next command" in result.stdout
    same = CliRunner().invoke(cli, ["--store", ":memory:", "restore", str(exported)])
    assert same.exit_code == 0 and "exported by cbrs" not in same.stdout


@pytest.mark.parametrize(
    ("stage", "said"),
    [
        pytest.param("reading", "Ctrl-C while reading it; nothing was restored", id="reading"),
        pytest.param(
            "counting what the store holds", "Ctrl-C before the write began; nothing was restored", id="count"
        ),
        pytest.param("writing batch", "a request the server had already taken may still be carried out", id="write"),
    ],
)
def test_ctrl_c_during_a_restore_says_what_it_left(
    exported: Path, monkeypatch: pytest.MonkeyPatch, stage: str, said: str
) -> None:
    def interrupted(*args: Any, **kwargs: Any) -> Any:
        if stage == "reading":
            raise KeyboardInterrupt
        args[-1](stage, 0, 0)  # the progress callback, as kb.backup tells it
        raise KeyboardInterrupt

    if stage == "reading":
        monkeypatch.setattr(cli_store, "read_backup", interrupted)
    else:
        monkeypatch.setattr(KnowledgeBase, "restore", interrupted)
    result = CliRunner().invoke(cli, ["--store", ":memory:", "restore", str(exported)])
    assert result.exit_code == 1 and said in result.stderr and "Aborted!" not in result.output


def test_a_cut_answer_is_refused_to_a_query_and_paged_only_as_far_as_quads_are_read() -> None:
    data = ox.Store()
    graph = ox.NamedNode("urn:example:lab")
    data.extend(
        ox.Quad(ox.NamedNode(f"urn:example:s{i}"), ox.NamedNode("urn:example:p"), ox.Literal(i), graph)
        for i in range(25)
    )
    sent: list[httpx.Request] = []
    server = _cutting_server(data, 10)

    def counted(request: httpx.Request) -> httpx.Response:
        sent.append(request)
        return server.handle_request(request)

    url = "http://virtuoso.test/sparql"
    store = RemoteStore(url, Endpoints(url, url))
    store._client = httpx.Client(transport=httpx.MockTransport(counted))
    store._union_verified = True
    try:
        with pytest.raises(StoreError, match=r"sent only the first 10 rows of an answer .* ResultSetMaxRows"):
            store.query("SELECT ?s WHERE { GRAPH ?g { ?s ?p ?o } }")
        sent.clear()
        assert next(store.quads(graph=graph)).graph_name == graph and len(sent) == 1  # no page read
        assert len(list(store.quads(graph=graph))) == 25
    finally:
        store.close()
