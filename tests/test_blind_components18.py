"""The eighteenth round, a component developer's (docs/components.md, "Tried by a component developer"):
a slow window-blind motor written with roslibpy and a battery gauge streaming a topic in roslibjs
(docs/examples/lab18_*), made to misbehave. These are the faults it met that were cbrs's, each pinned on
loopback, bounded, without a simulation."""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator

import pytest

from cbrs.actions.components import Status
from cbrs.actions.remote import MAX_CALL_SECONDS, RemoteComponent
from cbrs.bridge_client import BridgeClient
from cbrs.rosbridge import Bridge, RunningBridge
from tests.helpers_threads import assert_threads_end
from tests.test_rosbridge import WAIT

BLIND = "https://example.org/lab18#LowerBlind_BlindMotor01"
LOWER = "/lab18_blind_motor_01/lower"


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
