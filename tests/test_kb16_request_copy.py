"""A service loads after its request copy. OWLS-TC's query files are copies of service files, the service's
IRI included; loaded into graph:requirements a copy becomes the requirement ``<IRI>-request``, and its
OWL-S triples keep the service's IRI there. A load of the service file then found that IRI typed in the
store and refused it as "described differently", though loading the two the other way round worked and
gives the same store. The merge check now looks at the graph the file goes to, and at cbrs descriptions
in other graphs; OWL-S triples of another graph describe another resource (docs/owls.md)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.kb import GraphName, KnowledgeBase, RdfParseError
from cbrs.kb.owls import requirement_iri
from tests.helpers_seeded import put_quads

from .test_deregister_owls import triples_by_graph
from .test_load_counts import NAVIGATE, ONTOLOGY

pytestmark = pytest.mark.both_stores

SERVICE = "http://example.org/services/navigate.owls#NavigateService"
OTHER_GRAPH = "http://example.org/lab/graph"


@pytest.fixture(scope="module")
def start() -> bytes:
    """The store each test starts from, as N-Quads: seeded (the core ontology tells what a description is),
    the OWL-S ontologies loaded."""
    kb = KnowledgeBase.open(":memory:")
    kb.load([ONTOLOGY])
    return kb.store.dump()


@pytest.fixture
def kb(store_location: str, start: bytes, request: pytest.FixtureRequest) -> Iterator[KnowledgeBase]:
    """On the server, the start is put in one request: seeding and loading through cbrs would take some
    3 s of queries each time (what a remote seed and load write is checked in test_remote_store.py)."""
    if store_location != ":memory:":
        put_quads(request.getfixturevalue("oxigraph_server"), start)  # cleared for the test already
    kb = KnowledgeBase.open(store_location)
    if store_location == ":memory:":
        kb.load([ONTOLOGY])
    assert kb.store.dump() == start
    yield kb
    kb.close()


def _copy(tmp_path: Path, folder: str, name: str = "Navigate to room") -> Path:
    """navigate.owls in ``folder`` (same file name, so the same device name), its service name ``name``:
    as OWLS-TC's queries/ copies services/, 19 of 22 byte for byte and 3 with another service name."""
    text = NAVIGATE.read_text(encoding="utf-8").replace("Navigate to room", name)
    path = tmp_path / folder / NAVIGATE.name
    path.parent.mkdir(exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("name", ["Navigate to room", "Go to a room"], ids=["identical", "renamed"])
def test_a_service_loads_after_its_request_copy_as_before_it(
    kb: KnowledgeBase, store_location: str, tmp_path: Path, name: str
) -> None:
    query, service = _copy(tmp_path, "queries", name), _copy(tmp_path, "services")
    request = kb.load([query], graph="requirements")
    assert [s.iri for item in request for s in item.owls.services] == [requirement_iri(SERVICE)]  # type: ignore[union-attr]
    loaded = kb.load([service])
    assert loaded.added.get(GraphName.SERVICES.iri, 0) > 0
    assert kb.description(SERVICE).iri == SERVICE
    assert kb.description(requirement_iri(SERVICE)).iri == requirement_iri(SERVICE)
    other = KnowledgeBase.open(":memory:")
    try:  # the other order, which loaded before: the same store
        other.load([ONTOLOGY])
        other.load([service])
        other.load([query], graph="requirements")
        assert triples_by_graph(kb) == triples_by_graph(other)
    finally:
        other.close()


def test_an_owl_individual_type_on_the_copy_does_not_stop_the_service(kb: KnowledgeBase, tmp_path: Path) -> None:
    """Ontology editors type every individual owl:NamedIndividual; on the request copy's service node that
    is OWL's own type, not a description of it."""
    query = _copy(tmp_path, "queries")
    text = query.read_text(encoding="utf-8").replace(
        '<service:Service rdf:ID="NavigateService">',
        '<service:Service rdf:ID="NavigateService">\n    '
        '<rdf:type rdf:resource="http://www.w3.org/2002/07/owl#NamedIndividual"/>',
    )
    assert "NamedIndividual" in text
    query.write_text(text, encoding="utf-8")
    kb.load([query], graph="requirements")
    kb.load([_copy(tmp_path, "services")])
    assert kb.description(SERVICE).iri == SERVICE


def test_the_same_graph_described_otherwise_is_refused_naming_the_graph(kb: KnowledgeBase, tmp_path: Path) -> None:
    kb.load([_copy(tmp_path, "services")])
    before = triples_by_graph(kb)
    with pytest.raises(RdfParseError) as refused:
        kb.load([_copy(tmp_path, "edited", "Go to a room")])
    message = refused.value.message
    assert f"<{SERVICE}> is already in the store, described differently in graph:services" in message
    assert "cbrs register --update FILE replaces it" in message
    assert triples_by_graph(kb) == before


def test_a_description_in_another_graph_is_refused_naming_that_graph(kb: KnowledgeBase, tmp_path: Path) -> None:
    """An advertisement by the service's IRI in graph:services and a second one in another graph would be
    read as one through the union graph: refused, whatever the file, saying where the first one is."""
    kb.load([_copy(tmp_path, "services")])
    before = triples_by_graph(kb)
    with pytest.raises(RdfParseError) as refused:
        kb.load([_copy(tmp_path, "services")], graph=OTHER_GRAPH)
    message = refused.value.message
    assert f"<{SERVICE}> is described in graph:services already" in message
    assert f"loading it into {OTHER_GRAPH} too" in message
    assert "cbrs deregister IRI first" in message
    assert triples_by_graph(kb) == before


ENTAILED = f"<{GraphName.ENTAILED.iri}>"


def _written(kb: KnowledgeBase, entailed: bool) -> dict[str, set[str]]:
    """The store's triples by graph; graph:entailed only with ``entailed``."""
    found = triples_by_graph(kb)
    if not entailed:
        found.pop(ENTAILED, None)
    return found


@pytest.mark.parametrize("entailed", [False, True], ids=["descriptions", "entailed"])
@pytest.mark.parametrize("removed", ["service", "request"])
def test_each_deregisters_without_touching_the_other(
    kb: KnowledgeBase, tmp_path: Path, removed: str, entailed: bool
) -> None:
    """The advertisement and the requirement share the OWL-S source's IRIs, each copy in its own graph:
    deregistering one, the request loaded first, leaves the store as loading the other alone left it,
    graph:entailed included (on a remote store it lost what the remaining copy still supports,
    ``<#Goal> a process:Parameter``..., kb/standard_terms.py's remote path)."""
    query, service = _copy(tmp_path, "queries", "Go to a room"), _copy(tmp_path, "services")
    base = _written(kb, entailed)
    if removed == "service":
        kb.load([query], graph="requirements")
        alone = _written(kb, entailed)
    else:
        kb.load([service])
        alone = _written(kb, entailed)
        kb.registry.deregister(SERVICE)
        assert _written(kb, entailed) == base
        kb.load([query], graph="requirements")
    kb.load([service])
    kb.registry.deregister(SERVICE if removed == "service" else requirement_iri(SERVICE))
    assert _written(kb, entailed) == alone
