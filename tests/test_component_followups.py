"""What the eighteenth round (a lab's developer writing components without the SDK, docs/components.md's
"Tried by a component developer") left, fixed: a live component's answer over the bridge, and a Stop
during a call to a slow one. One server for the module, on loopback ports; raw programs write the frames
roslibpy and buggy clients send."""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any

import pytest

from cbrs.actions.remote import RemoteCallError
from cbrs.bridge_client import BridgeClient
from cbrs.kb import KnowledgeBase
from cbrs.rosbridge import Bridge, RunningBridge
from cbrs.server import Server
from tests.test_live_components import READING, THERMOMETER, TOKEN, live_server, thermometer, url
from tests.test_remote_trial_bridge import WAIT, Raw


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    with live_server() as running:
        yield running


def registered(server: Server, service: str, device: str) -> Raw:
    """A raw program that registered a thermometer named ``device`` and advertised ``service``."""
    description = thermometer(service).replace("Thermometer07", device)
    program = Raw(url(server))
    program.send({"op": "auth", "mac": TOKEN})
    program.send({"op": "call_service", "service": "/cbrs/register", "id": "r", "args": {"description": description}})
    assert program.expect("service_response", id="r")["result"] is True
    program.send({"op": "advertise_service", "service": service, "type": "cbrs_msgs/RoomTemperature"})
    synced(program)
    return program


def synced(program: Raw) -> None:
    """Wait until the bridge has read what ``program`` sent before (a call of its own answered)."""
    program.send({"op": "call_service", "service": "/rosapi/get_time", "id": "sync"})
    program.expect("service_response", id="sync")


def answer_text(call: dict[str, Any], values: Any, service: str | None = None) -> str:
    """A service_response as roslibpy writes it: Python's json.dumps, NaN and infinities as tokens."""
    message = {"op": "service_response", "service": service or call["service"], "id": call["id"]}
    return json.dumps({**message, "result": True, "values": values})


@pytest.mark.parametrize(
    ("values", "where"),
    [
        pytest.param({"percent": float("nan")}, "field 'percent' is NaN", id="nan"),
        pytest.param({"r": {"ranges": [1.0, float("-inf")]}}, "field 'r.ranges[1]' is -Infinity", id="nested"),
    ],
)
def test_a_live_components_non_finite_answer_fails_the_call_naming_the_field(
    server: Server, values: dict[str, Any], where: str
) -> None:
    """roslibpy sends a NaN as the token; the bridge writes it to JSON callers as null, so a broken
    reading was taken for a missing one and the run succeeded with {"percent": null}."""
    program = registered(server, "/followup01/read", "Thermometer81")
    try:
        with BridgeClient(url(server), TOKEN) as caller:
            answer = caller.call("/followup01/read", {}, timeout=10)
            program.send(answer_text(program.expect("call_service"), values))
            with pytest.raises(RemoteCallError, match="answered values that are not JSON") as failed:
                answer.result(timeout=WAIT)
            assert where in str(failed.value) and "'/followup01/read'" in str(failed.value)
    finally:
        program.close()


@pytest.fixture(scope="module")
def bridge() -> Iterator[RunningBridge]:
    with Bridge().start(port=0) as running:
        yield running


def test_another_services_non_finite_answer_still_reaches_its_caller_as_null(bridge: RunningBridge) -> None:
    """Only a live component's service is held to finite numbers: a ROS client's scan keeps its
    rosbridge_suite meaning (null for a float JSON cannot hold)."""
    provider, caller = Raw(bridge.url), Raw(bridge.url)
    try:
        provider.send({"op": "advertise_service", "service": "/scan/read", "type": "x/Y"})
        synced(provider)
        caller.send({"op": "call_service", "service": "/scan/read", "id": "c"})
        provider.send(answer_text(provider.expect("call_service"), {"range": float("inf")}))
        answer = caller.expect("service_response", id="c")
        assert answer["result"] is True and answer["values"] == {"range": None}
    finally:
        provider.close()
        caller.close()


def test_an_answer_naming_another_service_is_dropped_and_the_call_waits_for_its_own(
    bridge: RunningBridge, caplog: pytest.LogCaptureFixture
) -> None:
    """A motor providing lower and raise answered a lower call with raise's name: it was taken as the
    lower's answer; rosbridge_suite looks the id up under the service named and drops it."""
    provider, caller = Raw(bridge.url), Raw(bridge.url)
    try:
        for service in ("/motor/lower", "/motor/raise"):
            provider.send({"op": "advertise_service", "service": service, "type": "x/Y"})
        synced(provider)
        caller.send({"op": "call_service", "service": "/motor/lower", "id": "c"})
        call = provider.expect("call_service")
        with caplog.at_level("WARNING", logger="cbrs.rosbridge"):
            provider.send(answer_text(call, {"by": "raise"}, service="/motor/raise"))
            refused = provider.expect("status", level="error")
        assert "names '/motor/raise', but its id" in refused["msg"] and "'/motor/lower'" in refused["msg"]
        assert any("/motor/lower" in r.getMessage() and "/motor/raise" in r.getMessage() for r in caplog.records)
        unread = {"op": "service_response", "service": "/motor/raise", "id": call["id"], "result": "yes"}
        provider.send(unread)  # nor does one that cannot be read fail the call it does not answer
        assert "'result' must be a boolean" in provider.expect("status", level="error")["msg"]
        provider.send(answer_text(call, {"by": "lower"}, service="motor/lower"))  # a relative name is the same
        answer = caller.expect("service_response", id="c")
        assert answer["result"] is True and answer["values"] == {"by": "lower"}, answer
    finally:
        provider.close()
        caller.close()


def test_a_call_fails_at_once_when_its_component_is_deregistered_through_the_endpoint(server: Server) -> None:
    """`cbrs deregister` (a SPARQL update through the server) was noticed only at the lease's next store
    write, half a lease and a beat later (6.7 s for the lab's motor), and an answer that came first was
    taken. The server's watchdog now looks at each store write: the call fails long before that write."""
    description = thermometer("/followup02/read").replace("Thermometer07", "Thermometer82")
    iri = THERMOMETER.replace("Thermometer07", "Thermometer82")
    program = Raw(url(server))
    store = KnowledgeBase.open(f"http://127.0.0.1:{server.http_port}", remote_token=TOKEN)
    try:
        program.send({"op": "auth", "mac": TOKEN})
        args = {"description": description, "ttl": 600.0}  # no store write of its lease within the test
        program.send({"op": "call_service", "service": "/cbrs/register", "id": "r", "args": args})
        assert program.expect("service_response", id="r")["result"] is True
        program.send({"op": "advertise_service", "service": "/followup02/read", "type": "cbrs_msgs/RoomTemperature"})
        synced(program)
        with BridgeClient(url(server), TOKEN) as caller:
            answer = caller.call("/followup02/read", {}, timeout=60)
            call = program.expect("call_service")
            assert store.registry.deregister(iri) > 0  # as `cbrs deregister --store URL` does
            with pytest.raises(RemoteCallError, match="was deregistered while '/followup02/read' was executing"):
                answer.result(timeout=WAIT)  # no heartbeat meanwhile: the watchdog noticed the update
            program.send(answer_text(call, READING))  # the motor's answer, after: it acts for nobody
            assert "no call with id" in program.expect("status", level="error")["msg"]
        assert iri not in server.live.live()
    finally:
        store.close()
        program.close()
