from __future__ import annotations

import pytest

from cbrs.kb import Advertisement, InvalidDescriptionError, KnowledgeBase, NotFoundError, Requirement, Statement
from cbrs.kb.errors import PartCycleError
from cbrs.kb.namespaces import GraphName
from cbrs.kb.vocab import CBRS

EX = "http://example.org/mini#"

pytestmark = pytest.mark.both_stores


def test_advertisement_six_tuple(mini_kb: KnowledgeBase) -> None:
    ad = mini_kb.description(EX + "Locate")
    assert isinstance(ad, Advertisement)
    assert ad.kind == CBRS.DynamicPerceptionComponent
    assert (ad.device_name, ad.service_name, ad.category) == ("Camera1", "LocateRobot", "Localisation")
    assert ad.device == EX + "Camera1"
    assert [p.type for p in ad.inputs] == [EX + "MarkerColour"]
    assert [p.name for p in ad.outputs] == ["location"]
    assert ad.area is not None and ad.area.areas == (EX + "LivingRoom",)
    assert ad.area.bounds == (0.0, 6.0, 0.0, 5.0)
    assert {q.metric: (q.value, q.better_when) for q in ad.qos} == {
        CBRS.responseTime: (0.1, "lower"),
        CBRS.availability: (0.95, "higher"),
    }
    assert [(p.kind, p.topic) for p in ad.ports] == [("data", "/camera1/location")]


def test_effect_is_a_statement(mini_kb: KnowledgeBase) -> None:
    ad = mini_kb.description(EX + "OpenDoor")
    assert ad.effects == (Statement(EX + "Door", EX + "hasStatus", EX + "Opened"),)
    assert ad.preconditions == ()


def test_requirement_has_requester_and_part_tree(mini_kb: KnowledgeBase) -> None:
    req = mini_kb.description(EX + "SelfPosition")
    assert isinstance(req, Requirement)
    assert req.requested_by == EX + "Robot1"
    tree = req.outputs[0].tree
    assert tree is not None
    assert tree.concept == EX + "RobotPosition"
    assert [(c.via, c.concept) for c in tree.children] == [
        (EX + "hasX", EX + "XCoordinate"),
        (EX + "hasY", EX + "YCoordinate"),
    ]
    assert all(child.is_leaf for child in tree.children)
    assert len(tree.walk()) == 3


def test_lists_read_every_description(mini_kb: KnowledgeBase) -> None:
    assert [a.iri for a in mini_kb.advertisements()] == [EX + "Locate", EX + "OpenDoor"]
    assert [r.iri for r in mini_kb.requirements()] == [EX + "SelfPosition"]


def test_unknown_description_is_not_found(mini_kb: KnowledgeBase) -> None:
    with pytest.raises(NotFoundError, match="nothing"):
        mini_kb.description(EX + "nothing")


def test_has_part_cycle_is_reported(mini_kb: KnowledgeBase, tmp_path) -> None:  # type: ignore[no-untyped-def]
    cyclic = tmp_path / "cycle.ttl"
    cyclic.write_text(
        f"""@prefix ex: <{EX}> . @prefix owl: <http://www.w3.org/2002/07/owl#> .
        @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
        ex:A a owl:Class ; rdfs:subClassOf [ owl:onProperty ex:hasX ; owl:someValuesFrom ex:B ] .
        ex:B a owl:Class ; rdfs:subClassOf [ owl:onProperty ex:hasX ; owl:someValuesFrom ex:A ] .""",
        encoding="utf-8",
    )
    before = mini_kb.store.dump()
    with pytest.raises(PartCycleError, match=r"hasPart cycle .*A -> .*B -> .*A"):
        mini_kb.load([cyclic])
    assert mini_kb.store.dump() == before
    # A cycle that reached the store another way (a SPARQL update) is still named when read.
    mini_kb.store.update(
        f"""PREFIX ex: <{EX}> PREFIX owl: <http://www.w3.org/2002/07/owl#>
        PREFIX rdfs: <http://www.w3.org/2000/01/rdf-schema#>
        INSERT DATA {{ GRAPH <{GraphName.ONTOLOGY.node.value}> {{
            ex:A a owl:Class ; rdfs:subClassOf ex:rA . ex:rA owl:onProperty ex:hasX ; owl:someValuesFrom ex:B .
            ex:B a owl:Class ; rdfs:subClassOf ex:rB . ex:rB owl:onProperty ex:hasX ; owl:someValuesFrom ex:A .
        }} }}"""
    )
    reader_tree = mini_kb._reader.part_tree
    with pytest.raises(InvalidDescriptionError, match=r"hasPart cycle .*A -> .*B -> .*A"):
        reader_tree(EX + "A")


def test_to_dict_is_json_ready(mini_kb: KnowledgeBase) -> None:
    import json

    data = mini_kb.description(EX + "Locate").to_dict()
    assert data["class"] == "Advertisement"
    assert json.loads(json.dumps(data))["service_name"] == "LocateRobot"
