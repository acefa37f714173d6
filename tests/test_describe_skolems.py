"""DESCRIBE follows the blank nodes cbrs skolemised on load (kb.described): a class's OWL restrictions
(``rdfs:subClassOf [ a owl:Restriction ; owl:onProperty act:subAction ; ... ]``) came back as bare
``genid:`` IRIs from the endpoint and from ``cbrs query``; now with what they say, within bounds."""

from __future__ import annotations

import itertools

import pyoxigraph as ox
import pytest

from cbrs.cli import _evaluate
from cbrs.kb import KnowledgeBase
from cbrs.kb.described import complete
from cbrs.kb.namespaces import GENID, PREFIXES
from cbrs.sparql_service import EndpointConfig, SparqlService

OWL = "http://www.w3.org/2002/07/owl#"
RDF_TYPE = ox.NamedNode("http://www.w3.org/1999/02/22-rdf-syntax-ns#type")
FETCH = ox.NamedNode(PREFIXES["act"] + "FetchMyPen")
SUB_ACTION = ox.NamedNode(PREFIXES["act"] + "subAction")
DESCRIBE = "DESCRIBE act:FetchMyPen"


def _restrictions(triples: list[ox.Triple]) -> set[str]:
    """The classes FetchMyPen's described restrictions say its sub-actions are (someValuesFrom)."""
    on_sub_action = {t.subject for t in triples if t.predicate.value == OWL + "onProperty" and t.object == SUB_ACTION}
    return {
        t.object.value.rsplit("#", 1)[-1]
        for t in triples
        if t.subject in on_sub_action and t.predicate.value == OWL + "someValuesFrom"
    }


WANTED = {"NavigatingToPlace", "HandingOverOntoPlatform", "NavigatingToPerson", "Delivering"}


def test_cbrs_query_describes_a_class_with_its_restrictions(bundled_kb: KnowledgeBase) -> None:
    result = _evaluate(bundled_kb, DESCRIBE)
    assert isinstance(result, list)
    assert _restrictions(result) == WANTED
    assert any(t.subject.value.startswith(GENID) and t.predicate == RDF_TYPE for t in result)


@pytest.mark.parametrize("isolate", [False, True], ids=["in-process", "worker"])
def test_the_endpoint_describes_a_class_with_its_restrictions(bundled_kb: KnowledgeBase, isolate: bool) -> None:
    service = SparqlService(bundled_kb, config=EndpointConfig(isolate=isolate, isolate_memory=isolate))
    try:
        for accept, form in (("text/turtle", ox.RdfFormat.TURTLE), ("application/ld+json", ox.RdfFormat.JSON_LD)):
            answer = service.query(DESCRIBE, accept=accept)
            assert answer.media_type == accept
            triples = [quad.triple for quad in ox.parse(answer.body, format=form)]
            assert _restrictions(triples) == WANTED
        # a CONSTRUCT is answered as written: only a DESCRIBE is completed
        construct = service.query("CONSTRUCT WHERE { act:FetchMyPen rdfs:subClassOf ?c }", accept="text/turtle")
        assert b"owl:Restriction" not in construct.body and b"someValuesFrom" not in construct.body
    finally:
        service.close()


def _chain(length: int) -> tuple[list[ox.Triple], dict[ox.NamedNode, list[ox.Triple]]]:
    """``<r> :p genid:0``, then ``genid:i :p genid:i+1`` up to ``length`` links, and a named end."""
    p = ox.NamedNode("http://example.org/p")
    nodes = [ox.NamedNode(f"{GENID}chain-{i}") for i in range(length)]
    about = {node: [ox.Triple(node, p, nxt)] for node, nxt in itertools.pairwise(nodes)}
    about[nodes[-1]] = [ox.Triple(nodes[-1], p, ox.NamedNode("http://example.org/end"))]
    return [ox.Triple(ox.NamedNode("http://example.org/r"), p, nodes[0])], about


def test_the_walk_is_bounded_in_depth_and_size_and_ends_at_named_resources() -> None:
    answer, about = _chain(5)
    looked: list[ox.NamedNode] = []

    def lookup(node: ox.NamedNode) -> list[ox.Triple]:
        looked.append(node)
        return about.get(node, [])

    whole = complete(answer, lookup)
    assert len(whole) == 6 and whole[0] == answer[0]  # the engine's triples first, then each node's
    assert all(node.value.startswith(GENID) for node in looked) and len(looked) == 5  # never the named end
    assert len(complete(answer, lookup, depth=2)) == 3  # two links followed, the third node left bare
    assert len(complete(answer, lookup, most=4)) == 5
    cycle = ox.NamedNode(f"{GENID}loop")
    looped = [ox.Triple(cycle, ox.NamedNode("http://example.org/p"), cycle)]
    assert (
        complete([ox.Triple(ox.NamedNode("http://example.org/r"), looped[0].predicate, cycle)], lambda _: looped)[1:]
        == looped
    )
