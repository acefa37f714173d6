"""A status effect no test decides is believed once the step with it succeeds (docs/tasks.md), and stays
believed into the next run, which then has nothing to do: a remote motor opening the kitchen door."""

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


class DoorMotor:
    """The motor's service, answered in this process: the door's new status, counting the calls."""

    def __init__(self) -> None:
        self.calls: list[dict[str, Any]] = []

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        self.calls.append(dict(args))
        future: Future[dict[str, Any]] = Future()
        future.set_result({"doorStatus": {"@type": "home:Opened"}})
        return future


def _kb(tmp_path: Path) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    (tmp_path / "door.ttl").write_text(KITCHEN_DOOR, encoding="utf-8")
    (tmp_path / "task.ttl").write_text(OPEN_KITCHEN_DOOR, encoding="utf-8")
    kb.load([tmp_path / "door.ttl"], graph="map")
    kb.load([tmp_path / "task.ttl"], graph="requirements")
    kb.registry.register(MOTOR_TTL)
    return kb


def _run(kb: KnowledgeBase, motor: DoorMotor) -> RunResult:
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        return run_task(kb, REQ + "OpenKitchenDoor", SimEnvironment(world, kb, motor), composer=Composer(kb))


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
