from __future__ import annotations

import pytest

from cbrs.kb import AlreadyRegisteredError, InvalidDescriptionError, KnowledgeBase, NotFoundError, RdfParseError

pytestmark = pytest.mark.both_stores

EX = "http://example.org/mini#"
HEAD = """@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix ex: <http://example.org/mini#> .
@prefix rdf: <http://www.w3.org/1999/02/22-rdf-syntax-ns#> .
"""


def _tracker(output: str = "ex:Location", name: str = "TrackRobot") -> str:
    return (
        HEAD
        + f"""
ex:Tracker a cbrs:DynamicPerceptionComponent ;
    cbrs:deviceName "Camera2" ; cbrs:serviceName "{name}" ;
    cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType ex:MarkerColour ] ;
                        cbrs:hasOutput [ cbrs:parameterType {output} ] ] .
"""
    )


def test_register_then_read(mini_kb: KnowledgeBase) -> None:
    assert mini_kb.registry.register(_tracker()) == [EX + "Tracker"]
    ad = mini_kb.description(EX + "Tracker")
    assert [p.type for p in ad.outputs] == [EX + "Location"]
    assert EX + "Tracker" in [a.iri for a in mini_kb.advertisements()]


def test_register_twice_is_refused(mini_kb: KnowledgeBase) -> None:
    mini_kb.registry.register(_tracker())
    before = mini_kb.store.dump()
    with pytest.raises(AlreadyRegisteredError):
        mini_kb.registry.register(_tracker(name="Other"))
    assert mini_kb.store.dump() == before


def test_update_replaces_the_whole_description(mini_kb: KnowledgeBase) -> None:
    mini_kb.registry.register(_tracker())
    mini_kb.registry.update(_tracker(output="ex:Position", name="TrackRobot2"))
    ad = mini_kb.description(EX + "Tracker")
    assert [p.type for p in ad.outputs] == [EX + "Position"]
    assert ad.service_name == "TrackRobot2"
    assert len(ad.inputs) == 1


def test_deregister_leaves_the_store_as_before_registration(mini_kb: KnowledgeBase) -> None:
    before = mini_kb.store.dump()
    mini_kb.registry.register(_tracker())
    removed = mini_kb.registry.deregister(EX + "Tracker")
    assert removed > 5
    assert mini_kb.store.dump() == before


def test_deregister_keeps_what_other_descriptions_share(mini_kb: KnowledgeBase) -> None:
    # The device node is shared, not part of the description's own nodes.
    mini_kb.registry.deregister(EX + "Locate")
    assert mini_kb.describes(EX + "Camera1")
    assert [a.iri for a in mini_kb.advertisements()] == [EX + "OpenDoor"]


def test_update_or_deregister_of_unknown_is_not_found(mini_kb: KnowledgeBase) -> None:
    with pytest.raises(NotFoundError):
        mini_kb.registry.update(_tracker())
    with pytest.raises(NotFoundError):
        mini_kb.registry.deregister(EX + "Tracker")


@pytest.mark.parametrize(
    ("turtle", "problem"),
    [
        pytest.param(
            HEAD + 'ex:T a cbrs:MethodInvocationComponent ; cbrs:deviceName "d" ; cbrs:serviceName "s" .',
            "hasOWLSModel",
            id="no-owls-model",
        ),
        pytest.param(
            HEAD + 'ex:T a cbrs:MethodInvocationComponent ; cbrs:deviceName "d" ; cbrs:serviceName "s" ;'
            " cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType ex:A ] ] .",
            "neither an output nor an effect",
            id="no-output",
        ),
        pytest.param(
            HEAD + 'ex:T a cbrs:MethodInvocationComponent ; cbrs:deviceName "d" ; cbrs:serviceName "s" ;'
            ' cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterName "x" ] ] .',
            "no cbrs:parameterType",
            id="untyped-parameter",
        ),
        pytest.param(
            HEAD + 'ex:T a cbrs:MethodInvocationComponent ; cbrs:deviceName "d" ; cbrs:serviceName "s" ;'
            " cbrs:hasOWLSModel [ cbrs:hasEffect [ cbrs:conditionSubject ex:Door ;"
            " cbrs:conditionObject ex:Opened ] ] .",
            "lacks cbrs:conditionPredicate",
            id="incomplete-condition",
        ),
        pytest.param(
            HEAD + 'ex:T a cbrs:MethodInvocationComponent ; cbrs:deviceName "d" ; cbrs:serviceName "s" ;'
            " cbrs:hasOWLSModel [ cbrs:hasEffect [ rdf:subject ex:Door ; rdf:predicate ex:hasStatus ;"
            " rdf:object ex:Opened ] ] .",
            "uses rdf:subject, rdf:predicate, rdf:object, the reified form of core 0.1.0",
            id="reified-condition",
        ),
        pytest.param(
            HEAD + 'ex:T a cbrs:MethodInvocationComponent ; cbrs:serviceName "s" ;'
            " cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType ex:A ] ] .",
            "device name",
            id="no-device-name",
        ),
        pytest.param(HEAD + "ex:T a ex:Camera .", "describes no advertisement", id="not-an-advertisement"),
    ],
)
def test_invalid_descriptions_are_refused_and_change_nothing(mini_kb: KnowledgeBase, turtle: str, problem: str) -> None:
    before = mini_kb.store.dump()
    with pytest.raises(InvalidDescriptionError, match=problem):
        mini_kb.registry.register(turtle)
    assert mini_kb.store.dump() == before


def test_unparseable_registration_names_the_line(mini_kb: KnowledgeBase) -> None:
    with pytest.raises(RdfParseError) as caught:
        mini_kb.registry.register(HEAD + 'ex:T a cbrs:MethodInvocationComponent ;\n  cbrs:serviceName "s .\n')
    assert caught.value.line == 5
