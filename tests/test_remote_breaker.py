"""A remote component whose calls time out is passed over for a cool-down, then given one trial call
(actions.breaker, docs/execution.md): its SDK's heartbeats keep it available, so before, every run and
every re-plan waited its whole call timeout again. Tick by tick with a silent transport and a clock of
the test's, then in runs (a stub environment), then a hanging SDK handler on a loopback server."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator, Mapping
from concurrent.futures import Future
from typing import Any

import pytest

from cbrs.actions.belief import Observation
from cbrs.actions.breaker import BreakerPolicy, BreakerPolicyError, late_answers_awaited, passed_over
from cbrs.actions.components import Registry, Status
from cbrs.actions.composer import Composer
from cbrs.actions.plan import Plan, PlanStep
from cbrs.actions.remote import RemoteComponent, given_up
from cbrs.actions.runner import RunResult, run_task
from cbrs.bridge_client import BridgeClient
from cbrs.kb import KnowledgeBase, Requirement, Statement
from cbrs.server import Server
from cbrs.sim.components import implementations
from tests.test_live_components import REQ, THERMOMETER, TOKEN, sdk_thermometer, server, url
from tests.test_remote_call_timeout import SERVICE, Clock, Silent
from tests.test_remote_call_values import MOTOR

__all__ = ["server"]  # the loopback server fixture, reused

POLICY = BreakerPolicy(timeouts=1, cooldown=30.0)


def _call(transport: Silent, clock: Clock, policy: BreakerPolicy | None = POLICY, **more: Any) -> RemoteComponent:
    component = RemoteComponent(MOTOR, transport, SERVICE, {}, None, 10.0, clock, breaker=policy, **more)
    component.begin({})
    return component


def _time_out(component: RemoteComponent, clock: Clock) -> None:
    assert component.update() is Status.RUNNING
    clock.now += 10.5
    assert component.update() is Status.FAILED
    assert component.reason == f"{SERVICE} did not answer within 10 s"


def test_a_timeout_passes_the_component_over_until_the_cool_down_then_one_trial_call_closes_it() -> None:
    transport, clock = Silent(), Clock()
    _time_out(_call(transport, clock), clock)
    why = passed_over(transport, clock())[MOTOR]
    assert why.startswith("svc:OpenDoor_DoorMotor05 is passed over: its last 1 call(s) to /door_motor_05/open")
    assert "timed out (no answer within 10 s), the last 0.0 s ago; one trial call goes to it in 30.0 s" in why
    clock.now += 29.0
    refused = _call(transport, clock)  # a later run's instance
    assert refused.update() is Status.FAILED and refused.reason.endswith(
        "in 1.0 s (a cool-down of 30 s, setting remote_breaker_cooldown)"
    )
    assert len(transport.calls) == 1  # nothing was sent
    clock.now += 1.0
    assert passed_over(transport, clock()) == {}  # half-open: composition may plan with it again
    trial = _call(transport, clock)
    assert len(transport.calls) == 2
    second = _call(transport, clock)  # another run meanwhile waits for the trial's verdict
    assert second.update() is Status.FAILED and "a trial call to /door_motor_05/open is out" in second.reason
    assert MOTOR in passed_over(transport, clock())
    transport.calls[1][2].set_result({})  # answered in time
    assert trial.update() is Status.SUCCEEDED
    assert passed_over(transport, clock()) == {}
    _call(transport, clock)
    assert len(transport.calls) == 3


def test_a_trial_that_times_out_passes_it_over_for_another_cool_down() -> None:
    transport, clock = Silent(), Clock()
    _time_out(_call(transport, clock), clock)
    clock.now += 30.0
    _time_out(_call(transport, clock), clock)
    assert "the last 0.0 s ago; one trial call goes to it in 30.0 s" in passed_over(transport, clock())[MOTOR]
    transport.calls[0][2].set_result({})  # a late answer closes nothing: it is still slower than its timeout
    assert MOTOR in passed_over(transport, clock())


def test_the_count_of_timeouts_is_of_calls_in_a_row_and_zero_switches_the_breaker_off() -> None:
    transport, clock = Silent(), Clock()
    twice = BreakerPolicy(timeouts=2)
    _time_out(_call(transport, clock, twice), clock)
    assert passed_over(transport, clock()) == {}
    answered = _call(transport, clock, twice)
    transport.calls[-1][2].set_result({})
    assert answered.update() is Status.SUCCEEDED  # the count starts again
    _time_out(_call(transport, clock, twice), clock)
    assert passed_over(transport, clock()) == {}
    _time_out(_call(transport, clock, twice), clock)
    assert "its last 2 call(s)" in passed_over(transport, clock())[MOTOR]
    never, never_clock = Silent(), Clock()
    _time_out(_call(never, never_clock, BreakerPolicy(timeouts=0)), never_clock)
    assert passed_over(never, never_clock()) == {}


@pytest.mark.parametrize(
    ("timeouts", "cooldown", "name"), [(-1, 30.0, "timeouts"), (1, -1.0, "cooldown"), (1, float("nan"), "cooldown")]
)
def test_an_impossible_policy_is_refused_naming_the_parameter(timeouts: int, cooldown: float, name: str) -> None:
    with pytest.raises(BreakerPolicyError, match=name) as refused:
        BreakerPolicy(timeouts, cooldown)
    assert refused.value.name == name


def test_an_actuator_is_passed_over_while_it_executes_a_call_given_up_then_for_the_cool_down() -> None:
    """The one-command rule and the breaker are one table: composition hears of both."""
    transport, clock = Silent(), Clock()
    _time_out(_call(transport, clock, exclusive=True), clock)
    assert passed_over(transport, clock())[MOTOR].startswith(f"{SERVICE} is still executing the call sent 10.5 s ago")
    refused = _call(transport, clock, exclusive=True)
    assert refused.update() is Status.FAILED and "is still executing" in refused.reason
    transport.calls[0][2].set_result({})  # the late answer frees the motor
    _taken(transport)  # its warning is logged here, not in the next test's records
    assert given_up(transport, SERVICE, clock) == ""
    assert "is passed over: its last 1 call(s)" in passed_over(transport, clock())[MOTOR]
    assert len(transport.calls) == 1


def _taken(transport: Silent) -> None:
    """Wait, 5 s at most, for the late answers given to ``transport`` to be taken: each is taken in a thread
    of its own (``breaker._watch``), which logs after ``set_result`` returns."""
    for _ in range(500):
        if not late_answers_awaited(transport):
            return
        time.sleep(0.01)


def test_an_actuators_answer_to_a_call_given_up_is_logged_when_it_comes(caplog: pytest.LogCaptureFixture) -> None:
    """The door motor opened the door after the run gave its call up: the answer was dropped in silence, and
    nobody knew that what the store believed of the door had gone stale."""
    transport, clock = Silent(), Clock()
    _time_out(_call(transport, clock, exclusive=True), clock)
    assert not [r for r in caplog.records if "given up" in r.getMessage()]  # nothing yet: it may never answer
    with caplog.at_level("WARNING", logger="cbrs.actions.remote"):
        transport.calls[0][2].set_result({"doorStatus": {"@type": "home:Opened"}})
        _taken(transport)
    (record,) = [r for r in caplog.records if "given up" in r.getMessage()]
    assert "svc:OpenDoor_DoorMotor05" in record.getMessage() and SERVICE in record.getMessage()
    assert "answered after its call was given up (no answer within 10 s)" in record.getMessage()
    assert "may be stale" in record.getMessage()


def test_a_component_registered_again_by_a_restarted_program_starts_afresh() -> None:
    transport, clock = Silent(), Clock()
    _time_out(_call(transport, clock, session="cbrs session client 1"), clock)
    assert MOTOR in passed_over(transport, clock(), {MOTOR: "cbrs session client 1"})
    assert passed_over(transport, clock(), {MOTOR: "cbrs session client 2"}) == {}
    _call(transport, clock, session="cbrs session client 2")
    assert len(transport.calls) == 2


# -- in runs -----------------------------------------------------------------------------------------

CAMERA_TTL = """
@prefix svc: <https://w3id.org/cbrs/service#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix cbrs: <https://w3id.org/cbrs/core#> .
svc:ReadRoomTemperature_{name} a cbrs:DynamicPerceptionComponent ;
    cbrs:deviceName "{name}" ; cbrs:serviceName "ReadRoomTemperature" ; cbrs:serviceCategory "EnvironmentalSensing" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "roomTemperature" ;
                         cbrs:parameterType home:RoomTemperature ] ] ;
    cbrs:hasSEAModel [ a cbrs:SEAModel ; cbrs:effectiveArea home:LivingRoom ;
        cbrs:minX 0.0 ; cbrs:maxX 6.0 ; cbrs:minY 0.0 ; cbrs:maxY 5.0 ] ;
    cbrs:hasQoSModel [ a cbrs:QoSModel ; cbrs:updateRate 1.0 ; cbrs:accuracy {accuracy} ] ;
    cbrs:hasPort [ a cbrs:ServicePort ; cbrs:portName "read" ;
        cbrs:topic "/{service}/read" ; cbrs:messageType "cbrs_msgs/RoomTemperature" ] .
"""
READING = {"roomTemperature": {"@type": "home:RoomTemperature", "celsius": 21.5}}


class Lab:
    """Two thermometers' services: ``hanging`` never answers (until the test ends its calls), the
    other answers at once."""

    def __init__(self, hanging: str) -> None:
        self.hanging = hanging
        self.answers = True  # the other one answers
        self.calls: list[str] = []
        self.open: list[Future[dict[str, Any]]] = []

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        self.calls.append(service)
        future: Future[dict[str, Any]] = Future()
        if service == self.hanging or not self.answers:
            self.open.append(future)
        else:
            future.set_result(READING)
        return future


class Room:
    """A stub environment over a transport: no simulation (only the components in another process are
    implemented: not the bundled sensor board's simulated temperature), nothing to verify, passing over
    as a simulated home does (``SimEnvironment.passed_over``)."""

    def __init__(self, kb: KnowledgeBase, transport: Any) -> None:
        self.kb = kb
        self.transport = transport
        remote = [ad for ad in kb.advertisements() if ad.bridge_port is not None]
        self.registry: Registry = implementations(kb, transport=transport, advertisements=remote)
        self.context = None

    def passed_over(self) -> dict[str, str]:
        import time

        sessions = {iri: state.registered_by for iri, state in self.kb.liveness.states().items()}
        return passed_over(self.transport, time.monotonic(), sessions)

    def given(self, plan: Plan, requirements: Mapping[str, Requirement]) -> dict[str, Any]:
        return {}

    def verify(self, step: PlanStep | None, statement: Statement, outputs: Mapping[str, Any]) -> bool | None:
        return None

    def observe(self) -> Observation:
        return Observation()

    def clock(self) -> float:
        return 0.0


FIRST, SECOND = (
    "https://w3id.org/cbrs/service#ReadRoomTemperature_Thermometer31",
    "https://w3id.org/cbrs/service#ReadRoomTemperature_Thermometer32",
)


@pytest.fixture(scope="module")
def lab_kb() -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(":memory:")
    kb.registry.register(CAMERA_TTL.format(name="Thermometer31", service="thermometer31", accuracy=0.99))
    kb.registry.register(CAMERA_TTL.format(name="Thermometer32", service="thermometer32", accuracy=0.9))
    yield kb
    kb.close()


@pytest.fixture
def quick(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CBRS_REMOTE_CALL_TIMEOUT", "0.1")


def _run(kb: KnowledgeBase, environment: Room, max_replans: int = 2) -> RunResult:
    return run_task(kb, REQ + "RoomTemperature", environment, composer=Composer(kb), max_replans=max_replans)


def test_a_later_run_is_planned_without_the_hanging_component_and_says_why(lab_kb: KnowledgeBase, quick: None) -> None:
    lab = Lab("/thermometer31/read")
    first = _run(lab_kb, Room(lab_kb, lab))
    assert first.succeeded and first.report is not None
    assert [a.component for a in first.report.steps[0].attempts] == [FIRST, SECOND]  # the timeout, the failover
    assert first.to_dict()["plan"]["passed_over"] == []
    for call in lab.open:
        call.set_exception(RuntimeError("the bridge ended the call"))
    second = _run(lab_kb, Room(lab_kb, lab))
    assert second.succeeded and second.composition.plan is not None
    assert second.composition.plan.components() == [SECOND]
    (passed,) = second.to_dict()["plan"]["passed_over"]
    assert passed["component"] == FIRST and "timed out (no answer within 0.1 s)" in passed["why"]
    assert lab.calls == ["/thermometer31/read", "/thermometer32/read", "/thermometer32/read"]


def test_a_failover_goes_only_to_alternatives_the_run_can_call(lab_kb: KnowledgeBase, quick: None) -> None:
    """The bundled sensor board also gives a room temperature, but nothing here implements it (the stub
    simulates nothing): after both thermometers timed out, the run failed over to it and failed again with
    NoImplementationError."""
    lab = Lab("/thermometer31/read")
    lab.answers = False  # both hang
    result = _run(lab_kb, Room(lab_kb, lab), max_replans=0)
    assert not result.succeeded and result.report is not None and result.composition.plan is not None
    assert result.composition.plan.steps[0].candidates == (FIRST, SECOND)
    assert [a.component for a in result.report.steps[0].attempts] == [FIRST, SECOND]
    assert "NoImplementationError" not in (result.report.reason or "")
    for call in lab.open:
        call.set_exception(RuntimeError("the bridge ended the call"))


def test_with_no_other_component_there_is_no_plan_and_the_unsatisfied_need_names_why(
    lab_kb: KnowledgeBase, quick: None
) -> None:
    lab = Lab("/thermometer31/read")
    lab.answers = False  # both hang
    assert not _run(lab_kb, Room(lab_kb, lab), max_replans=0).succeeded
    second = _run(lab_kb, Room(lab_kb, lab))
    assert second.report is None and second.composition.plan is None
    (unsatisfied,) = second.composition.unsatisfied
    why = dict(unsatisfied.unrunnable)  # the sensor board has no implementation here: it says so too
    assert "is passed over" in why[FIRST] and "is passed over" in why[SECOND]
    assert f"{SECOND.split('#')[1]} was planned for it but cannot run here" in unsatisfied.text()
    # what the task asks for is named as its output, and not proposed as an input it could give
    assert unsatisfied.text().startswith("no component provides output roomTemperature (home:RoomTemperature) of")
    assert "as an input" not in unsatisfied.remedy()
    assert {p["component"] for p in second.to_dict()["plan"]["passed_over"]} == {FIRST, SECOND}
    assert lab.calls == ["/thermometer31/read", "/thermometer32/read"]  # each waited for once


def test_a_hanging_sdk_handler_stays_available_and_is_passed_over_without_a_second_wait(
    server: Server, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The scenario of the report: a handler that hangs while its SDK keeps beating (loopback)."""
    monkeypatch.setenv("CBRS_REMOTE_CALL_TIMEOUT", "0.1")
    kb = server.kb
    release = threading.Event()
    calls: list[dict[str, Any]] = []

    def hang(request: dict[str, Any]) -> dict[str, Any]:
        calls.append(request)
        release.wait(5.0)
        return READING

    try:
        with sdk_thermometer(hang).connect(url(server), TOKEN), BridgeClient(url(server), TOKEN) as bridge:
            first = _run(kb, Room(kb, bridge))
            assert not first.succeeded and first.replans  # the re-plan passed it over: no plan
            assert len(calls) == 1  # before, each of the two re-plans called it again and waited 0.1 s
            assert kb.liveness.states()[THERMOMETER].live  # its heartbeats go on
            second = _run(kb, Room(kb, bridge))
            assert second.composition.plan is None and second.report is None
            (passed,) = second.to_dict()["plan"]["passed_over"]
            assert passed["component"] == THERMOMETER and "is passed over" in passed["why"]
            assert len(calls) == 1
    finally:
        release.set()
