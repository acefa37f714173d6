"""An answer that contradicts its step's effect fails the step (actions.answers, docs/execution.md): a door
motor asked to open the door answering that it is closed. Disjointness is the store's (owl:disjointWith,
inherited by subclasses); the same class, a subclass, a superclass or an unknown class is no contradiction.
The failed step fails over or re-plans like any other, and nothing of it is believed."""

from __future__ import annotations

import logging
from collections.abc import Iterator, Mapping
from concurrent.futures import Future
from pathlib import Path
from typing import Any

import pytest

from cbrs.actions.answers import ContradictedEffectError, StoreClasses, read_answer
from cbrs.actions.belief import BeliefState, Observation
from cbrs.actions.components import Status
from cbrs.actions.composer import Composer
from cbrs.actions.plan import Plan, PlanStep
from cbrs.actions.remote import RemoteComponent
from cbrs.actions.runner import RunResult, run_task
from cbrs.kb import KnowledgeBase, Requirement, Statement
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment, implementations
from cbrs.sim.values import check
from tests.test_remote_call_values import MOTOR, MOTOR_TTL
from tests.test_status_effects import DOOR, KITCHEN_DOOR, OPEN_KITCHEN_DOOR, OPENED

HOME, REQ, SVC = PREFIXES["home"], PREFIXES["req"], PREFIXES["svc"]
LAB = "https://example.org/lab#"
OPENED_EFFECT = Statement(HOME + "Door", HOME + "hasStatus", HOME + "Opened")
CLOSED_EFFECT = Statement(HOME + "Door", HOME + "hasStatus", HOME + "Closed")
OUTPUTS = {"doorStatus": HOME + "DoorStatus"}
SERVICE = "/door_motor_05/open"
OTHER = SVC + "OpenDoor_DoorMotor06"
OTHER_TTL = (
    MOTOR_TTL.replace("DoorMotor05", "DoorMotor06")
    .replace("door_motor_05", "door_motor_06")
    .replace("motor 5", "motor 6")
    .replace("cbrs:responseTime 2.0", "cbrs:responseTime 2.5")  # the second choice
)
LAB_CLASSES = f"""
@prefix lab: <{LAB}> . @prefix home: <{HOME}> .
@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
lab:Jammed a owl:Class ; rdfs:subClassOf home:Closed .
lab:Ajar a owl:Class ; rdfs:subClassOf home:Opened .
"""


class Motors:
    """A transport answering each door motor's service with the status it is given (in this process)."""

    def __init__(self, answers: Mapping[str, str]) -> None:
        self.answers = dict(answers)
        self.calls: list[str] = []

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        self.calls.append(service)
        future: Future[dict[str, Any]] = Future()
        future.set_result({"doorStatus": {"@type": self.answers[service]}})
        return future


class Door:
    """A stub environment (no simulation): the kitchen door the task gives, nothing to verify."""

    def __init__(self, kb: KnowledgeBase, transport: Motors) -> None:
        self.registry = implementations(kb, transport=transport)
        self.context = None

    def given(self, plan: Plan, requirements: Mapping[str, Requirement]) -> dict[str, Any]:
        return {"door": {"@id": DOOR, "@type": HOME + "Door"}}

    def verify(self, step: PlanStep | None, statement: Statement, outputs: Mapping[str, Any]) -> bool | None:
        return None

    def observe(self) -> Observation:
        return Observation()

    def clock(self) -> float:
        return 0.0


@pytest.fixture(scope="module")
def door_kb(tmp_path_factory: pytest.TempPathFactory) -> Iterator[KnowledgeBase]:
    """The kitchen door, its task, two motors that open it (05 the first choice) and two lab classes."""
    kb = _door_kb(tmp_path_factory.mktemp("door"), MOTOR_TTL, OTHER_TTL)
    yield kb
    kb.close()


def _door_kb(tmp_path: Path, *descriptions: str) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    (tmp_path / "door.ttl").write_text(KITCHEN_DOOR, encoding="utf-8")
    (tmp_path / "task.ttl").write_text(OPEN_KITCHEN_DOOR, encoding="utf-8")
    (tmp_path / "lab.ttl").write_text(LAB_CLASSES, encoding="utf-8")
    kb.load([tmp_path / "door.ttl"], graph="map")
    kb.load([tmp_path / "task.ttl"], graph="requirements")
    kb.load([tmp_path / "lab.ttl"], graph="ontology")
    for description in descriptions:
        kb.registry.register(description)
    return kb


@pytest.fixture(scope="module")
def classes(door_kb: KnowledgeBase) -> StoreClasses:
    return StoreClasses(door_kb)


def _motor(answer: str, classes: StoreClasses, contradictions: str = "fail", checked: bool = True) -> RemoteComponent:
    motor = RemoteComponent(
        MOTOR,
        Motors({SERVICE: answer}),
        SERVICE,
        OUTPUTS,
        (lambda concept, value: check(concept, value, classes.is_a)) if checked else None,
        effects=(OPENED_EFFECT,),
        classes=classes,
        contradictions=contradictions,
    )
    motor.begin({"door": {"@id": DOOR}})
    return motor


@pytest.mark.parametrize(
    ("answer", "effect_class"),
    [
        pytest.param(HOME + "Closed", HOME + "Opened", id="declared-disjoint"),
        pytest.param(LAB + "Jammed", HOME + "Opened", id="subclass-of-a-disjoint-class"),
    ],
)
def test_an_answer_the_store_says_the_effect_excludes_fails_naming_component_output_value_and_effect(
    classes: StoreClasses, answer: str, effect_class: str
) -> None:
    motor = _motor(answer, classes)
    with pytest.raises(ContradictedEffectError) as failed:
        motor.update()
    error = failed.value
    assert (error.component, error.service, error.output, error.answered) == (MOTOR, SERVICE, "doorStatus", answer)
    assert error.effect == OPENED_EFFECT
    text = str(error)
    assert "svc:OpenDoor_DoorMotor05" in text and "doorStatus" in text and "home:hasStatus" in text
    assert answer.rsplit("#", 1)[1] in text and "disjoint with home:Opened" in text
    assert motor.outputs == {}


@pytest.mark.parametrize(
    "answer",
    [
        pytest.param(HOME + "Opened", id="the-effect-class"),
        pytest.param(LAB + "Ajar", id="a-subclass"),
        pytest.param(HOME + "DoorStatus", id="a-superclass-says-less"),
    ],
)
def test_an_answer_the_store_does_not_exclude_is_taken(classes: StoreClasses, answer: str) -> None:
    motor = _motor(answer, classes)
    assert motor.update() is Status.SUCCEEDED, motor.reason
    assert motor.outputs["doorStatus"]["@type"] == answer


def test_an_unknown_class_is_no_contradiction_but_is_noted(
    classes: StoreClasses, caplog: pytest.LogCaptureFixture
) -> None:
    motor = _motor(LAB + "NeverDeclared", classes, checked=False)
    with caplog.at_level(logging.INFO, logger="cbrs.actions.remote"):
        assert motor.update() is Status.SUCCEEDED
    assert "NeverDeclared, a class the store does not know" in caplog.text


def test_warn_takes_the_contradicting_answer_and_logs_it(
    classes: StoreClasses, caplog: pytest.LogCaptureFixture
) -> None:
    motor = _motor(HOME + "Closed", classes, contradictions="warn")
    with caplog.at_level(logging.WARNING, logger="cbrs.actions.remote"):
        assert motor.update() is Status.SUCCEEDED
    assert "contradicts its effect" in caplog.text and "remote_contradictions=warn" in caplog.text


def test_an_output_reporting_several_effects_contradicts_only_when_it_excludes_each(classes: StoreClasses) -> None:
    closed = {"doorStatus": {"@type": HOME + "Closed"}}
    both = (OPENED_EFFECT, CLOSED_EFFECT)
    assert read_answer(closed, OUTPUTS, both, classes).contradiction is None  # it may report the closing
    found = read_answer(closed, OUTPUTS, (OPENED_EFFECT,), classes).contradiction
    assert found == ("doorStatus", HOME + "Closed", OPENED_EFFECT)
    other = {"doorStatus": {"@type": HOME + "Closed"}}  # an output of another class reports no door status
    assert read_answer(other, {"doorStatus": HOME + "RobotStatus"}, both, classes).contradiction is None


def test_the_setting_reaches_the_components_of_a_run(door_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch) -> None:
    kb = door_kb
    for setting, status in (("fail", Status.FAILED), ("warn", Status.SUCCEEDED)):
        monkeypatch.setenv("CBRS_REMOTE_CONTRADICTIONS", setting)
        motor = implementations(kb, transport=Motors({SERVICE: "home:Closed"}))(MOTOR)
        assert isinstance(motor, RemoteComponent) and motor.effects == (OPENED_EFFECT,)
        motor.begin({})
        try:
            assert motor.update() is status
        except ContradictedEffectError:
            assert status is Status.FAILED
    monkeypatch.setenv("CBRS_REMOTE_CONTRADICTIONS", "ignore")
    with pytest.raises(ValueError, match="CBRS_REMOTE_CONTRADICTIONS"):
        implementations(kb, transport=Motors({}))


def _attempts(result: RunResult) -> list[tuple[str, str, str]]:
    assert result.report is not None
    return [(a.component, a.outcome, a.reason) for step in result.report.steps for a in step.attempts]


def test_a_contradicting_motor_fails_over_to_its_alternative(door_kb: KnowledgeBase) -> None:
    kb = door_kb
    motors = Motors({SERVICE: "home:Closed", "/door_motor_06/open": "home:Opened"})
    result = run_task(kb, REQ + "OpenKitchenDoor", Door(kb, motors), composer=Composer(kb))
    assert result.succeeded, result.report
    (failed, done) = _attempts(result)
    assert failed[:2] == (MOTOR, "failed") and failed[2].startswith("ContradictedEffectError: ")
    assert "answered doorStatus = home:Closed, which contradicts its effect" in failed[2]
    assert done[:2] == (OTHER, "succeeded")
    assert motors.calls == [SERVICE, "/door_motor_06/open"]


CLOSING_BOTH = {SERVICE: "home:Closed", "/door_motor_06/open": LAB + "Jammed"}


def test_contradicting_motors_fail_the_run_after_a_re_plan(door_kb: KnowledgeBase) -> None:
    kb = door_kb
    motors = Motors(CLOSING_BOTH)
    result = run_task(kb, REQ + "OpenKitchenDoor", Door(kb, motors), composer=Composer(kb), max_replans=1)
    assert not result.succeeded and len(result.replans) == 1  # re-planned like any failed step
    assert result.report is not None and result.report.unmet is not None
    assert result.report.unmet.text().count("ContradictedEffectError") == 2
    assert "OpenDoor_DoorMotor05, OpenDoor_DoorMotor06" in result.report.unmet.remedy()


def test_nothing_of_a_contradicting_answer_is_believed(door_kb: KnowledgeBase) -> None:
    """In the simulated home (its belief keeps the effects no test decides): the door is not believed
    open, nor closed; before, the motor's step succeeded and the door was believed open."""
    from cbrs.sim.world import open_world

    kb = door_kb
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb, Motors(CLOSING_BOTH))
        result = run_task(kb, REQ + "OpenKitchenDoor", environment, composer=Composer(kb), max_replans=0)
    assert not result.succeeded
    assert [(g.believed, g.holds) for g in result.goals] == [(None, None)]
    facts = BeliefState(kb).facts()
    assert OPENED not in facts
    assert not [fact for fact in facts if fact[0] == DOOR and fact[1] == HOME + "hasStatus"]
