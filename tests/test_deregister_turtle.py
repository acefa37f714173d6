"""Deregistering a Turtle description, registered or loaded, gives back the store as it was before, graph
by graph (graph:entailed included); registering it again gives the store of a single registration. What
is not an advertisement is not deregistered: a device in graph:services was (``is_registered`` took any
typed subject for an advertisement), which left the advertisements that use it pointing at nothing."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from cbrs.kb import InvalidDescriptionError, KnowledgeBase, NotFoundError

from .test_deregister_owls import triples_by_graph

pytestmark = pytest.mark.both_stores

EX = "http://example.org/mini#"
BLANK = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix ex: <http://example.org/mini#> .
ex:Tracker a cbrs:DynamicPerceptionComponent ; cbrs:deviceName "Camera2" ; cbrs:serviceName "TrackRobot" ;
    cbrs:device ex:Camera1 ;
    cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType ex:MarkerColour ] ;
                        cbrs:hasOutput [ cbrs:parameterType ex:Location ] ;
                        cbrs:hasEffect [ cbrs:conditionSubject ex:Robot ; cbrs:conditionPredicate ex:isAt ;
                                         cbrs:conditionObject ex:Location ] ] ;
    cbrs:hasSEAModel [ cbrs:effectiveArea ex:LivingRoom ] ;
    cbrs:hasQoSModel [ cbrs:responseTime 0.2 ] ;
    cbrs:hasPort [ a cbrs:DataPort ; cbrs:portName "pose" ; cbrs:topic "/tracker/pose" ] .
"""
NAMED = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix ex: <http://example.org/mini#> .
ex:Tracker a cbrs:DynamicPerceptionComponent ; cbrs:deviceName "Camera2" ; cbrs:serviceName "TrackRobot" ;
    cbrs:hasOWLSModel ex:Tracker-model ; cbrs:hasQoSModel ex:Tracker-qos .
ex:Tracker-model cbrs:hasInput ex:Tracker-in ; cbrs:hasOutput ex:Tracker-out .
ex:Tracker-in cbrs:parameterType ex:MarkerColour .
ex:Tracker-out cbrs:parameterType ex:Location .
ex:Tracker-qos cbrs:responseTime 0.2 .
"""


@pytest.mark.parametrize("turtle", [BLANK, NAMED], ids=["blank-parts", "named-parts"])
def test_a_registration_goes_whole_and_comes_back_the_same(mini_kb: KnowledgeBase, turtle: str) -> None:
    before = triples_by_graph(mini_kb)
    mini_kb.registry.register(turtle)
    registered = triples_by_graph(mini_kb)
    mini_kb.registry.deregister(EX + "Tracker")
    assert triples_by_graph(mini_kb) == before
    mini_kb.registry.register(turtle)
    assert triples_by_graph(mini_kb) == registered


def test_a_loaded_description_goes_whole(mini_kb: KnowledgeBase, tmp_path: Path) -> None:
    """``cbrs load`` has no unload; a description it loaded into graph:services is deregistered."""
    before = triples_by_graph(mini_kb)
    path = tmp_path / "tracker.ttl"
    path.write_text(BLANK, encoding="utf-8")
    mini_kb.load([path])
    loaded = triples_by_graph(mini_kb)
    mini_kb.registry.deregister(EX + "Tracker")
    assert triples_by_graph(mini_kb) == before
    mini_kb.load([path])
    assert triples_by_graph(mini_kb) == loaded


def test_the_device_two_descriptions_use_stays(mini_kb: KnowledgeBase) -> None:
    mini_kb.registry.register(BLANK)
    mini_kb.registry.deregister(EX + "Tracker")
    assert mini_kb.description(EX + "Locate").device == EX + "Camera1"
    assert mini_kb.describes(EX + "Camera1")


@pytest.mark.parametrize(
    "iri",
    [EX + "Camera1", EX + "Nothing", EX + "MarkerColour"],
    ids=["a-device", "unknown", "a-concept"],
)
def test_what_is_no_advertisement_is_not_deregistered(mini_kb: KnowledgeBase, iri: str) -> None:
    before = triples_by_graph(mini_kb)
    with pytest.raises(NotFoundError, match="registered advertisement or requirement"):
        mini_kb.registry.deregister(iri)
    assert triples_by_graph(mini_kb) == before


def test_a_device_is_not_updated_as_an_advertisement(mini_kb: KnowledgeBase) -> None:
    before = triples_by_graph(mini_kb)
    as_device = BLANK.replace("ex:Tracker a", "ex:Camera1 a")
    with pytest.raises(NotFoundError):
        mini_kb.registry.update(as_device)
    assert triples_by_graph(mini_kb) == before
    assert not mini_kb.registry.is_registered(EX + "Camera1")
    assert mini_kb.registry.is_registered(EX + "Locate")


def test_a_lab_kind_counts_as_an_advertisement(mini_kb: KnowledgeBase) -> None:
    turtle = BLANK.replace("cbrs:DynamicPerceptionComponent", "ex:DoorCamera") + (
        "ex:DoorCamera <http://www.w3.org/2000/01/rdf-schema#subClassOf> cbrs:DynamicPerceptionComponent ."
    )
    mini_kb.registry.register(turtle)
    assert mini_kb.registry.is_registered(EX + "Tracker")
    mini_kb.registry.deregister(EX + "Tracker")
    assert not mini_kb.registry.is_registered(EX + "Tracker")


def test_a_named_part_two_descriptions_share_goes_with_the_last(mini_kb: KnowledgeBase) -> None:
    before = triples_by_graph(mini_kb)
    other = NAMED.replace("ex:Tracker a", "ex:Follower a").replace('"TrackRobot"', '"FollowRobot"')
    other = other.split("ex:Tracker-model cbrs:hasInput")[0].replace(
        "ex:Tracker-model", "[ cbrs:hasOutput [ cbrs:parameterType ex:Location ] ]"
    )
    mini_kb.registry.register(NAMED)
    mini_kb.registry.register(other)
    mini_kb.registry.deregister(EX + "Tracker")
    assert [q.value for q in mini_kb.description(EX + "Follower").qos] == [0.2]
    mini_kb.registry.deregister(EX + "Follower")
    assert triples_by_graph(mini_kb) == before


def test_a_loaded_requirement_goes_whole(mini_kb: KnowledgeBase, tmp_path: Path) -> None:
    """Requirements have no registry of their own: a loaded one is deregistered from graph:requirements."""
    before = triples_by_graph(mini_kb)
    path = tmp_path / "need.ttl"
    path.write_text(
        """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix ex: <http://example.org/mini#> .
ex:Need2 a cbrs:Requirement ; cbrs:serviceName "FindRobot" ;
    cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType ex:MarkerColour ] ;
                        cbrs:hasOutput [ cbrs:parameterType ex:Location ] ] ;
    cbrs:hasQoSModel [ cbrs:responseTime 0.5 ] .
""",
        encoding="utf-8",
    )
    mini_kb.load([path], graph="requirements")
    loaded = triples_by_graph(mini_kb)
    mini_kb.registry.deregister(EX + "Need2")
    assert triples_by_graph(mini_kb) == before
    mini_kb.load([path], graph="requirements")
    assert triples_by_graph(mini_kb) == loaded


def test_a_file_with_a_requirement_besides_advertisements_is_refused(mini_kb: KnowledgeBase) -> None:
    """Registration wrote the requirement into graph:services with the advertisement, said only
    'registered' for the advertisement, and no deregistration found the requirement there afterwards."""
    before = triples_by_graph(mini_kb)
    mixed = (
        BLANK
        + """ex:Need3 a cbrs:Requirement ; cbrs:serviceName "FindRobot" ;
    cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType ex:Location ] ] .
"""
    )
    with pytest.raises(InvalidDescriptionError, match=re.escape(f"requirement {EX}Need3 besides advertisements")):
        mini_kb.registry.register(mixed)
    with pytest.raises(InvalidDescriptionError, match="cbrs load --graph requirements"):
        mini_kb.registry.update(mixed)
    assert triples_by_graph(mini_kb) == before


def test_a_blank_node_two_descriptions_of_one_file_share_stays_with_the_one_left(mini_kb: KnowledgeBase) -> None:
    """``cbrs:hasQoSModel _:q`` on two descriptions of one file: deregistering the first took the QoS
    model of the second with it."""
    before = triples_by_graph(mini_kb)
    mini_kb.registry.register(
        """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix ex: <http://example.org/mini#> .
ex:A a cbrs:StaticDataComponent ; cbrs:deviceName "S" ; cbrs:serviceName "A" ; cbrs:hasQoSModel _:q ;
    cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType ex:Location ] ] .
ex:B a cbrs:StaticDataComponent ; cbrs:deviceName "S" ; cbrs:serviceName "B" ; cbrs:hasQoSModel _:q ;
    cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType ex:Location ] ] .
_:q cbrs:responseTime 0.5 .
"""
    )
    mini_kb.registry.deregister(EX + "A")
    assert [q.value for q in mini_kb.description(EX + "B").qos] == [0.5]
    mini_kb.registry.deregister(EX + "B")
    assert triples_by_graph(mini_kb) == before
