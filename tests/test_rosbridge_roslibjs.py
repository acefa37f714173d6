"""roslibjs (the npm package ``roslib``), unchanged, against the cbrs rosbridge server.

tests/js/roundtrip.mjs does the round trips in node and prints what it saw as JSON; tests/js/actions.mjs
does the same with ROS 2 actions, and tests/js/run_task_action.mjs runs a task of ``cbrs serve`` as an
action. Install their dependencies once with ``npm ci --prefix tests/js``; without node or them, the
tests are skipped.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from typing import Any

import pytest

from cbrs.rosbridge import Bridge, ServiceError
from tests.helpers_roslibjs import ROSLIBJS_MARKS, node
from tests.helpers_threads import assert_threads_end
from tests.test_rosbridge_actions import TOKEN, count

pytestmark = ROSLIBJS_MARKS


def test_roslibjs_round_trips() -> None:
    def refuse(args: dict[str, Any]) -> dict[str, Any]:
        raise ServiceError("the robot is busy")

    bridge = Bridge(call_timeout=5.0, params={"/robot/speed": 0.5})
    bridge.add_service("/test/add", "test/Add", lambda args: {"sum": args["a"] + args["b"]})
    bridge.add_service("/test/refuse", "test/Refuse", refuse)
    bridge.add_topic("/test/events", "test/Event")
    threads = threading.active_count()
    with bridge.start(port=0) as running:
        found = node("roundtrip.mjs", running.port)
    assert found == {
        "connected": True,
        "subscribed": True,
        "heard": ["one", "two", "three"],
        "topics": ["/chatter", "/test/events"],
        "topic_type": "std_msgs/String",
        "add": {"sum": 5},
        "refuse": {"failed": "the robot is busy"},
        "advertised": True,
        "upper": {"text": "HELLO"},
        "fold": {"failed": "Error: the arm is folded"},  # advertiseAsync's error text, relayed
        "service_type": "test/Upper",
        "param": {"k": [1, 2.5], "on": True},
        "params": ["/robot/speed", "/test/gain/k", "/test/gain/on"],
        "deleted": {"failed": "parameter '/test/gain' is not set"},  # roslibjs reads successful/reason
    }
    assert bridge.topics() == [("/test/events", "test/Event")]
    assert_threads_end(threads, 5.0)


def test_roslibjs_sends_provides_and_cancels_action_goals() -> None:
    bridge = Bridge(call_timeout=5.0)
    bridge.add_action("/test/count", "test/action/Count", count)
    threads = threading.active_count()
    with bridge.start(port=0) as running:
        found = node("actions.mjs", running.port)
    assert found == {
        "count": {"feedback": [0, 1, 2], "result": {"reached": 3, "authorised": False}},
        # roslibjs's failed callback: GoalError with the status's words and the values
        "unknown": {
            "feedback": [],
            "failed": "GoalError: Action status unknown: action '/no/such/action' does not exist",
        },
        "listed": True,
        "fibonacci": {"feedback": [3, 4, 5], "result": {"sequence": [0, 1, 1, 2, 3]}},
        "failed": {"feedback": [], "failed": "GoalError: Action was aborted: {}"},
        "cancelled": {"failed": 'GoalError: Action was canceled: {"sequence":[]}'},
    }
    assert bridge.actions() == [("/test/count", "test/action/Count")]  # the provider's went with it
    assert_threads_end(threads, 5.0)


@pytest.fixture
def served(fresh_bundled_kb: Any) -> Iterator[int]:
    pytest.importorskip("pybullet", reason="a task run needs the [sim] extra")
    from cbrs.server import ServeConfig, Server
    from cbrs.sparql_service import EndpointConfig

    server = Server(fresh_bundled_kb, ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN)))
    server.start()
    yield server.bridge_port
    server.stop(timeout=10.0)


def test_roslibjs_runs_a_task_as_an_action_with_feedback_per_step(served: int) -> None:
    found = node("run_task_action.mjs", served, TOKEN, timeout=180)
    anonymous = found["anonymous"]
    assert anonymous["feedback"] == [] and anonymous["failed"].startswith(
        "GoalError: Action status unknown: a task run"
    )
    run = found["run"]["result"]
    assert run["status"] == "succeeded"
    steps = run["result"]["plan"]["steps"]
    feedback = found["run"]["feedback"]
    assert [(f["step"], f["component"], f["action"], f["status"]) for f in feedback] == [
        (s["index"], s["component"], s["action"], "succeeded") for s in steps
    ]
    assert all(f["run"] == run["id"] for f in feedback)
