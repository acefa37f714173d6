"""The eighteenth round, a component developer's (docs/components.md, "Tried by a component developer"):
a slow window-blind motor written with roslibpy and a battery gauge streaming a topic in roslibjs
(docs/examples/lab18_*), made to misbehave. These are the faults it met that were cbrs's, each pinned on
loopback, bounded, without a simulation."""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cbrs.actions.answers import StoreClasses
from cbrs.actions.belief import BeliefState, Observation
from cbrs.actions.components import Status
from cbrs.actions.remote import MAX_CALL_SECONDS, RemoteCallError, RemoteComponent
from cbrs.bridge_client import BridgeClient
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.rosbridge import Bridge, RunningBridge
from cbrs.server import Server
from tests.helpers_threads import assert_threads_end
from tests.test_failed_step_belief import Answering
from tests.test_live_components import READING, THERMOMETER, TOKEN, live_server, thermometer, url
from tests.test_rosbridge import WAIT

BLIND = "https://example.org/lab18#LowerBlind_BlindMotor01"
LOWER = "/lab18_blind_motor_01/lower"
LAB18, HOME = "https://example.org/lab18#", PREFIXES["home"]
RAISE = LAB18 + "RaiseBlind_BlindMotor01"
BLIND_THING = {"@id": LAB18 + "SouthWindowBlind", "@type": LAB18 + "WindowBlind"}
EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"


@pytest.fixture
def live() -> Iterator[Server]:
    with live_server() as running:
        yield running


@pytest.fixture
def bridge() -> Iterator[RunningBridge]:
    threads = threading.active_count()
    running = Bridge(call_timeout=WAIT).start(port=0)
    yield running
    assert running.stop(timeout=5.0)
    assert_threads_end(threads, WAIT)


@pytest.mark.parametrize("stated", [1e308, math.inf, 1e13], ids=["1e308", "inf", "1e13"])
def test_a_mistyped_response_time_is_waited_a_day_and_its_call_is_answered(
    bridge: RunningBridge, stated: float, caplog: pytest.LogCaptureFixture
) -> None:
    """A description stating cbrs:responseTime 1e308 (1e3 mistyped) gets three times that a call: before,
    the call failed at once "OverflowError: timestamp out of range for platform time_t" (the bridge
    refused the timeout "not inf"), though the motor was there to answer. Now it is waited for a day,
    and the warning names it."""
    with BridgeClient(bridge.url) as provider, BridgeClient(bridge.url) as caller:
        answered = threading.Event()

        def lower(args: dict[str, object]) -> dict[str, object]:
            answered.set()
            return {"blindStatus": {"@type": "https://example.org/lab18#Lowered"}}

        provider.advertise(LOWER, "lab18_msgs/MoveBlind", lower)
        component = RemoteComponent(
            BLIND, caller, LOWER, {"blindStatus": "https://w3id.org/cbrs/home#DeviceStatus"}, timeout=3 * stated
        )
        component.begin({"blind": {"@id": "https://example.org/lab18#SouthWindowBlind"}})
        for _ in range(200):  # each tick returns once the answer is in
            status = component.update()
            if status is not Status.RUNNING:
                break
        assert status is Status.SUCCEEDED, component.reason
        assert answered.is_set()
        assert component.outputs["blindStatus"] == {"@type": "https://example.org/lab18#Lowered"}
    assert component.timeout == MAX_CALL_SECONDS
    assert f"{BLIND} ({LOWER}) would be waited for" in caplog.text and "more than a day" in caplog.text


def test_a_call_in_flight_fails_when_its_component_is_deregistered(live: Server) -> None:
    """`cbrs deregister` of the blind's raise while the motor ran: the call went on, the motor's answer
    was taken and the run succeeded with the blind believed raised, though the run's own log said "did a
    step but is no longer described: its effects are not believed". Someone removed it on purpose, as a
    lease that lapses is the server giving up on it: the calls waiting on it fail at once, saying so."""
    release = threading.Event()

    def stuck(request: dict[str, Any]) -> dict[str, Any]:
        release.wait(10.0)  # the motor still running
        return READING

    with BridgeClient(url(live), TOKEN) as component, BridgeClient(url(live), TOKEN) as caller:
        component.provide("/thermometer07/read", "cbrs_msgs/RoomTemperature", stuck)
        registered = component.call_sync("/cbrs/register", {"description": thermometer(), "ttl": 1.0})
        assert registered["components"] == [THERMOMETER]
        call = caller.call("/thermometer07/read", {}, timeout=20.0)
        try:
            with live.sparql.lock:
                live.kb.registry.deregister(THERMOMETER)
            for _ in range(40):  # beats, until one past half the lease writes the store and finds it gone
                if call.done():
                    break
                component.call("/cbrs/heartbeat", {}, timeout=5.0)
                time.sleep(0.1)
            with pytest.raises(RemoteCallError, match="was deregistered while '/thermometer07/read' was executing"):
                call.result(timeout=2.0)  # well before the call's own 20 s
        finally:
            release.set()


def test_a_failed_call_of_a_component_deregistered_meanwhile_still_unsettles_its_effects() -> None:
    """The blind's raise deregistered mid-motion: its call failed (the test above), and the belief was to
    become unknown, since the motor may have moved, but the store no longer described the component: "what
    it may have done could not be marked unknown (no service description ...): the belief may be stale".
    The call knows what it would set (the advertisement it was made from), and that is what is unsettled."""

    kb = KnowledgeBase.open(":memory:")
    try:
        for graph in ("ontology", "map"):
            kb.load([EXAMPLES / "lab18_window_blind.ttl"], graph=graph)
        kb.registry.register((EXAMPLES / "lab18_blind_motor.ttl").read_text(encoding="utf-8"))
        effects = kb.description(RAISE).effects
        kb.registry.deregister(RAISE)  # by `cbrs deregister`, while the motor ran
        BeliefState(kb).write(
            Observation(facts=frozenset({(BLIND_THING["@id"], HOME + "hasStatus", LAB18 + "Lowered")})), whole=True
        )
        classes = StoreClasses(kb)
        transport = Answering(
            RemoteCallError("<…> was deregistered while '/lab18_blind_motor_01/raise' was executing the call")
        )
        component = RemoteComponent(
            RAISE,
            transport,
            "/lab18_blind_motor_01/raise",
            {"blindStatus": HOME + "DeviceStatus"},
            effects=effects,
            classes=classes,
        )
        component.begin({"blind": BLIND_THING})
        assert component.update() is Status.FAILED
        status = [o for s, p, o in BeliefState(kb).facts(BLIND_THING["@id"]) if p == HOME + "hasStatus"]
        assert status == []  # it may have moved: unknown, not still lowered
    finally:
        kb.close()


def test_a_program_whose_one_component_was_deregistered_registers_both_again(live: Server) -> None:
    """The blind motor's program registers its two components in one call. After `cbrs deregister` of the
    raise, the program restarted was refused for good, "register the components coming back apart from the
    new ones": the lower was coming back, the raise new. Both are registered again, in one transaction."""
    motor = (EXAMPLES / "lab18_blind_motor.ttl").read_text(encoding="utf-8")
    with BridgeClient(url(live), TOKEN) as first:
        assert first.call_sync("/cbrs/register", {"description": motor, "ttl": 1.0})["components"] == [BLIND, RAISE]
    with live.sparql.lock:
        live.kb.registry.deregister(RAISE)
    with BridgeClient(url(live), TOKEN) as again:
        assert sorted(again.call_sync("/cbrs/register", {"description": motor, "ttl": 1.0})["components"]) == [
            BLIND,
            RAISE,
        ]
        states = live.kb.liveness.states()
        assert states[BLIND].live and states[RAISE].live
