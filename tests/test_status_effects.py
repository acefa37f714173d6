"""A status effect no test decides is believed once the step with it succeeds (docs/tasks.md), and stays
believed into the next run, which then has nothing to do: a remote motor opening the kitchen door. It
stops being believed when a later step deletes it or makes a contradicting status believed (closing the
door), so that opening the door again is planned again."""

from __future__ import annotations

from collections.abc import Mapping
from concurrent.futures import Future
from pathlib import Path
from typing import Any

from cbrs.actions.belief import BeliefState
from cbrs.actions.composer import Composer
from cbrs.actions.runner import RunResult, run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.model import Statement
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import open_world
from tests.test_remote_call_values import MOTOR, MOTOR_TTL

HOME, REQ, WORLD = PREFIXES["home"], PREFIXES["req"], "https://w3id.org/cbrs/world#"
DOOR = WORLD + "KitchenDoor"
OPENED = (DOOR, HOME + "hasStatus", HOME + "Opened")
KITCHEN_DOOR = f"""
@prefix home: <{HOME}> . @prefix world: <{WORLD}> .
world:KitchenDoor a home:Door ;
    home:minX 5.95 ; home:maxX 6.05 ; home:minY 1.6 ; home:maxY 2.6 ; home:minZ 0.0 ; home:maxZ 2.0 .
"""
OPEN_KITCHEN_DOOR = f"""
@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <{HOME}> .
@prefix svc: <https://w3id.org/cbrs/service#> . @prefix req: <{REQ}> .
req:OpenKitchenDoor a cbrs:Requirement ;
    cbrs:requestedBy svc:P3DX01 ; cbrs:deviceName "P3DX01" ; cbrs:serviceName "OpenKitchenDoor" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "door" ; cbrs:parameterType home:Door ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Door ; cbrs:conditionPredicate home:hasStatus ;
                         cbrs:conditionObject home:Opened ] ] .
"""


CLOSER = PREFIXES["svc"] + "CloseDoor_DoorMotor05"


def task(name: str, status: str) -> str:
    """A task in the shape of OpenKitchenDoor that brings the door to another status."""
    return OPEN_KITCHEN_DOOR.replace("OpenKitchenDoor", name).replace("home:Opened", status)


def closing_motor(status: str = "home:Closed", deletes: str = "") -> str:
    """The same motor's second service: the door to ``status``, with delete effects ``deletes``."""
    text = (
        MOTOR_TTL.replace("OpenDoor_DoorMotor05", "CloseDoor_DoorMotor05")
        .replace('"OpenDoor"', '"CloseDoor"')
        .replace("Open door", "Close door")
        .replace("home:Opened", status)
        .replace('"open"', '"close"')
        .replace("/door_motor_05/open", "/door_motor_05/close")
        .replace("lab_msgs/OpenDoor", "lab_msgs/CloseDoor")
        .replace('svc:DoorMotor05 a owl:NamedIndividual , home:Actuator ; rdfs:label "Kitchen door motor 5"@en .', "")
    )
    effect = f"cbrs:conditionObject {status} ]"
    return text.replace(f"{effect} ] ;", f"{effect}{deletes} ] ;")


class DoorMotor:
    """The motor's services, answered in this process: the door's new status, counting the calls."""

    def __init__(self) -> None:
        self.calls: list[dict[str, Any]] = []
        self.services: list[str] = []

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        self.calls.append(dict(args))
        self.services.append(service)
        future: Future[dict[str, Any]] = Future()
        future.set_result({"doorStatus": {"@type": "home:Closed" if service.endswith("close") else "home:Opened"}})
        return future


def _kb(tmp_path: Path) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    (tmp_path / "door.ttl").write_text(KITCHEN_DOOR, encoding="utf-8")
    (tmp_path / "task.ttl").write_text(OPEN_KITCHEN_DOOR, encoding="utf-8")
    kb.load([tmp_path / "door.ttl"], graph="map")
    kb.load([tmp_path / "task.ttl"], graph="requirements")
    kb.registry.register(MOTOR_TTL)
    return kb


def _run(kb: KnowledgeBase, motor: DoorMotor, name: str = "OpenKitchenDoor") -> RunResult:
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        return run_task(kb, REQ + name, SimEnvironment(world, kb, motor), composer=Composer(kb))


def test_opening_the_door_is_believed_and_the_next_run_has_nothing_to_do(tmp_path: Path) -> None:
    kb = _kb(tmp_path)
    motor = DoorMotor()
    first = _run(kb, motor)
    assert first.succeeded, first.report
    assert first.report is not None and [a.component for s in first.report.steps for a in s.attempts] == [MOTOR]
    assert [(g.believed, g.holds) for g in first.goals] == [(True, None)]  # no referee decides a door here
    assert OPENED in BeliefState(kb).facts()
    assert motor.calls == [{"door": {"@id": DOOR, "@type": HOME + "Door"}}]

    second = _run(kb, motor)
    assert second.succeeded, second.report
    assert second.composition.plan is not None and second.composition.plan.steps == ()
    assert [(g.believed, g.holds) for g in second.goals] == [(True, None)]  # it held at the start: believed
    assert len(motor.calls) == 1  # the door was not opened again
    assert OPENED in BeliefState(kb).facts()


def test_a_status_object_is_a_quality_and_only_relations_no_test_decides_are_kept_from_an_earlier_run(
    tmp_path: Path,
) -> None:
    kb = _kb(tmp_path)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb, DoorMotor())
        opened = Statement(HOME + "Door", HOME + "hasStatus", HOME + "Opened")
        environment.context.inputs = {"door": {"@id": DOOR, "@type": HOME + "Door"}}
        assert environment._believe_effect(opened) == OPENED
        not_a_quality = Statement(HOME + "Door", HOME + "hasStatus", HOME + "DoorOpenedEvent")  # an event
        assert environment._believe_effect(not_a_quality) is None
        BeliefState(kb).write(environment.observe())
    kb.update(
        "INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/world> {"
        f" <{DOOR}> <{HOME}isNear> <{WORLD}Person> . <{DOOR}> <{HOME}hasStatus> <{HOME}Opened> }} }}"
    )
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        kept = SimEnvironment(world, kb, DoorMotor()).effects
    assert kept == {OPENED}


LAB = "https://example.org/lab#"
AJAR = (DOOR, HOME + "hasStatus", LAB + "Ajar")
AJAR_TTL = f"""
@prefix lab: <{LAB}> . @prefix home: <{HOME}> .
@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
lab:Ajar a owl:Class ; rdfs:subClassOf home:DoorStatus ; rdfs:label "ajar"@en .
"""
DELETES_OPENED = (
    " ; cbrs:hasDeleteEffect [ a cbrs:DeleteEffect ; cbrs:conditionSubject home:Door ;"
    " cbrs:conditionPredicate home:hasStatus ; cbrs:conditionObject home:Opened ]"
)


def _with_closing(tmp_path: Path, status: str = "home:Closed", deletes: str = "") -> KnowledgeBase:
    """The opening motor and its task, plus the motor's closing service and a task to reach ``status``."""
    kb = _kb(tmp_path)
    kb.registry.register((AJAR_TTL if status.startswith("lab:") else "") + closing_motor(status, deletes))
    (tmp_path / "close.ttl").write_text(
        (f"@prefix lab: <{LAB}> .\n" if status.startswith("lab:") else "") + task("CloseKitchenDoor", status),
        encoding="utf-8",
    )
    kb.load([tmp_path / "close.ttl"], graph="requirements")
    return kb


def test_closing_the_door_ends_the_belief_that_it_is_open_so_opening_it_is_planned_again(tmp_path: Path) -> None:
    kb = _with_closing(tmp_path)  # Opened and Closed are declared disjoint (ontologies/home.ttl)
    motor = DoorMotor()
    closed = (DOOR, HOME + "hasStatus", HOME + "Closed")
    assert _run(kb, motor).succeeded
    assert OPENED in BeliefState(kb).facts()
    assert _run(kb, motor, "CloseKitchenDoor").succeeded
    assert closed in BeliefState(kb).facts() and OPENED not in BeliefState(kb).facts()
    again = _run(kb, motor)
    assert again.succeeded, again.report
    assert again.composition.plan is not None and [s.component for s in again.composition.plan.steps] == [MOTOR]
    assert motor.services == ["/door_motor_05/open", "/door_motor_05/close", "/door_motor_05/open"]
    assert OPENED in BeliefState(kb).facts() and closed not in BeliefState(kb).facts()


def test_a_delete_effect_ends_a_belief_the_ontology_does_not_say_is_contradicted(tmp_path: Path) -> None:
    kb = _with_closing(tmp_path, "lab:Ajar", DELETES_OPENED)
    motor = DoorMotor()
    assert _run(kb, motor).succeeded
    assert _run(kb, motor, "CloseKitchenDoor").succeeded
    facts = BeliefState(kb).facts()
    assert AJAR in facts and OPENED not in facts  # Ajar is not declared disjoint with Opened: the delete did it


def test_without_a_delete_or_a_contradiction_both_statuses_stay_believed(tmp_path: Path) -> None:
    kb = _with_closing(tmp_path, "lab:Ajar")
    motor = DoorMotor()
    assert _run(kb, motor).succeeded
    assert _run(kb, motor, "CloseKitchenDoor").succeeded
    assert {OPENED, AJAR} <= BeliefState(kb).facts()


def test_a_component_nothing_here_can_run_is_named_when_no_plan_is_left(tmp_path: Path) -> None:
    """The motor without a service port, and no simulated skill of its name: the run said only that no
    component provides the effect, though the motor is registered and plans (new-user walkthrough)."""
    kb = KnowledgeBase.open(":memory:")
    (tmp_path / "door.ttl").write_text(KITCHEN_DOOR, encoding="utf-8")
    (tmp_path / "task.ttl").write_text(OPEN_KITCHEN_DOOR, encoding="utf-8")
    kb.load([tmp_path / "door.ttl"], graph="map")
    kb.load([tmp_path / "task.ttl"], graph="requirements")
    port = MOTOR_TTL.index("    cbrs:hasPort [")
    kb.registry.register(MOTOR_TTL[:port].rstrip().removesuffix(";") + " .\n")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, REQ + "OpenKitchenDoor", SimEnvironment(world, kb), composer=Composer(kb))
    assert not result.succeeded and result.composition.plan is None
    (unsatisfied,) = result.composition.unsatisfied
    assert unsatisfied.unrunnable and unsatisfied.unrunnable[0][0] == MOTOR
    assert "OpenDoor_DoorMotor05 was planned for it but cannot run here" in unsatisfied.text()
    assert "no skill for its service name 'OpenDoor'" in unsatisfied.text()
    assert [entry["component"] for entry in unsatisfied.to_dict()["unrunnable"]] == [MOTOR]
