from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.kb import GraphName, KnowledgeBase, RdfParseError, Store, UnknownFormatError, UnknownGraphError
from cbrs.kb.loader import parse_file, skolemise
from cbrs.kb.namespaces import GENID

pytestmark = pytest.mark.both_stores

BAD = Path(__file__).parent / "data" / "bad"

SAMPLE = """@prefix ex: <http://example.org/s#> .
ex:café ex:label "naïve façade" ; ex:part [ ex:x 1 ; ex:y 2 ] .
"""


def _sample_quads() -> list[ox.Quad]:
    return list(ox.parse(input=SAMPLE, format=ox.RdfFormat.TURTLE))


@pytest.mark.parametrize(
    ("suffix", "rdf_format"),
    [
        pytest.param(".ttl", ox.RdfFormat.TURTLE, id="turtle"),
        pytest.param(".nt", ox.RdfFormat.N_TRIPLES, id="ntriples"),
        pytest.param(".rdf", ox.RdfFormat.RDF_XML, id="rdfxml"),
        pytest.param(".owl", ox.RdfFormat.RDF_XML, id="owl-rdfxml"),
        pytest.param(".jsonld", ox.RdfFormat.JSON_LD, id="jsonld"),
    ],
)
def test_each_format_loads_the_same_graph(tmp_path: Path, suffix: str, rdf_format: ox.RdfFormat) -> None:
    path = tmp_path / f"sample{suffix}"
    path.write_bytes(ox.serialize(_sample_quads(), format=rdf_format) or b"")
    parsed = parse_file(path, "services")
    assert len(parsed.quads) == 4
    labels = [q.object.value for q in parsed.quads if q.predicate.value.endswith("label")]
    assert labels == ["naïve façade"]


def test_owl_file_with_turtle_content_is_read_as_turtle(tmp_path: Path) -> None:
    path = tmp_path / "onto.owl"
    path.write_text(SAMPLE, encoding="utf-8")
    assert len(parse_file(path).quads) == 4


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be", "iso-8859-1", "utf-8-sig"])
def test_rdfxml_in_other_encodings_loads(tmp_path: Path, encoding: str) -> None:
    xml = (ox.serialize(_sample_quads(), format=ox.RdfFormat.RDF_XML) or b"").decode("utf-8")
    body = xml.split("?>", 1)[1] if xml.startswith("<?xml") else xml
    declared = "UTF-16" if encoding.startswith("utf-16") else encoding.upper().replace("-SIG", "")
    text = f'<?xml version="1.0" encoding="{declared}"?>' + body
    path = tmp_path / "sample.rdf"
    data = text.encode(encoding)
    if encoding == "utf-16-be":
        data = b"\xfe\xff" + data
    path.write_bytes(data)
    labels = [q.object.value for q in parse_file(path).quads if q.predicate.value.endswith("label")]
    assert labels == ["naïve façade"]


def test_broken_turtle_names_file_and_line() -> None:
    with pytest.raises(RdfParseError) as caught:
        parse_file(BAD / "broken.ttl")
    assert caught.value.line == 4
    assert str(caught.value).startswith(f"{BAD / 'broken.ttl'}:4")


def test_malformed_rdfxml_names_the_line() -> None:
    with pytest.raises(RdfParseError) as caught:
        parse_file(BAD / "broken.rdf")
    assert caught.value.line == 5
    assert "broken.rdf:5" in str(caught.value)


def test_unknown_format_is_named() -> None:
    with pytest.raises(UnknownFormatError, match=r"unknown\.format"):
        parse_file(BAD / "unknown.format")


def test_missing_file_is_a_parse_error_naming_it(tmp_path: Path) -> None:
    with pytest.raises(RdfParseError, match=r"nothere\.ttl"):
        parse_file(tmp_path / "nothere.ttl")


def test_a_failing_file_loads_nothing(mini_kb: KnowledgeBase, tmp_path: Path) -> None:
    good = tmp_path / "good.ttl"
    good.write_text(SAMPLE, encoding="utf-8")
    before = mini_kb.store.dump()
    with pytest.raises(RdfParseError):
        mini_kb.load([good, BAD / "broken.ttl"])
    assert mini_kb.store.dump() == before


def test_loading_a_file_twice_adds_nothing(mini_kb: KnowledgeBase, tmp_path: Path) -> None:
    path = tmp_path / "sample.ttl"
    path.write_text(SAMPLE, encoding="utf-8")
    mini_kb.load([path])
    once = mini_kb.store.dump()
    mini_kb.load([path])
    assert mini_kb.store.dump() == once


def test_blank_nodes_become_stable_genid_iris() -> None:
    first = skolemise(_sample_quads())
    second = skolemise(_sample_quads())
    assert first == second
    terms = [t for q in first for t in (q.subject, q.object)]
    assert not any(isinstance(t, ox.BlankNode) for t in terms)
    assert any(isinstance(t, ox.NamedNode) and t.value.startswith(GENID) for t in terms)


def test_graph_is_chosen_from_content(tmp_path: Path) -> None:
    ontology = tmp_path / "o.ttl"
    ontology.write_text("<http://e/C> a <http://www.w3.org/2002/07/owl#Class> .", encoding="utf-8")
    plain = tmp_path / "p.ttl"
    plain.write_text("<http://e/a> <http://e/b> <http://e/c> .", encoding="utf-8")
    assert parse_file(ontology).graph == GraphName.ONTOLOGY.iri
    assert parse_file(plain).graph == GraphName.SERVICES.iri
    assert parse_file(plain, "world").graph == GraphName.WORLD.iri
    assert parse_file(plain, "http://example.org/g").graph == "http://example.org/g"


def test_unknown_graph_name_is_refused(tmp_path: Path) -> None:
    plain = tmp_path / "p.ttl"
    plain.write_text("<http://e/a> <http://e/b> <http://e/c> .", encoding="utf-8")
    with pytest.raises(UnknownGraphError, match="servces"):
        parse_file(plain, "servces")


def test_on_disk_store_keeps_what_was_loaded(tmp_path: Path) -> None:
    location = tmp_path / "store"
    kb = KnowledgeBase.open(location)
    count = kb.store.count()
    assert count > 0
    kb.close()
    del kb
    reopened = Store.open(location)
    assert reopened.count() == count
    assert reopened.is_seeded()


def test_a_directory_with_no_rdf_file_is_an_error_not_a_silent_success(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("not RDF", encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    before = kb.store.dump()
    with pytest.raises(RdfParseError, match="a directory with no RDF file in it"):
        kb.load([tmp_path])
    assert kb.store.dump() == before


def test_a_store_emptied_by_an_update_is_seeded_again_on_open(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(tmp_path / "store")
    kb.update("DELETE { GRAPH ?g { ?s ?p ?o } } WHERE { GRAPH ?g { ?s ?p ?o } }")
    assert kb.store.count() == 0 and not kb.store.is_seeded()
    kb.store.close()
    again = KnowledgeBase.open(tmp_path / "store")
    assert again.store.is_seeded() and again.store.count() > 1000


# -- the bulk path for large plain files (kb.loader.BULK_BYTES) -----------------------------------------

BULK_DATA = "".join(
    f"<http://example.org/bulk#e{i}> <http://example.org/bulk#next> <http://example.org/bulk#e{i + 1}> .\n"
    for i in range(200)
)
BULK_GRAPH = "http://example.org/bulk-graph"


@pytest.fixture
def bulk_sized(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every file counts as large, so that small test files take the bulk path."""
    monkeypatch.setattr("cbrs.kb.loader.BULK_BYTES", 1)


@pytest.fixture
def disk_kb(tmp_path: Path) -> KnowledgeBase:
    return KnowledgeBase.open(tmp_path / "store")


def _spy_bulk(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    from cbrs.kb.store import EmbeddedStore

    calls: list[str] = []
    original = EmbeddedStore.bulk_load

    def spy(self: EmbeddedStore, path: Path, *args: object) -> None:
        calls.append(str(path))
        original(self, path, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(EmbeddedStore, "bulk_load", spy)
    return calls


@pytest.mark.usefixtures("bulk_sized")
def test_a_large_plain_file_is_bulk_loaded_into_its_graph(
    tmp_path: Path, disk_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = _spy_bulk(monkeypatch)
    path = tmp_path / "big.nt"
    path.write_text(BULK_DATA, encoding="utf-8")
    report = disk_kb.load([path], BULK_GRAPH)
    assert calls == [str(path)]
    assert [(item.graph, item.triples) for item in report] == [(BULK_GRAPH, 200)]
    assert report.quads == 200
    assert disk_kb.store.count(ox.NamedNode(BULK_GRAPH)) == 200


@pytest.mark.usefixtures("bulk_sized")
def test_a_large_file_that_fails_to_parse_loads_nothing_and_names_the_line(
    tmp_path: Path, disk_kb: KnowledgeBase
) -> None:
    before = disk_kb.store.dump()
    path = tmp_path / "big.nt"
    path.write_text(BULK_DATA + "<http://example.org/bulk#broken> <oops .\n", encoding="utf-8")
    with pytest.raises(RdfParseError) as raised:
        disk_kb.load([path], BULK_GRAPH)
    assert raised.value.line == 201
    assert disk_kb.store.dump() == before


@pytest.mark.usefixtures("bulk_sized")
def test_a_large_file_with_blank_nodes_takes_the_full_path(
    tmp_path: Path, disk_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = _spy_bulk(monkeypatch)
    path = tmp_path / "big.ttl"
    path.write_text(SAMPLE, encoding="utf-8")
    disk_kb.load([path], BULK_GRAPH)
    assert calls == []
    subjects = {q.subject.value for q in disk_kb.store.quads(graph=ox.NamedNode(BULK_GRAPH))}
    assert any(s.startswith(GENID) for s in subjects)  # skolemised, as always


@pytest.mark.usefixtures("bulk_sized")
def test_a_large_file_into_a_graph_in_use_takes_the_full_path(
    tmp_path: Path, disk_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = _spy_bulk(monkeypatch)
    first, second = tmp_path / "a.nt", tmp_path / "b.nt"
    first.write_text(BULK_DATA[: BULK_DATA.index("\n") + 1], encoding="utf-8")
    second.write_text(BULK_DATA, encoding="utf-8")
    disk_kb.load([first], BULK_GRAPH)  # one file, bulk (the graph was empty)
    disk_kb.load([second], BULK_GRAPH)  # the graph holds a triple now: one transaction instead
    assert calls == [str(first)]
    assert disk_kb.store.count(ox.NamedNode(BULK_GRAPH)) == 200


@pytest.mark.usefixtures("bulk_sized")
def test_a_bulk_write_that_fails_leaves_the_store_as_it_was(
    tmp_path: Path, disk_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    from cbrs.kb.errors import StoreError

    before = disk_kb.store.dump()
    backend = disk_kb.store._backend  # type: ignore[attr-defined]

    class HalfWritten:
        """Oxigraph's bulk loader that writes part of the file and then meets a full disk."""

        def __getattr__(self, name: str) -> object:
            return getattr(backend, name)

        def bulk_load(self, path: str, format: ox.RdfFormat, base_iri: str, to_graph: ox.NamedNode) -> None:
            quads = list(ox.parse(path=path, format=format, base_iri=base_iri))[:50]
            backend.bulk_extend(ox.Quad(q.subject, q.predicate, q.object, to_graph) for q in quads)
            raise OSError("No space left on device")

    monkeypatch.setattr(disk_kb.store, "_open", HalfWritten())
    path = tmp_path / "big.nt"
    path.write_text(BULK_DATA, encoding="utf-8")
    with pytest.raises(StoreError, match=r"No space left on device.*undone"):
        disk_kb.load([path], BULK_GRAPH)
    assert disk_kb.store.dump() == before


_KILLED_LOADER = """
import sys
import cbrs.kb.loader as loader
from cbrs.kb import KnowledgeBase
from cbrs.kb.store import EmbeddedStore
loader.BULK_BYTES = 1
original = EmbeddedStore.bulk_load
def announced(self, *args):
    print("bulk", flush=True)
    original(self, *args)
EmbeddedStore.bulk_load = announced
KnowledgeBase.open(sys.argv[1]).load([sys.argv[2]], sys.argv[3])
print("loaded", flush=True)
"""


@pytest.mark.parametrize("delay", [0.0, 0.5], ids=["at-start", "later"])
def test_a_bulk_load_killed_mid_way_leaves_none_of_it(tmp_path: Path, delay: float) -> None:
    path = tmp_path / "big.nt"
    lines = [
        f"<http://example.org/bulk#n{i}> <http://example.org/bulk#v> <http://example.org/bulk#n{i + 1}> .\n"
        for i in range(150_000)
    ]
    path.write_text("".join(lines), encoding="utf-8")
    store = tmp_path / "store"
    KnowledgeBase.open(store).close()  # seeded first
    child = subprocess.Popen(
        [sys.executable, "-c", _KILLED_LOADER, str(store), str(path), BULK_GRAPH],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert child.stdout is not None
        assert child.stdout.readline().strip() == "bulk"
        time.sleep(delay)
        child.send_signal(signal.SIGKILL)
    finally:
        child.wait(30)
    kb = KnowledgeBase.open(store)
    try:
        assert kb.store.count(ox.NamedNode(BULK_GRAPH)) in (0, 150_000)
        assert "bulk-loading" not in " ".join(kb.store.graphs())
        assert kb.select("advertisements")  # the rest of the store is as it was
    finally:
        kb.close()


def test_a_store_left_mid_bulk_load_drops_the_graph_when_opened(tmp_path: Path) -> None:
    from cbrs.kb.store import _BULK_LOAD_OF, BULK_LOADING, EmbeddedStore

    store = EmbeddedStore.open(tmp_path / "store")
    graph = ox.NamedNode(BULK_GRAPH)
    backend = store._backend
    backend.add(ox.Quad(graph, _BULK_LOAD_OF, ox.Literal("big.nt"), BULK_LOADING))  # as bulk_load starts
    part = list(ox.parse(input=BULK_DATA, format=ox.RdfFormat.N_TRIPLES))[:50]
    backend.bulk_extend(ox.Quad(q.subject, q.predicate, q.object, graph) for q in part)  # then dies
    backend.add(ox.Quad(ox.NamedNode("urn:other"), ox.NamedNode("urn:p"), ox.Literal("kept")))
    store.close()
    del backend  # Oxigraph releases the store's lock with its last reference
    reopened = EmbeddedStore.open(tmp_path / "store")
    try:
        assert reopened.count(graph) == 0
        assert reopened.graphs() == []
        assert reopened.count() == 1  # what else the store held is kept
    finally:
        reopened.close()
