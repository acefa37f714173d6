from __future__ import annotations

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
