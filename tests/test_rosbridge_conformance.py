"""The rosbridge v2 protocol as rosbridge_suite implements it, spoken by a raw websocket client.

Each test sends what a client other than roslibpy and roslibjs may send (rosbridge_suite's
``ROSBRIDGE_PROTOCOL.md`` and its capabilities, ``ros2`` branch: docs/rosbridge.md, "Protocol coverage")
and checks the reply's shape and its ``id``. One server for the module; loopback only, every wait bounded.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from cbrs.bridge_client import BridgeClient
from cbrs.rosbridge import Bridge, GoalHandle, RunningBridge
from tests.test_rosbridge import WAIT, Client, client_maker


@pytest.fixture(scope="module")
def running(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RunningBridge]:
    bridge = Bridge(call_timeout=WAIT)
    folder: Path = tmp_path_factory.mktemp("interfaces")
    (folder / "srv").mkdir()
    (folder / "srv" / "AddTwoInts.srv").write_text("int64 a\nint64 b\n---\nint64 sum\n", encoding="utf-8")
    bridge.interfaces.load(folder, "demo")
    bridge.add_service("/add_two_ints", "demo/AddTwoInts", lambda args: {"sum": args.get("a", 0) + args.get("b", 0)})
    bridge.add_service("/untyped", "demo/Untyped", lambda args: {"got": args})

    def count(goal: GoalHandle) -> dict[str, Any]:
        goal.publish_feedback({"n": 1})
        return {"done": True}

    bridge.add_action("/count", "demo/action/Count", count)
    with bridge.start(port=0) as served:
        yield served


@pytest.fixture
def client(running: RunningBridge) -> Iterator[Callable[[], Client]]:
    with client_maker(running.url) as make:
        yield make


def test_publish_without_msg_sends_an_empty_message_as_rosbridge_does(client: Callable[[], Client]) -> None:
    publisher, subscriber = client(), client()
    subscriber.send(op="subscribe", topic="/ping", type="std_msgs/Empty")
    subscriber.sync()
    publisher.send(op="advertise", topic="/ping", type="std_msgs/Empty")
    publisher.send(op="publish", topic="/ping")
    assert subscriber.expect("publish") == {"op": "publish", "topic": "/ping", "msg": {}}


def test_several_messages_in_one_frame_are_each_handled_in_order(client: Callable[[], Client]) -> None:
    me = client()
    first = {"op": "call_service", "id": "one", "service": "/add_two_ints", "args": {"a": 1, "b": 2}}
    second = {"op": "call_service", "service": "/rosapi/get_time", "id": "two"}
    me.ws.send(json.dumps(first) + "\n" + json.dumps(second))
    answers = [me.expect("service_response") for _ in range(2)]
    assert sorted(answer["id"] for answer in answers) == ["one", "two"]
    assert next(a for a in answers if a["id"] == "one")["values"] == {"sum": 3}
    me.ws.send(json.dumps(first) + " trailing words")  # not all JSON objects: refused whole, as before
    status = me.expect("status")
    assert "not valid JSON: Extra data" in status["msg"]
    assert status["id"] == "one"


@pytest.mark.parametrize(
    ("service", "args", "values"),
    [
        pytest.param("/add_two_ints", [2, 40], {"sum": 42}, id="defined-type"),
        pytest.param("/add_two_ints", [5], {"sum": 5}, id="fewer-values"),
        pytest.param("/rosapi/has_param", ["/nothing"], {"exists": False}, id="rosapi"),
        pytest.param(
            "/rosapi/get_param", ["/nothing", "7"], {"value": "7", "successful": True, "reason": ""}, id="default"
        ),
        pytest.param("/rosapi/get_time", [], None, id="empty-list"),
    ],
)
def test_args_as_a_list_fill_the_request_fields_in_order(
    client: Callable[[], Client], service: str, args: list[Any], values: dict[str, Any] | None
) -> None:
    answer = client().call(service, args)
    assert answer["result"] is True, answer
    if values is not None:
        assert answer["values"] == values


def test_a_list_that_cannot_fill_the_request_is_refused_with_the_reason(client: Callable[[], Client]) -> None:
    me = client()
    me.send(op="call_service", service="/add_two_ints", args=[1, 2, 3], id="long")
    status = me.expect("status")
    reason = "service '/add_two_ints' (demo/AddTwoInts) takes 2 request fields (a, b), not the 3 values of args"
    assert (status["level"], status["id"]) == ("error", "long") and reason in status["msg"]
    answer = me.expect("service_response")
    assert (answer["id"], answer["result"]) == ("long", False) and reason in answer["values"]
    untyped = me.call("/untyped", [1])  # no definition: no field names to give the values
    assert untyped["result"] is False
    assert "takes its args as an object of named fields" in untyped["values"]


def test_a_provider_gets_a_list_of_a_type_not_defined_here_as_it_is(client: Callable[[], Client]) -> None:
    provider, caller = client(), client()
    provider.send(op="advertise_service", service="/legacy", type="legacy/Positional")
    provider.sync()
    caller.send(op="call_service", service="/legacy", args=[1, "two"], id="c")
    forwarded = provider.expect("call_service")
    assert forwarded["args"] == [1, "two"]
    provider.send(op="service_response", service="/legacy", id=forwarded["id"], values={"ok": True}, result=True)
    assert caller.expect("service_response") == {
        "op": "service_response",
        "service": "/legacy",
        "values": {"ok": True},
        "result": True,
        "id": "c",
    }


def test_rosapi_describes_its_own_service_types(client: Callable[[], Client]) -> None:
    me = client()
    request = me.call("/rosapi/service_request_details", {"type": "rosapi/GetParam"})["values"]["typedefs"]
    assert request[0]["type"] == "rosapi/GetParamRequest"
    assert request[0]["fieldnames"] == ["name", "default"]
    response = me.call("/rosapi/service_response_details", {"type": "rosapi/srv/MessageDetails"})
    assert [typedef["type"] for typedef in response["values"]["typedefs"]] == [
        "rosapi/MessageDetailsResponse",
        "rosapi/TypeDef",
    ]


def test_get_param_reads_ros_2s_default_value(client: Callable[[], Client]) -> None:
    answer = client().call("/rosapi/get_param", {"name": "/unset/anywhere", "default_value": "[1, 2]"})
    assert answer["values"] == {"value": "[1, 2]", "successful": True, "reason": ""}


@pytest.mark.parametrize(
    "extra",
    [
        pytest.param({"fragment_size": None}, id="fragment_size-null"),
        pytest.param({"compression": "none"}, id="compression-none"),
        pytest.param({"compression": "png"}, id="compression-png"),  # rosbridge_suite takes it and sends JSON
        pytest.param({"args": None}, id="args-null"),
        pytest.param({"type": "rosapi/GetTime"}, id="type"),
    ],
)
def test_call_service_takes_rosbridges_optional_fields(client: Callable[[], Client], extra: dict[str, Any]) -> None:
    assert client().call("/rosapi/get_time", **extra)["result"] is True


@pytest.mark.parametrize(
    "extra",
    [
        pytest.param({"type": "std_msgs/String", "throttle_rate": 0, "queue_length": 0}, id="defaults"),
        pytest.param({"fragment_size": None, "compression": "none"}, id="nulls"),
        pytest.param({"queue_length": 5, "throttle_rate": 10}, id="queued"),
    ],
)
def test_subscribe_takes_rosbridges_optional_fields(client: Callable[[], Client], extra: dict[str, Any]) -> None:
    publisher, subscriber = client(), client()
    subscriber.send(op="set_level", level="info")
    subscriber.send(op="subscribe", topic="/opt", id="s", **extra)
    assert subscriber.expect("status") == {"op": "status", "level": "info", "msg": "subscribed to /opt", "id": "s"}
    publisher.send(op="advertise", topic="/opt", type="std_msgs/String")
    publisher.send(op="publish", topic="/opt", msg={"data": "x"})
    assert subscriber.expect("publish")["msg"] == {"data": "x"}


def test_replies_have_rosbridges_shapes_and_echo_the_id(client: Callable[[], Client]) -> None:
    me = client()
    assert me.call("/add_two_ints", {"a": 1, "b": 1}) == {
        "op": "service_response",
        "service": "/add_two_ints",
        "values": {"sum": 2},
        "result": True,
        "id": "call-/add_two_ints",
    }
    failed = me.call("/nowhere")
    assert set(failed) == {"op", "service", "values", "result", "id"}
    assert (failed["result"], failed["values"]) == (False, "service '/nowhere' does not exist")
    me.send(op="send_action_goal", action="/count", action_type="demo/action/Count", args={}, feedback=True, id=7)
    feedback = me.expect("action_feedback")
    assert feedback == {"op": "action_feedback", "action": "/count", "values": {"n": 1}, "id": 7}
    result = me.expect("action_result")
    assert result == {
        "op": "action_result",
        "action": "/count",
        "values": {"done": True},
        "status": 4,
        "result": True,
        "id": 7,
    }
    me.send(op="publish", topic="/never", msg={}, id="p")
    status = me.expect("status")
    assert (set(status), status["level"], status["id"]) == ({"op", "level", "msg", "id"}, "error", "p")


def test_status_levels_filter_as_rosbridge_does(client: Callable[[], Client]) -> None:
    me = client()
    me.send(op="unadvertise", topic="/never", id="w")  # a warning: not sent at the default level, error
    me.send(op="set_level", level="warning")
    me.send(op="unadvertise", topic="/never", id="w2")
    assert me.expect("status")["id"] == "w2"
    me.send(op="set_level", level="none")
    me.send(op="publish", topic="/never", msg={}, id="quiet")  # an error, but the client wants none
    me.nothing()
    assert me.call("/rosapi/get_time")["result"] is True  # answers are not statuses: they still come


#: The services rosbridge_suite's ROS 2 rosapi node offers (rosapi/scripts/rosapi_node, ros2 c1bfc2f).
ROS2_ROSAPI = [
    "topics",
    "topics_for_type",
    "topics_and_raw_types",
    "services",
    "services_for_type",
    "nodes",
    "node_details",
    "action_servers",
    "topic_type",
    "service_type",
    "publishers",
    "subscribers",
    "service_providers",
    "service_node",
    "message_details",
    "service_request_details",
    "service_response_details",
    "set_param",
    "get_param",
    "has_param",
    "delete_param",
    "get_param_names",
    "get_time",
    "get_ros_version",
]


def test_every_service_of_ros_2s_rosapi_answers(client: Callable[[], Client]) -> None:
    me = client()
    listed = set(me.call("/rosapi/services")["values"]["services"])
    assert {f"/rosapi/{name}" for name in ROS2_ROSAPI} <= listed
    assert me.call("/rosapi/get_ros_version")["values"] == {"version": 2, "distro": ""}
    described = me.call("/rosapi/service_response_details", {"type": "rosapi/GetROSVersion"})["values"]
    assert described["typedefs"][0]["fieldnames"] == ["version", "distro"]


def test_ros_1_and_ros_2_spellings_of_a_type_are_the_same_type(client: Callable[[], Client]) -> None:
    ros1, ros2 = client(), client()
    ros2.send(op="subscribe", topic="/mixed", type="std_msgs/msg/String", id="s")
    ros2.sync()
    ros1.send(op="advertise", topic="/mixed", type="std_msgs/String", id="a")
    ros1.send(op="publish", topic="/mixed", msg={"data": "both"})
    assert ros2.expect("publish")["msg"] == {"data": "both"}
    ros1.nothing()  # no type conflict
    for spelling in ("std_msgs/String", "std_msgs/msg/String"):
        assert "/mixed" in ros1.call("/rosapi/topics_for_type", {"type": spelling})["values"]["topics"]
    ros1.send(op="subscribe", topic="/mixed", type="std_msgs/msg/Int32", id="other")
    assert "has type 'std_msgs/" in ros1.expect("status")["msg"]


def test_the_python_client_answers_a_positional_call_with_the_reason(
    running: RunningBridge, client: Callable[[], Client]
) -> None:
    with BridgeClient(running.url, timeout=WAIT) as provider:
        provider.advertise("/py/echo", "py/Echo", lambda args: dict(args))
        caller = client()
        assert caller.call("/py/echo", {"a": 1})["values"] == {"a": 1}
        answer = caller.call("/py/echo", [1, 2])
        assert answer["result"] is False
        assert "/py/echo takes its args as an object of named fields, not the list [1, 2]" in answer["values"]
