"""Preconditions and effects as condition nodes (cbrs:conditionSubject/Predicate/Object), the upgrade of a
store seeded in the reified form of core 0.1.0, and the refusal of that form in new input."""

from __future__ import annotations

import hashlib
import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.kb import GraphName, KnowledgeBase, Store
from cbrs.kb.errors import InvalidDescriptionError
from cbrs.kb.loader import parse_file
from cbrs.kb.namespaces import GENID, RDF
from cbrs.kb.resources import bundled_files
from cbrs.kb.vocab import CBRS

pytestmark = pytest.mark.both_stores

DATA = Path(__file__).parent / "data"
OLD_CORE = DATA / "legacy" / "core-0.1.0.ttl"  # ontologies/core.ttl as core 0.1.0 had it
LAB = ox.NamedNode("urn:example:lab")  # a graph of the user's own


# the files whose version core 0.2.0 raised, with the rest of the bundle as it was
RAISED = {"actions.ttl", "services.ttl", "requirements.ttl"}


def _as_before(text: str, version: bool) -> str:
    """A bundled file as it was with core 0.1.0: reified conditions, and (``version``) version 0.1.0."""
    pairs = [("cbrs:conditionSubject", "rdf:subject"), ("cbrs:conditionPredicate", "rdf:predicate")]
    pairs += [("cbrs:conditionObject", "rdf:object")]
    for new, old in pairs:
        text = text.replace(new, old)
    return re.sub(r'owl:versionInfo "[^"]*"', 'owl:versionInfo "0.1.0"', text) if version else text


def _seed_as_core_0_1_0(store: Store, folder: Path, older_map: bool = False) -> None:
    """What a store seeded by cbrs with core 0.1.0 holds (with ``older_map``, also a semantic map of an older
    version), plus a reified condition in a graph of the user's."""
    quads = []
    for item in bundled_files():
        path = OLD_CORE if item.path.name == "core.ttl" else folder / item.path.name
        if path != OLD_CORE:
            older = item.path.name in RAISED or (older_map and item.graph is GraphName.MAP)
            path.write_text(_as_before(item.path.read_text(encoding="utf-8"), older), encoding="utf-8")
        quads += parse_file(path, item.graph).quads
    node, model = ox.NamedNode(GENID + "lab-condition"), ox.NamedNode(GENID + "lab-model")
    ex = "http://example.org/lab#"
    quads += [
        ox.Quad(model, ox.NamedNode(CBRS.hasEffect), node, LAB),
        ox.Quad(node, ox.NamedNode(RDF + "type"), ox.NamedNode(CBRS.Effect), LAB),
        ox.Quad(node, ox.NamedNode(RDF + "type"), ox.NamedNode(RDF + "Statement"), LAB),
        ox.Quad(node, ox.NamedNode(RDF + "subject"), ox.NamedNode(ex + "Lamp"), LAB),
        ox.Quad(node, ox.NamedNode(RDF + "predicate"), ox.NamedNode(ex + "hasStatus"), LAB),
        ox.Quad(node, ox.NamedNode(RDF + "object"), ox.NamedNode(ex + "On"), LAB),
        # a reified statement that is no condition stays as it is
        ox.Quad(ox.NamedNode(ex + "rumour"), ox.NamedNode(RDF + "subject"), ox.NamedNode(ex + "Lamp"), LAB),
    ]
    store.add(quads)


def _canonical(store: Store, graph: ox.NamedNode) -> set[str]:
    """The graph with its skolem IRIs as blank nodes, canonicalised: equal whatever file digest named them."""

    def blank(term: ox.NamedNode | ox.BlankNode | ox.Literal | ox.Triple) -> ox.NamedNode | ox.BlankNode | ox.Literal:
        if isinstance(term, ox.NamedNode) and term.value.startswith(GENID):
            return ox.BlankNode(hashlib.sha256(term.value.encode()).hexdigest()[:24])
        assert not isinstance(term, ox.Triple)
        return term

    dataset = ox.Dataset(ox.Quad(blank(q.subject), q.predicate, blank(q.object)) for q in store.quads(graph=graph))
    dataset.canonicalize(ox.CanonicalizationAlgorithm.RDFC_1_0)
    return {str(quad) for quad in dataset}


def _conditions(kb: KnowledgeBase) -> dict[str, tuple[object, ...]]:
    found: dict[str, tuple[object, ...]] = {}
    for description in (*kb.advertisements(include_unavailable=True), *kb.requirements()):
        found[description.iri] = (description.preconditions, description.effects)
    return found


@dataclass
class Fresh:
    """A freshly seeded store, shared by the module's tests (they only read it), with each graph's
    canonical form worked out once."""

    kb: KnowledgeBase
    canonical: dict[ox.NamedNode, set[str]] = field(default_factory=dict)

    def of(self, graph: ox.NamedNode) -> set[str]:
        if graph not in self.canonical:
            self.canonical[graph] = _canonical(self.kb.store, graph)
        return self.canonical[graph]


@pytest.fixture(scope="module")
def fresh() -> Iterator[Fresh]:
    kb = KnowledgeBase.open(":memory:")
    yield Fresh(kb)
    kb.close()


@pytest.fixture
def location(store_location: str, tmp_path: Path) -> str:
    """A store that outlives one handle: a directory for the embedded store, the cleared server for the remote."""
    return str(tmp_path / "store") if store_location == ":memory:" else store_location


@pytest.mark.parametrize("older_map", [False, True], ids=["map-current", "map-older"])
def test_a_store_seeded_with_core_0_1_0_is_upgraded_on_open(
    location: str, tmp_path: Path, older_map: bool, fresh: Fresh
) -> None:
    old = Store.open(location)
    _seed_as_core_0_1_0(old, tmp_path, older_map)
    old.close()
    kb = KnowledgeBase.open(location)
    assert kb.select("legacy_conditions") == []
    # the bundled graphs now say what a fresh seed says: conditions, core vocabulary, headers (the map's
    # version too, when it was older), and no action model twice
    for graph in (GraphName.ONTOLOGY, GraphName.SERVICES, GraphName.REQUIREMENTS, GraphName.MAP):
        assert _canonical(kb.store, graph.node) == fresh.of(graph.node), graph
    assert _conditions(kb) == _conditions(fresh.kb)
    action = "https://w3id.org/cbrs/action#FillCupFromTapOfWaterDispenser"
    assert kb.action_requirement(action).preconditions == fresh.kb.action_requirement(action).preconditions
    # the user's graph: its condition rewritten, its other reified statement left alone
    lab = {(q.subject.value, q.predicate.value, q.object.value) for q in kb.store.quads(graph=LAB)}
    assert (GENID + "lab-condition", CBRS.conditionSubject, "http://example.org/lab#Lamp") in lab
    assert (GENID + "lab-condition", RDF + "type", RDF + "Statement") not in lab
    assert ("http://example.org/lab#rumour", RDF + "subject", "http://example.org/lab#Lamp") in lab
    assert not kb.upgrade().changed  # nothing left to do
    kb.close()


def test_a_current_store_is_left_as_it_is(location: str) -> None:
    KnowledgeBase.open(location).close()
    kb = KnowledgeBase.open(location)
    before = kb.store.dump()
    assert not kb.upgrade().changed
    assert kb.store.dump() == before
    kb.close()


def test_the_reified_form_is_refused_in_new_input_with_the_fix(store_location: str, tmp_path: Path) -> None:
    kb = KnowledgeBase.open(store_location)
    path = tmp_path / "old.ttl"
    path.write_text(
        "@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .\n"
        "@prefix rdf: <http://www.w3.org/1999/02/22-rdf-syntax-ns#> .\n"
        'home:OpenDoorAct a cbrs:PhysicalManipulationComponent ; cbrs:deviceName "arm" ; cbrs:serviceName "open" ;\n'
        "  cbrs:hasOWLSModel [ cbrs:hasEffect [ a cbrs:Effect ;\n"
        "    rdf:subject home:Door ; rdf:predicate home:hasStatus ; rdf:object home:Opened ] ] .\n",
        encoding="utf-8",
    )
    before = kb.store.dump()
    with pytest.raises(InvalidDescriptionError) as caught:
        kb.load([path], graph="services")
    assert "the reified form of core 0.1.0" in str(caught.value)
    assert "write cbrs:conditionSubject, cbrs:conditionPredicate and cbrs:conditionObject" in str(caught.value)
    assert kb.store.dump() == before


def test_a_misspelt_condition_predicate_gets_a_did_you_mean(store_location: str) -> None:
    kb = KnowledgeBase.open(store_location)
    turtle = (
        "@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .\n"
        'home:Opener a cbrs:PhysicalManipulationComponent ; cbrs:deviceName "arm" ; cbrs:serviceName "open" ;\n'
        "  cbrs:hasOWLSModel [ cbrs:hasEffect [ a cbrs:Effect ;\n"
        "    cbrs:conditionSubject home:Door ; cbrs:conditionPredicate home:hasStatsu ;"
        " cbrs:conditionObject home:Opened ] ] .\n"
    )
    with pytest.raises(InvalidDescriptionError) as caught:
        kb.registry.register(turtle)
    assert "the property home:hasStatsu is declared nowhere" in str(caught.value)
    assert "home:hasStatus" in str(caught.value)


def test_a_store_seeded_before_the_standard_vocabularies_gets_them_on_open(location: str, fresh: Fresh) -> None:
    """Files new in the bundle (the standard vocabularies, the alignments) join an older store whole, and
    the standard terms are entailed from them."""
    KnowledgeBase.open(location).close()
    old = Store.open(location)
    new_files = [i for i in bundled_files() if i.path.parent.name == "standards" or i.path.name == "alignments.ttl"]
    assert new_files, "the bundle names the standard vocabularies"
    old.replace([quad for item in new_files for quad in parse_file(item.path, item.graph).quads], [])
    old.clear_graph(GraphName.ENTAILED.node)
    old.close()
    kb = KnowledgeBase.open(location)
    assert _canonical(kb.store, GraphName.ONTOLOGY.node) == fresh.of(GraphName.ONTOLOGY.node)
    sensors = "SELECT ?s WHERE { GRAPH ?g { ?s a <http://www.w3.org/ns/sosa/Sensor> } }"
    assert sorted(str(r["s"]) for r in kb.store.query(sensors)) == sorted(
        str(r["s"]) for r in fresh.kb.store.query(sensors)
    )
    assert list(kb.store.query(sensors))
    assert not kb.upgrade().changed
    kb.close()
