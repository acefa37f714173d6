"""How long a remote call may take, and what a run does with an actuator's call it gave up on: the
timeout comes from the advertisement's cbrs:responseTime (three times it) or the remote_call_timeout
setting, has one reason however it ends, and no new command goes to an actuator still executing one."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from typing import Any

import pytest

from cbrs.actions.components import Status
from cbrs.actions.remote import LATE_WINDOW, MAX_POLLS, RemoteComponent, given_up
from cbrs.kb import KnowledgeBase
from cbrs.kb.model import QoSValue
from cbrs.kb.vocab import CBRS
from cbrs.sim.components import RESPONSE_TIME_MARGIN, call_timeout, implementations
from tests.test_remote_call_values import MOTOR, MOTOR_TTL

SERVICE = "/door_motor_05/open"


class Silent:
    """A transport that keeps every call open until the test answers it."""

    def __init__(self) -> None:
        self.calls: list[tuple[str, float, Future[dict[str, Any]]]] = []

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        future: Future[dict[str, Any]] = Future()
        self.calls.append((service, timeout, future))
        return future


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def _motor(transport: Silent, clock: Clock, exclusive: bool = True) -> RemoteComponent:
    return RemoteComponent(MOTOR, transport, SERVICE, {}, None, 10.0, clock, exclusive=exclusive)


def _timed_out(component: RemoteComponent, clock: Clock) -> None:
    component.begin({"door": {}})
    assert component.update() is Status.RUNNING
    clock.now += 10.5
    assert component.update() is Status.FAILED


@pytest.fixture(scope="module")
def motor_kb() -> Any:
    kb = KnowledgeBase.open(":memory:")
    kb.registry.register(MOTOR_TTL)
    yield kb
    kb.close()


def test_the_timeout_is_three_times_the_stated_response_time_or_the_setting(
    motor_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    ad = next(ad for ad in motor_kb.advertisements() if ad.iri == MOTOR)
    assert [q.value for q in ad.qos if q.metric == CBRS.responseTime] == [2.0]
    monkeypatch.delenv("CBRS_REMOTE_CALL_TIMEOUT", raising=False)
    assert call_timeout(ad) == 10.0  # 3 x 2 s is less than the setting's default
    slow = dataclasses.replace(ad, qos=(QoSValue(CBRS.responseTime, 12.0), QoSValue(CBRS.availability, 0.95)))
    assert call_timeout(slow) == RESPONSE_TIME_MARGIN * 12.0 == 36.0
    assert call_timeout(dataclasses.replace(ad, qos=())) == 10.0
    monkeypatch.setenv("CBRS_REMOTE_CALL_TIMEOUT", "25")
    assert call_timeout(ad) == 25.0 and call_timeout(slow) == 36.0
    monkeypatch.setenv("CBRS_REMOTE_CALL_TIMEOUT", "-1")
    with pytest.raises(ValueError, match="CBRS_REMOTE_CALL_TIMEOUT"):
        call_timeout(ad)


def test_a_run_invokes_an_actuator_with_its_timeout_one_call_at_a_time(
    motor_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("CBRS_REMOTE_CALL_TIMEOUT", "4")
    component = implementations(motor_kb, transport=Silent())(MOTOR)
    assert isinstance(component, RemoteComponent)
    assert (component.timeout, component.exclusive) == (6.0, True)  # 3 x 2 s; a PhysicalManipulationComponent


def test_the_transport_is_given_longer_so_a_timeout_has_one_reason() -> None:
    transport, clock = Silent(), Clock()
    component = _motor(transport, clock)
    _timed_out(component, clock)
    assert component.reason == f"{SERVICE} did not answer within 10 s"
    assert transport.calls[0][1] == 10.0 * LATE_WINDOW


def test_an_actuator_still_executing_a_call_given_up_gets_no_new_one_until_it_answers() -> None:
    transport, clock = Silent(), Clock()
    _timed_out(_motor(transport, clock), clock)
    clock.now += 1.0
    again = _motor(transport, clock)  # a re-plan's fresh instance
    again.begin({"door": {}})
    assert again.update() is Status.FAILED
    assert again.reason.startswith(f"{SERVICE} is still executing the call sent 11.5 s ago, given up after 10 s")
    assert len(transport.calls) == 1  # nothing was sent
    transport.calls[0][2].set_result({"doorStatus": {"@type": "home:Opened"}})  # the late answer
    assert given_up(transport, SERVICE, clock) == ""
    again.begin({"door": {}})
    assert len(transport.calls) == 2 and again.update() is Status.RUNNING


def test_a_call_the_transport_ended_frees_the_actuator_and_other_services_and_transports_are_not_held() -> None:
    transport, clock = Silent(), Clock()
    _timed_out(_motor(transport, clock), clock)
    other = RemoteComponent(MOTOR, transport, "/door_motor_06/open", {}, None, 10.0, clock, exclusive=True)
    other.begin({})
    elsewhere = Silent()
    _motor(elsewhere, clock).begin({})
    assert len(transport.calls) == 2 and len(elsewhere.calls) == 1
    transport.calls[0][2].set_exception(RuntimeError("service did not answer within 20 s"))  # the bridge's end
    _motor(transport, clock).begin({})
    assert len(transport.calls) == 3


def test_a_sensor_is_called_again_at_once() -> None:
    transport, clock = Silent(), Clock()
    _timed_out(_motor(transport, clock, exclusive=False), clock)
    again = _motor(transport, clock, exclusive=False)
    again.begin({})
    assert len(transport.calls) == 2 and again.update() is Status.RUNNING


def test_a_long_timeout_is_spread_over_a_bounded_number_of_ticks() -> None:
    """The executor bounds a step's ticks (10,000 by default): a 60 s call must not need more than
    MAX_POLLS of them, each waiting its share of the timeout for the answer."""
    clock = Clock()

    class Waited(Future[dict[str, Any]]):
        """Never answers; each wait for it passes on the clock at once."""

        def result(self, timeout: float | None = None) -> dict[str, Any]:
            assert timeout is not None
            clock.now += timeout
            raise FutureTimeout

    class Never:
        def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
            return Waited()

    component = RemoteComponent(MOTOR, Never(), SERVICE, {}, None, 60.0, clock)
    component.begin({})
    ticks = 1
    while component.update() is Status.RUNNING:
        ticks += 1
    assert ticks <= MAX_POLLS + 1
    assert component.reason == f"{SERVICE} did not answer within 60 s"
