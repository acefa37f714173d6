"""What a buggy remote component or caller does to the bridge, found by writing components from the docs
alone (roslibpy, roslibjs, a raw websocket): each mistake is answered at once, naming it, and harms no
other client. Loopback only; every wait is bounded."""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from contextlib import ExitStack
from typing import Any

import pyoxigraph as ox
import pytest
from websockets.sync.client import ClientConnection, connect

from cbrs.actions.remote import RemoteCallError
from cbrs.bridge_client import BridgeClient
from cbrs.component import Component, ComponentEndedError
from cbrs.kb.errors import InvalidDescriptionError
from cbrs.live_components import NO_LIVE_COMPONENT
from cbrs.rosbridge import Bridge, RunningBridge
from cbrs.rosbridge.protocol import LEADING_CHARS, leading_fields
from cbrs.server import Server
from tests.test_live_components import READING, THERMOMETER, TOKEN, eventually, live_server, thermometer, url

WAIT = 5.0
LIMIT = 4096  # the test bridge's max_message_bytes: a "huge" message is small here


class Raw:
    """A websocket client that writes frames as they are, to send what a buggy client sends."""

    def __init__(self, url: str) -> None:
        self._stack = ExitStack()
        self.ws: ClientConnection = self._stack.enter_context(connect(url, max_size=None, open_timeout=WAIT))

    def send(self, message: dict[str, Any] | str) -> None:
        self.ws.send(message if isinstance(message, str) else json.dumps(message))

    def expect(self, op: str, **fields: Any) -> dict[str, Any]:
        """The next message of ``op`` (whose ``fields`` have those values), skipping others; bounded."""
        for _ in range(50):
            message = json.loads(self.ws.recv(timeout=WAIT))
            if message["op"] == op and all(message.get(k) == v for k, v in fields.items()):
                return dict(message)
        raise AssertionError(f"no {op} {fields} among 50 messages")

    def nothing(self, op: str, wait: float = 0.3) -> None:
        """No message of ``op`` comes within ``wait`` seconds (others may)."""
        while True:
            try:
                message = json.loads(self.ws.recv(timeout=wait))
            except TimeoutError:
                return
            assert message["op"] != op, message

    def close(self) -> None:
        self._stack.close()


@pytest.fixture(scope="module")
def bridge() -> Iterator[RunningBridge]:
    with Bridge(max_message_bytes=LIMIT).start(port=0) as running:
        yield running


def test_leading_fields_reads_only_the_top_level_before_the_first_nested_value() -> None:
    head = '{"op": "call_service", "id": 7, "service": "/a", "args": {"id": "inner"}, "x": '
    assert leading_fields(head + '"' + "y" * 10_000) == {"op": "call_service", "id": 7, "service": "/a"}
    assert leading_fields('{"args": {"id": "inner"}, "op": "call_service", "id": "late"}') == {}
    assert leading_fields('{"op": "call_service", "service": "a\\"b", "id": "q", oops') == {
        "op": "call_service",
        "service": 'a"b',
        "id": "q",
    }
    assert leading_fields("[1, 2]") == leading_fields("not json") == {}
    # only the head is looked at, whatever the message's size: a member past it is not read
    late = '{"op": "call_service", "pad": "' + "x" * LEADING_CHARS + '", "id": "late"}'
    assert leading_fields(late) == {"op": "call_service"}


@pytest.mark.parametrize(
    ("frame", "reason"),
    [
        pytest.param(
            json.dumps({"op": "call_service", "id": "big", "service": "/cbrs/register", "args": {"d": "x" * LIMIT}}),
            f"exceeds the limit of {LIMIT} bytes",
            id="too-large",
        ),
        pytest.param(
            '{"op": "call_service", "id": "big", "service": "/cbrs/register", "args": {"d": oops}}',
            "not valid JSON",
            id="not-json-after-its-head",
        ),
        pytest.param(
            '{"op": "call_service", "id": "big", "service": 5}', "field 'service' must be a string", id="bad-field"
        ),
    ],
)
def test_a_call_that_cannot_be_read_is_answered_failed_by_its_id(
    bridge: RunningBridge, frame: str, reason: str
) -> None:
    """roslibjs's callService waits for its answer without a timeout: a call the bridge refuses gets one,
    not only a status message, which roslibjs does not read."""
    caller = Raw(bridge.url)
    try:
        caller.send(frame)
        assert reason in caller.expect("status", id="big")["msg"]  # the status carries the id it found
        answer = caller.expect("service_response", id="big")
        assert answer["result"] is False
        assert reason in answer["values"]
    finally:
        caller.close()


def test_a_call_whose_id_comes_only_after_its_args_gets_no_answer_in_its_name(bridge: RunningBridge) -> None:
    caller = Raw(bridge.url)
    try:
        caller.send('{"op": "call_service", "service": "/a", "args": {"id": "inner", "d": "' + "x" * LIMIT + '"}}')
        assert "exceeds the limit" in caller.expect("status")["msg"]
        caller.nothing("service_response")
    finally:
        caller.close()


def test_an_answer_without_an_id_fails_the_one_call_it_can_be_for_at_once(bridge: RunningBridge) -> None:
    provider, caller = Raw(bridge.url), Raw(bridge.url)
    try:
        provider.send({"op": "advertise_service", "service": "/trial/read", "type": "lab_msgs/Read"})
        provider.send({"op": "call_service", "service": "/rosapi/get_time", "id": "sync"})
        provider.expect("service_response", id="sync")  # the advertisement is in
        caller.send({"op": "call_service", "service": "/trial/read", "id": "c1", "timeout": 60})
        call = provider.expect("call_service")
        provider.send({"op": "service_response", "service": call["service"], "result": True, "values": {}})
        status = provider.expect("status")
        assert "missing field 'id'" in status["msg"] and "the one call of /trial/read" in status["msg"]
        answer = caller.expect("service_response", id="c1")  # at once, not after its 60 s
        assert answer["result"] is False and "it has no 'id'" in answer["values"]
    finally:
        provider.close()
        caller.close()


def test_an_answer_without_an_id_fails_no_call_when_several_wait(bridge: RunningBridge) -> None:
    provider, caller = Raw(bridge.url), Raw(bridge.url)
    try:
        provider.send({"op": "advertise_service", "service": "/trial/two", "type": "lab_msgs/Read"})
        provider.send({"op": "call_service", "service": "/rosapi/get_time", "id": "sync"})
        provider.expect("service_response", id="sync")
        for key in ("a", "b"):
            caller.send({"op": "call_service", "service": "/trial/two", "id": key, "timeout": 60})
        calls = [provider.expect("call_service"), provider.expect("call_service")]
        provider.send({"op": "service_response", "service": "/trial/two", "result": True, "values": {}})
        assert "missing field 'id'" in provider.expect("status")["msg"]
        caller.nothing("service_response")
        for call, value in zip(calls, (1, 2), strict=True):
            provider.send(
                {
                    "op": "service_response",
                    "service": "/trial/two",
                    "id": call["id"],
                    "result": True,
                    "values": {"n": value},
                }
            )
        assert caller.expect("service_response", id="a")["values"] == {"n": 1}
        assert caller.expect("service_response", id="b")["values"] == {"n": 2}
    finally:
        provider.close()
        caller.close()


def test_an_answer_without_result_says_what_roslibjs_users_forgot(bridge: RunningBridge) -> None:
    """roslibjs's advertise callback must return true: one that returns nothing sends no result."""
    provider, caller = Raw(bridge.url), Raw(bridge.url)
    try:
        provider.send({"op": "advertise_service", "service": "/trial/noreturn", "type": "x/Y"})
        provider.send({"op": "call_service", "service": "/rosapi/get_time", "id": "sync"})
        provider.expect("service_response", id="sync")
        caller.send({"op": "call_service", "service": "/trial/noreturn", "id": "c", "timeout": 60})
        call = provider.expect("call_service")
        provider.send({"op": "service_response", "service": call["service"], "id": call["id"]})
        answer = caller.expect("service_response", id="c")
        assert answer["result"] is False
        assert "missing required field 'result' (roslibjs sends none when an advertise callback" in answer["values"]
    finally:
        provider.close()
        caller.close()


# -- through cbrs serve: a live component's service, and /cbrs/register's fields -----------------------


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    with live_server() as running:
        yield running


@pytest.mark.parametrize("authorised", [True, False], ids=["authorised", "anonymous"])
def test_another_client_cannot_take_the_service_a_live_component_holds(server: Server, authorised: bool) -> None:
    """The bridge lets a client take a service over from another (as rosbridge_suite does); a live
    component's service is kept for the program that registered it, else any page or script on the
    bridge would answer the plan's calls in its place."""
    component = Component(thermometer())
    component.handler(lambda request: {**READING, "by": "the thermometer"})
    with component.connect(url(server), TOKEN):
        intruder = Raw(url(server))
        try:
            if authorised:
                intruder.send({"op": "auth", "mac": TOKEN})
            intruder.send({"op": "advertise_service", "service": "thermometer07/read", "type": "x/Y", "id": "a"})
            refused = intruder.expect("status", id="a")
            assert refused["level"] == "error"
            assert f"held by the live component <{THERMOMETER}>" in refused["msg"]
            with BridgeClient(url(server), TOKEN) as caller:
                assert caller.call_sync("/thermometer07/read", {})["by"] == "the thermometer"
        finally:
            intruder.close()
    assert eventually(lambda: server.live.holder("/thermometer07/read", "anyone") is None)  # its program gone


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        pytest.param({"description": "x", "tll": 10}, "takes no field 'tll'", id="misspelt-field"),
        pytest.param({"description": 5}, "field 'description' must be the description as text", id="not-text"),
        pytest.param({}, "missing field 'description'", id="missing"),
        pytest.param({"description": " \n"}, "it is empty: send the description's text", id="empty"),
    ],
)
def test_a_registration_with_a_wrong_field_is_refused_naming_it(
    server: Server, args: dict[str, Any], reason: str
) -> None:
    with BridgeClient(url(server), TOKEN) as client, pytest.raises(RemoteCallError, match=reason) as refused:
        client.call_sync("/cbrs/register", args)
    if "tll" in args:
        assert "did you mean 'ttl'?" in str(refused.value)


def test_a_registration_too_large_to_read_is_refused_at_once(server: Server) -> None:
    with BridgeClient(url(server), TOKEN) as client, pytest.raises(RemoteCallError, match="exceeds the limit"):
        client.call_sync("/cbrs/register", {"description": "#" * (2 << 20)}, timeout=30)


def test_registering_without_the_token_says_how_to_send_it(server: Server) -> None:
    with BridgeClient(url(server)) as client, pytest.raises(RemoteCallError, match="call it before run"):
        client.call_sync("/cbrs/register", {"description": thermometer()})


def test_a_component_whose_program_answers_another_service_than_it_registered_is_made_unavailable(
    server: Server,
) -> None:
    """A misspelt service name (the description says /trial07/read, the program advertises /trial_07/read):
    every call of a plan would fail 'does not exist', so at the lease's first store write it is unavailable,
    and its heartbeat says what to fix rather than 'register again', which would not help."""
    description = thermometer("/trial07/read").replace("Thermometer07", "Thermometer77")
    iri = THERMOMETER.replace("Thermometer07", "Thermometer77")
    with BridgeClient(url(server), TOKEN) as program:
        program.call_sync("/cbrs/register", {"description": description, "ttl": 1.0})
        program.provide("/trial_07/read", "cbrs_msgs/RoomTemperature", lambda request: READING)
        answers: list[str] = []
        for _ in range(40):  # a heartbeat every 0.1 s, 4 s at most
            try:
                program.call_sync("/cbrs/heartbeat", {})
            except RemoteCallError as error:
                answers.append(str(error))
                break
            time.sleep(0.1)
        assert answers, "the heartbeat kept the component available"
        assert "no bridge client provides its service /trial07/read" in answers[0]
        assert "advertise the service its cbrs:topic names" in answers[0]
        assert NO_LIVE_COMPONENT not in answers[0]  # the SDK would register again, to no avail
        state = server.kb.liveness.states()[iri]
        assert not state.live and "/trial07/read" in (state.reason or "")


def test_a_live_components_result_false_fails_the_call_though_it_sent_an_object(server: Server) -> None:
    """roslibpy answers a handler's ``return False`` with ``values: {}``, which rosbridge_suite (and the
    bridge, for any other service) takes as the answer: a door motor with no outputs would have opened."""
    description = thermometer("/trial08/read").replace("Thermometer07", "Thermometer78")
    program = Raw(url(server))
    try:
        program.send({"op": "auth", "mac": TOKEN})
        program.send(
            {"op": "call_service", "service": "/cbrs/register", "id": "r", "args": {"description": description}}
        )
        assert program.expect("service_response", id="r")["result"] is True
        program.send({"op": "advertise_service", "service": "/trial08/read", "type": "cbrs_msgs/RoomTemperature"})
        with BridgeClient(url(server), TOKEN) as caller:
            answer = caller.call("/trial08/read", {}, timeout=10)
            call = program.expect("call_service")
            program.send(
                {"op": "service_response", "service": call["service"], "id": call["id"], "result": False, "values": {}}
            )
            with pytest.raises(RemoteCallError, match="'/trial08/read' answered result: false"):
                answer.result(timeout=WAIT)
    finally:
        program.close()


@pytest.mark.parametrize(
    ("fmt", "as_json", "reason"),
    [
        pytest.param("turtle", True, "it reads as json-ld, not turtle", id="json-ld-sent-as-turtle"),
        pytest.param("json-ld", False, "it reads as turtle, not json-ld", id="turtle-sent-as-json-ld"),
    ],
)
def test_a_description_sent_as_the_other_format_is_refused_saying_so(
    server: Server, fmt: str, as_json: bool, reason: str
) -> None:
    text = thermometer("/trial09/read").replace("Thermometer07", "Thermometer79")
    if as_json:
        text = ox.serialize(list(ox.parse(text.encode(), format=ox.RdfFormat.TURTLE)), format=ox.RdfFormat.JSON_LD)
        text = text.decode("utf-8")
    with BridgeClient(url(server), TOKEN) as client, pytest.raises(RemoteCallError, match=reason):
        client.call_sync("/cbrs/register", {"description": text, "format": fmt})
    with BridgeClient(url(server), TOKEN) as client:  # said so, in either spelling, it registers
        right = "json-ld" if as_json else "turtle"
        assert client.call_sync("/cbrs/register", {"description": text, "format": right.upper()})["components"]


def test_a_component_of_the_store_is_refused_saying_how_to_serve_it_from_a_program(server: Server) -> None:
    """A lab replacing a bundled component with its own program: "update it instead" did not say how."""
    description = thermometer("/trial10/read").replace("Thermometer07", "Thermometer80")
    with server.sparql.lock:
        server.kb.registry.register(description, "stored.ttl")  # as cbrs register does
    with BridgeClient(url(server), TOKEN) as client, pytest.raises(RemoteCallError) as refused:
        client.call_sync("/cbrs/register", {"description": description})
    assert "is a component of the store, not a live one" in str(refused.value)
    assert "cbrs deregister svc:ReadRoomTemperature_Thermometer80" in str(refused.value)


def test_the_sdk_ends_when_the_server_says_nobody_answers_its_service(server: Server) -> None:
    """Its program stopped providing the service (here: unadvertised behind the SDK's back): the SDK ends
    with the server's reason instead of logging a failed heartbeat every second, unavailable for good."""
    component = Component(thermometer("/trial11/read").replace("Thermometer07", "Thermometer81"))
    component.handler(lambda request: READING)
    connected = component.connect(url(server), TOKEN, heartbeat=0.1, ttl=0.6)
    connected.client.send({"op": "unadvertise_service", "service": "/trial11/read"})
    with pytest.raises(ComponentEndedError, match="no bridge client provides its service /trial11/read"):
        connected.serve()  # the lease's next store write comes within half of its 0.6 s


def test_the_sdk_refuses_two_components_in_one_description_saying_how_to_serve_both() -> None:
    on = thermometer("/trial12/read").replace("Thermometer07", "Thermometer82")
    off = thermometer("/trial13/read").replace("Thermometer07", "Thermometer83")
    with pytest.raises(InvalidDescriptionError, match=r"not 2 \(svc:ReadRoomTemperature_Thermometer82, ") as refused:
        Component(on + off)
    assert "give each a Component of its own; one program serves several" in str(refused.value)


def test_a_goal_too_large_to_read_is_answered_by_its_id(bridge: RunningBridge) -> None:
    client = Raw(bridge.url)
    try:
        client.send(
            json.dumps(
                {"op": "send_action_goal", "id": "g", "action": "/x", "action_type": "a/B", "args": {"d": "x" * LIMIT}}
            )
        )
        result = client.expect("action_result", id="g")
        assert result["result"] is False and "exceeds the limit" in result["values"]
    finally:
        client.close()
