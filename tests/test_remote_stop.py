"""A Stop while a remote component's call is out ends the run's wait for it, not the call's end.

A Stop was asked only when a step's attempt ended, so a run stopped during a lamp plug's switch-on waited
for the plug's answer (up to the call's timeout, 3 x cbrs:responseTime, at least 10 s; a day at most). Now
the wait ends at once: the run is cancelled, what the call would set is unknown (the plug may act on it),
and its answer, when it comes, is dropped. A real loopback bridge, a provider whose handler is held until
the test lets it answer, bounded waits throughout."""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest

from cbrs.actions.belief import BeliefState, Observation
from cbrs.actions.executor import RunStatus
from cbrs.actions.remote import MAX_CALL_SECONDS, RemoteComponent, given_up
from cbrs.actions.runner import RunResult, run_task
from cbrs.bridge_client import BridgeClient
from cbrs.kb import KnowledgeBase
from cbrs.rosbridge import Bridge, RunningBridge
from tests.test_failed_step_belief import ANSWERED_ON, IS_OFF, LAB10, LivingRoom, _status, kb  # noqa: F401
from tests.test_remote_call_timeout import Silent

SWITCH_ON = "/lab10_lamp_plug_01/switch_on"
HELD = 30.0  # the longest the plug's handler is held: far past every wait of the test


@pytest.fixture
def bridge() -> Iterator[RunningBridge]:
    running = Bridge(call_timeout=HELD).start(port=0)
    yield running
    assert running.stop(timeout=5.0)


def test_a_stop_during_a_remote_call_ends_the_run_at_once_and_drops_the_late_answer(
    kb: KnowledgeBase,  # noqa: F811
    bridge: RunningBridge,
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
) -> None:
    monkeypatch.setenv("CBRS_REMOTE_CALL_TIMEOUT", "600")  # a tick waits 0.6 s: longer than a Stop may take
    caplog.set_level(logging.INFO, logger="cbrs.actions.remote")
    BeliefState(kb).write(Observation(facts=frozenset({IS_OFF})), whole=True)
    called, release = threading.Event(), threading.Event()

    def switch_on(args: dict[str, Any]) -> dict[str, Any]:
        called.set()
        release.wait(HELD)  # the plug still switching
        return ANSWERED_ON

    stop = threading.Event()
    ran: list[RunResult] = []
    with BridgeClient(bridge.url) as plug, BridgeClient(bridge.url) as caller:
        plug.advertise(SWITCH_ON, "lab10_msgs/Switch", switch_on)
        room = LivingRoom(kb, caller)  # type: ignore[arg-type]  # a transport as a run's bridge client is
        run = threading.Thread(
            target=lambda: ran.append(
                run_task(kb, LAB10 + "SwitchOnTheReadingLamp", room, cancelled=stop.is_set, max_replans=0)
            ),
            daemon=True,
        )
        try:
            run.start()
            assert called.wait(10.0), "the plug was never called"
            stop.set()
            run.join(10.0)  # the plug answers only when released, after this
            assert not run.is_alive(), "the run waited for the plug's answer"
            (result,) = ran
            report = result.report
            assert report is not None and report.status is RunStatus.CANCELLED
            assert report.reason == "cancelled on request after 0 of 1 steps; the remote call under way was abandoned"
            (step,) = report.steps
            assert step.outcome == "cancelled" and [a.outcome for a in step.attempts] == ["cancelled"]
            assert not result.replans
            assert _status(kb) == []  # switched on, or half, or not: unknown, not still believed off
            assert given_up(caller, SWITCH_ON)  # an actuator still executing: no new call goes to it
        finally:
            release.set()
            run.join(10.0)
        for _ in range(200):  # bounded: until the plug's answer has come and been dropped
            if not given_up(caller, SWITCH_ON) and "dropped" in caplog.text:
                break
            time.sleep(0.05)
        assert not given_up(caller, SWITCH_ON)
        assert "answered after the run that called it was stopped: dropped" in caplog.text
        assert _status(kb) == []  # the late "on" is not believed


def test_a_tick_of_a_days_call_ends_within_a_stop_poll_of_a_stop_and_a_sensors_answer_is_dropped(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """A call given a day (MAX_CALL_SECONDS) waits 86 s a tick; a Stop asked from another thread ends the
    tick's wait, and the halt that follows drops the answer of a component that does not act."""
    caplog.set_level(logging.INFO, logger="cbrs.actions.remote")
    transport = Silent()
    sensor = RemoteComponent(LAB10 + "Thermometer", transport, "/thermometer/read", {}, timeout=MAX_CALL_SECONDS)
    stop = threading.Event()
    sensor.stop_asked = stop.is_set
    sensor.begin({})
    assert sensor.waiting()
    threading.Timer(0.3, stop.set).start()
    ticked = threading.Thread(target=sensor.update, daemon=True)
    ticked.start()
    ticked.join(10.0)  # 86 s without the Stop
    assert not ticked.is_alive() and sensor.waiting()
    sensor.halt()
    ((_, _, pending),) = transport.calls
    pending.set_result({"celsius": 21.5})
    assert "(/thermometer/read) answered after the run that called it was stopped: dropped" in caplog.text
    assert sensor.outputs == {} and not given_up(transport, "/thermometer/read")
