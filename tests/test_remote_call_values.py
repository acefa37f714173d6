"""A remote component's answer is checked against its port's type as docs/values.md says: the declared
class or a subclass of it (by the store's taxonomy), a designator only for a class with no JSON shape
and only of that class; a refused answer fails the step that produced it, so its alternative runs."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from concurrent.futures import Future
from typing import Any

import pytest

from cbrs.actions.components import Status
from cbrs.actions.remote import RemoteComponent
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.sim.components import implementations
from cbrs.sim.values import MalformedValueError, check, taxonomy

HOME, SVC = PREFIXES["home"], PREFIXES["svc"]
DOOR_STATUS, OBJECT_POSITION = HOME + "DoorStatus", HOME + "ObjectPosition3D"
LAB = "http://lab.example/onto#"
MOTOR = SVC + "OpenDoor_DoorMotor05"
MOTOR_TTL = f"""
@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <{HOME}> . @prefix svc: <{SVC}> .
@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
svc:DoorMotor05 a owl:NamedIndividual , home:Actuator ; rdfs:label "Kitchen door motor 5"@en .
svc:OpenDoor_DoorMotor05 a cbrs:PhysicalManipulationComponent ;
    rdfs:label "Open door (kitchen door motor 5)"@en ;
    cbrs:device svc:DoorMotor05 ; cbrs:deviceName "DoorMotor05" ;
    cbrs:serviceName "OpenDoor" ; cbrs:serviceCategory "DoorActuation" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput  [ a cbrs:Parameter ; cbrs:parameterName "door" ; cbrs:parameterType home:Door ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "doorStatus" ; cbrs:parameterType home:DoorStatus ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Door ; cbrs:conditionPredicate home:hasStatus ;
                         cbrs:conditionObject home:Opened ] ] ;
    cbrs:hasSEAModel [ a cbrs:SEAModel ; cbrs:effectiveArea home:Kitchen ;
        cbrs:minX 6.0 ; cbrs:maxX 10.0 ; cbrs:minY 0.0 ; cbrs:maxY 5.0 ] ;
    cbrs:hasQoSModel [ a cbrs:QoSModel ; cbrs:responseTime 2.0 ; cbrs:availability 0.95 ] ;
    cbrs:hasPort [ a cbrs:ServicePort ; cbrs:portName "open" ;
        cbrs:topic "/door_motor_05/open" ; cbrs:messageType "lab_msgs/OpenDoor" ] .
"""


class Answering:
    """A transport whose every call is answered at once with ``answer``."""

    def __init__(self, answer: Any) -> None:
        self.answer = answer
        self.calls: list[tuple[str, dict[str, Any], float]] = []

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        self.calls.append((service, dict(args), timeout))
        future: Future[dict[str, Any]] = Future()
        future.set_result(self.answer)
        return future


def _run(component: RemoteComponent) -> Status:
    component.begin({})
    for _ in range(100):
        status = component.update()
        if status is not Status.RUNNING:
            return status
    return Status.RUNNING


@pytest.fixture(scope="module")
def door_kb() -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(":memory:")
    kb.registry.register(MOTOR_TTL)
    kb.update(
        "INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/ontology> {"
        f" <{LAB}Ajar> a <http://www.w3.org/2002/07/owl#Class> ;"
        f" <http://www.w3.org/2000/01/rdf-schema#subClassOf> <{HOME}Opened> }} }}"
    )
    yield kb
    kb.close()


def test_a_subclass_of_a_port_class_with_no_shape_is_accepted() -> None:
    assert check(DOOR_STATUS, {"@type": "home:Opened"}) == {"@type": HOME + "Opened"}
    assert check(DOOR_STATUS, {"@type": DOOR_STATUS, "state": "opened"})["state"] == "opened"


@pytest.mark.parametrize(
    ("port", "value", "shown"),
    [
        (DOOR_STATUS, {"@type": "home:RobotLocation"}, "'@type' is 'home:RobotLocation'"),
        (DOOR_STATUS, {"@type": "home:Status"}, "'@type' is 'home:Status'"),  # a superclass is not enough
        (DOOR_STATUS, {"@id": "urn:x", "@type": "home:RobotLocation"}, "'@type' is 'home:RobotLocation'"),
        (HOME + "RobotLocation", {"@id": "urn:x", "@type": "home:PersonPosition"}, "'urn:x'"),
        (OBJECT_POSITION, {"@id": "urn:x", "@type": "home:Cup"}, "'home:Cup'"),
        (OBJECT_POSITION, {"@id": "urn:x", "@type": OBJECT_POSITION}, "'urn:x'"),
    ],
)
def test_a_value_of_another_class_or_a_designator_for_a_shaped_port_is_refused_naming_both(
    port: str, value: dict[str, Any], shown: str
) -> None:
    with pytest.raises(MalformedValueError) as refused:
        check(port, value)
    message = str(refused.value)
    assert refused.value.concept == port
    assert message.startswith(f"malformed home:{port.split('#')[1]}: ")
    assert shown in message
    assert port.split("#")[1] in message.split("expected", 1)[1]


def test_a_port_type_given_as_a_prefixed_name_is_the_class_it_names() -> None:
    """docs/values.md's own example, ``check("home:ObjectPosition3D", ...)``: a good value was refused as of
    another class, the port's prefixed name being no class with a shape."""
    value = {"@type": OBJECT_POSITION, "x": 1.0, "y": 2.0, "z": 0.8}
    assert check("home:ObjectPosition3D", value) == check(OBJECT_POSITION, value)
    with pytest.raises(MalformedValueError) as refused:
        check("home:ObjectPosition3D", {"@id": "urn:x", "@type": "home:Cup"})
    assert refused.value.concept == OBJECT_POSITION


def test_a_designator_of_the_port_class_or_a_subclass_is_a_thing_of_that_class() -> None:
    door = {"@id": "https://w3id.org/cbrs/world#KitchenDoor", "@type": "home:Door"}
    assert check(HOME + "BuildingElement", door)["@id"] == door["@id"]
    with pytest.raises(MalformedValueError):
        check(HOME + "Window", door)


def test_a_subclass_with_no_shape_of_its_own_is_read_as_the_port_shape_and_passed_on_as_the_port_class() -> None:
    lab = LAB + "CalibratedRobotLocation"
    is_a = taxonomy([(lab, HOME + "RobotLocation")])
    value = {"@type": lab, "x": 1.0, "y": 2.0, "theta": 0.5}
    assert check(HOME + "RobotLocation", value, is_a) == {**value, "@type": HOME + "RobotLocation"}
    with pytest.raises(MalformedValueError, match="'x' is missing"):
        check(HOME + "RobotLocation", {"@type": lab, "y": 2.0, "theta": 0.5}, is_a)
    with pytest.raises(MalformedValueError, match="'@type'"):
        check(HOME + "RobotLocation", value)  # the bundled taxonomy does not know the lab's class


def test_a_taxonomy_is_closed_under_transitivity() -> None:
    is_a = taxonomy([("c", "b"), ("b", "a"), ("a", "c")])  # a cycle ends
    assert is_a("c", "a") and is_a("a", "b") and is_a("x", "x") and not is_a("x", "a")


def test_a_remote_answer_is_checked_by_the_store_taxonomy_with_the_classes_a_lab_added(door_kb: KnowledgeBase) -> None:
    for answer, status in (
        ({"doorStatus": {"@type": "home:Opened"}}, Status.SUCCEEDED),
        ({"doorStatus": {"@type": LAB + "Ajar"}}, Status.SUCCEEDED),
        ({"doorStatus": {"@id": "urn:not-a-status", "@type": "home:RobotLocation"}}, Status.FAILED),
    ):
        registry = implementations(door_kb, transport=Answering(answer))
        component = registry(MOTOR)
        assert isinstance(component, RemoteComponent)
        assert _run(component) is status, component.reason
        if status is Status.FAILED:
            assert component.reason.startswith("/door_motor_05/open answered a wrong doorStatus: malformed home:Door")
            assert "RobotLocation" in component.reason


def test_a_designator_where_a_position_is_due_fails_the_producing_step() -> None:
    """A lab camera answering the pen for its position (repro 06, mode designator): its step fails, not the next."""
    answer = {"objectPosition": {"@id": "https://w3id.org/cbrs/world#Pen", "@type": "home:Pen"}}
    camera = RemoteComponent(
        SVC + "RecogniseObjectByColour_LabCam01",
        Answering(answer),
        "/lab_cam_01/recognise",
        {"objectPosition": OBJECT_POSITION},
        check,
    )
    assert _run(camera) is Status.FAILED
    assert "answered a wrong objectPosition: malformed home:ObjectPosition3D" in camera.reason
    assert camera.outputs == {}
