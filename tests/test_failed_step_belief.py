"""The belief after an actuator's step fails in time (actions.late_answers.unsettle, docs/execution.md "The
belief after a failed step"): the tenth round's reading lamp (docs/examples/lab10_*), switched on, then a
switch-off answered malformed left "on" believed, and the next "switch on" did nothing. A call that was
sent and failed (a malformed, error or contradicting answer) now leaves the lamp's status unknown; a call
refused before it was sent, or given up with its answer still awaited, leaves the belief as it was. No
Node and no simulation: the lamp plug's services are the store's advertisements made by the run's own
factory (sim.components.implementations) over a transport that answers at once."""

from __future__ import annotations

import logging
from collections.abc import Iterator, Mapping
from concurrent.futures import Future
from pathlib import Path
from typing import Any

import pytest

from cbrs.actions.answers import ContradictedEffectError, StoreClasses
from cbrs.actions.belief import BeliefState, Observation
from cbrs.actions.components import Component, Registry, Status
from cbrs.actions.executor import Uncounted
from cbrs.actions.plan import Plan, PlanStep
from cbrs.actions.remote import RemoteComponent
from cbrs.actions.remote_errors import RemoteCallError
from cbrs.actions.runner import RunResult, run_task
from cbrs.kb import KnowledgeBase, Requirement, Statement
from cbrs.kb.namespaces import PREFIXES
from cbrs.sim.components import implementations
from cbrs.sim.values import check
from tests.test_remote_call_timeout import Silent

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"
HOME = PREFIXES["home"]
LAB10 = "https://example.org/lab10#"
ON, OFF = LAB10 + "SwitchOnReadingLamp_LampPlug01", LAB10 + "SwitchOffReadingLamp_LampPlug01"
LAMP = {"@id": LAB10 + "ReadingLamp1", "@type": LAB10 + "ReadingLamp"}
IS_ON = (LAMP["@id"], HOME + "hasStatus", HOME + "SwitchedOn")
IS_OFF = (LAMP["@id"], HOME + "hasStatus", HOME + "SwitchedOff")
ANSWERED_ON = {"lampStatus": {"@type": "home:SwitchedOn"}}
ANSWERED_OFF = {"lampStatus": {"@type": "home:SwitchedOff"}}


@pytest.fixture
def kb() -> Iterator[KnowledgeBase]:
    store = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        store.load([EXAMPLES / "lab10_reading_lamp.ttl"], graph=graph)
    for task in ("lab10_switch_on_the_lamp.ttl", "lab10_switch_off_the_lamp.ttl"):
        store.load([EXAMPLES / task], graph="requirements")
    store.registry.register((EXAMPLES / "lab10_lamp_switch.ttl").read_text(encoding="utf-8"))
    yield store
    store.close()


class Answering:
    """A transport whose every call is answered at once: ``answer`` (an exception: the call fails with it)."""

    def __init__(self, answer: Any) -> None:
        self.answer = answer
        self.calls: list[str] = []

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        self.calls.append(service)
        future: Future[dict[str, Any]] = Future()
        if isinstance(self.answer, BaseException):
            future.set_exception(self.answer)
        else:
            future.set_result(self.answer)
        return future


def _status(kb: KnowledgeBase) -> list[str]:
    return sorted(o for s, p, o in BeliefState(kb).facts(LAMP["@id"]) if p == HOME + "hasStatus")


def _believe(kb: KnowledgeBase, *facts: tuple[str, str, str]) -> None:
    BeliefState(kb).write(Observation(facts=frozenset(facts)), whole=True)


def _plug(kb: KnowledgeBase, transport: Any, iri: str) -> Component:
    """The lamp plug's service as a run makes it (sim.components.implementations)."""
    return implementations(kb, transport=transport)(iri)


def _invoke(component: Component) -> Status:
    component.begin({"lamp": LAMP})
    return component.update()


@pytest.fixture
def warnings(caplog: pytest.LogCaptureFixture) -> Iterator[pytest.LogCaptureFixture]:
    with caplog.at_level(logging.WARNING, logger="cbrs.actions.remote"):
        yield caplog


@pytest.mark.parametrize(
    "answer, reason",
    [
        ({"lampStatus": "off"}, "answered a wrong lampStatus"),  # the round's Node plug, --answer text
        ({"status": {"@type": "home:SwitchedOff"}}, "answered without lampStatus"),
        (RemoteCallError("relay stuck"), "failed: relay stuck"),
    ],
)
def test_a_switch_off_that_fails_after_its_call_was_sent_leaves_the_lamp_unknown(
    kb: KnowledgeBase, warnings: pytest.LogCaptureFixture, answer: Any, reason: str
) -> None:
    _believe(kb, IS_ON)
    plug = _plug(kb, Answering(answer), OFF)
    assert _invoke(plug) is Status.FAILED and reason in plug.reason
    assert _status(kb) == []  # neither on nor off
    (told,) = [r.getMessage() for r in warnings.records]
    assert "SwitchOffReadingLamp_LampPlug01 (/lab10_lamp_plug_01/switch_off) failed after its call was sent" in told
    assert "so no value of " + LAMP["@id"] + " home:hasStatus is believed now" in told


def test_a_contradicting_answer_leaves_the_lamp_unknown(kb: KnowledgeBase) -> None:
    """Switch-off answered "on": the step fails (ContradictedEffectError) and the old "off" is not kept."""
    _believe(kb, IS_OFF)
    plug = _plug(kb, Answering(ANSWERED_ON), OFF)
    plug.begin({"lamp": LAMP})
    with pytest.raises(ContradictedEffectError):
        plug.update()
    assert _status(kb) == []


def test_a_call_refused_before_it_was_sent_or_still_awaited_changes_no_belief(
    kb: KnowledgeBase, warnings: pytest.LogCaptureFixture
) -> None:
    """A switch-off halted while its call is out is given up (its late answer settles the belief, as
    actions.late_answers says); the next call to the plug is refused before it is sent: nothing was done."""
    _believe(kb, IS_ON)
    silent = Silent()
    first = _plug(kb, silent, OFF)
    first.begin({"lamp": LAMP})
    first.halt()
    assert _status(kb) == [IS_ON[2]]
    refused = _plug(kb, silent, OFF)
    assert _invoke(refused) is Status.FAILED and "is still executing the call" in refused.reason
    assert len(silent.calls) == 1 and _status(kb) == [IS_ON[2]]
    assert not [r for r in warnings.records if "failed after its call was sent" in r.getMessage()]
    silent.calls[0][2].set_result({"lampStatus": "off"})  # its late answer, refused as in time: nothing changes


def test_a_success_is_believed_and_changes_nothing_else(kb: KnowledgeBase) -> None:
    _believe(kb, IS_ON)
    assert _invoke(_plug(kb, Answering(ANSWERED_OFF), OFF)) is Status.SUCCEEDED
    assert _status(kb) == [IS_ON[2]]  # a success is believed by the run's environment (on_done), not here


class LivingRoom:
    """A stub environment: it gives the lamp, verifies nothing, keeps the world graph's belief it started
    with and believes a succeeded step's effect, as the simulated home does for a relation no test decides."""

    def __init__(self, kb: KnowledgeBase, transport: Answering, refuting: bool = False) -> None:
        self.kb = kb
        self.refuting = refuting  # verify finds a step's effect not reached (as a test of the store would)
        self.registry: Registry = implementations(kb, transport=transport)
        self.context = None
        self.facts = frozenset(BeliefState(kb).facts())

    def passed_over(self) -> dict[str, str]:
        return {}

    def given(self, plan: Plan, requirements: Mapping[str, Requirement]) -> dict[str, Any]:
        return {"lamp": LAMP}

    def verify(self, step: PlanStep | None, statement: Statement, outputs: Mapping[str, Any]) -> bool | None:
        return False if self.refuting and step is not None else None

    def succeeded(self, step: PlanStep, component: str) -> None:
        status = IS_ON if component == ON else IS_OFF
        self.facts = frozenset(f for f in self.facts if f[:2] != status[:2]) | {status}

    def observe(self) -> Observation:
        return Observation(facts=self.facts)

    def clock(self) -> float:
        return 0.0


def _run(kb: KnowledgeBase, task: str, answer: Any, refuting: bool = False) -> tuple[RunResult, Answering]:
    transport = Answering(answer)
    return run_task(kb, LAB10 + task, LivingRoom(kb, transport, refuting), max_replans=0), transport


def test_after_a_malformed_switch_off_the_next_switch_on_acts(kb: KnowledgeBase) -> None:
    """The round's sequence: on (believed on), off answered as text (failed), on again: it calls the plug
    (before, the lamp was still believed on and the plan had nothing to do)."""
    first, _ = _run(kb, "SwitchOnTheReadingLamp", ANSWERED_ON)
    assert first.succeeded and _status(kb) == [IS_ON[2]]
    second, _ = _run(kb, "SwitchOffTheReadingLamp", {"lampStatus": "off"})
    assert not second.succeeded
    assert _status(kb) == []  # the run's last write, from a belief that still said on, keeps the correction
    third, plug = _run(kb, "SwitchOnTheReadingLamp", ANSWERED_ON)
    assert third.succeeded and third.composition.plan is not None
    assert [s.component for s in third.composition.plan.steps] == [ON]
    assert plug.calls == ["/lab10_lamp_plug_01/switch_on"] and _status(kb) == [IS_ON[2]]


def test_an_answer_taken_whose_effect_is_then_not_reached_leaves_the_lamp_unknown(kb: KnowledgeBase) -> None:
    """The plug answered "off", well formed, and the verifier found the lamp not off: the step failed after
    its answer was taken (actions.executor.Uncounted), and the "on" from before is not kept."""
    _believe(kb, IS_ON)
    result, plug = _run(kb, "SwitchOffTheReadingLamp", ANSWERED_OFF, refuting=True)
    assert not result.succeeded and plug.calls == ["/lab10_lamp_plug_01/switch_off"]
    assert result.report is not None and "effect not reached" in result.report.reason
    assert _status(kb) == []


def test_the_rule_holds_for_a_remote_component_built_outside_the_simulation(
    kb: KnowledgeBase, warnings: pytest.LogCaptureFixture
) -> None:
    """An executor against real devices builds RemoteComponent itself, with the advertisement's effects and
    delete effects and the store's classes: a malformed answer leaves the lamp unknown, as in a run (before,
    only sim.components' own subclass applied the rule, and this kept "on"). A call answered and then not
    counted by the executor (RemoteComponent.uncounted) does the same; one without effects changes nothing."""
    (ad,) = [ad for ad in kb.advertisements() if ad.iri == OFF]
    assert ad.effects and ad.bridge_port is not None and ad.bridge_port.topic is not None
    service = ad.bridge_port.topic
    classes = StoreClasses(kb)
    outputs = {p.name: p.type for p in ad.outputs if p.name}

    def checked(concept: str, value: Any) -> Any:
        return check(concept, value, classes.is_a)

    def plug(answer: Any, acting: bool = True) -> RemoteComponent:
        effects, deletes = (ad.effects, ad.deletes) if acting else ((), ())
        return RemoteComponent(
            OFF, Answering(answer), service, outputs, checked, 1.0,
            effects=effects, deletes=deletes, classes=classes,
        )  # fmt: skip

    _believe(kb, IS_ON)
    without = plug({"lampStatus": "off"}, acting=False)
    assert _invoke(without) is Status.FAILED and _status(kb) == [IS_ON[2]]
    malformed = plug({"lampStatus": "off"})
    assert _invoke(malformed) is Status.FAILED and "answered a wrong lampStatus" in malformed.reason
    assert _status(kb) == []
    assert any("failed after its call was sent" in r.getMessage() for r in warnings.records)

    _believe(kb, IS_ON)
    answered = plug(ANSWERED_OFF)
    assert _invoke(answered) is Status.SUCCEEDED and _status(kb) == [IS_ON[2]]
    assert isinstance(answered, Uncounted)
    answered.uncounted("effect not reached: (ReadingLamp1, hasStatus, SwitchedOff)")
    assert _status(kb) == []
