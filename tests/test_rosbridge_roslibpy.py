"""roslibpy, unchanged, against the cbrs rosbridge server (topics, services, parameters, ROS 2 actions).

roslibpy's transports run on a process-wide event loop (Twisted's reactor cannot be restarted, and
Autobahn binds one async framework per process), so the client runs in a child process: this file,
run as a script, does the round trips and prints what it saw as JSON; the test serves the bridge and
asserts on that. Both of roslibpy's transports are exercised, each in its own process.

    python tests/test_rosbridge_roslibpy.py PORT [twisted|asyncio]
"""

from __future__ import annotations

import json
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

import pytest

WAIT = 5.0  # seconds any single step may take


def _until(condition: Callable[[], bool], timeout: float = WAIT, step: Callable[[], None] | None = None) -> bool:
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            return False
        if step is not None:
            step()
        time.sleep(0.05)
    return True


def run_client(port: int, transport: str) -> dict[str, Any]:
    """The round trips, as a roslibpy user writes them; returns what each one gave."""
    import roslibpy
    from roslibpy.core import ServiceException

    results: dict[str, Any] = {}
    a = roslibpy.Ros("127.0.0.1", port, transport=transport)
    b = roslibpy.Ros("127.0.0.1", port, transport=transport)
    a.run(timeout=WAIT)
    b.run(timeout=WAIT)
    results["connected"] = a.is_connected and b.is_connected

    heard: list[str] = []
    listener = roslibpy.Topic(b, "/chatter", "std_msgs/String")
    listener.subscribe(lambda message: heard.append(message["data"]))
    talker = roslibpy.Topic(a, "/chatter", "std_msgs/String")
    talker.advertise()
    # b's subscribe and a's publish travel on different connections: ping until b hears one
    results["subscribed"] = _until(
        lambda: "ping" in heard, step=lambda: talker.publish(roslibpy.Message({"data": "ping"}))
    )
    for text in ["one", "two", "three"]:
        talker.publish(roslibpy.Message({"data": text}))
    _until(lambda: "three" in heard)
    results["heard"] = [text for text in heard if text != "ping"]
    results["topics"] = sorted(a.get_topics())
    results["topic_type"] = a.get_topic_type("/chatter")

    adder = roslibpy.Service(b, "/test/add", "test/Add")
    results["add"] = dict(adder.call(roslibpy.ServiceRequest({"a": 2, "b": 3}), timeout=WAIT))
    try:
        roslibpy.Service(b, "/test/refuse", "test/Refuse").call(roslibpy.ServiceRequest({}), timeout=WAIT)
        results["refuse"] = "no error"
    except ServiceException as error:
        results["refuse"] = str(error)

    def upper(request: dict[str, Any], response: dict[str, Any]) -> bool:
        response["text"] = request["text"].upper()
        return True

    provider = roslibpy.Service(a, "/test/upper", "test/Upper")
    provider.advertise(upper)
    results["advertised"] = _until(lambda: "/test/upper" in b.get_services())
    caller = roslibpy.Service(b, "/test/upper", "test/Upper")
    results["upper"] = dict(caller.call(roslibpy.ServiceRequest({"text": "hello"}), timeout=WAIT))
    results["service_type"] = b.get_service_type("/test/upper")

    a.set_param("/test/gain", {"k": [1, 2.5], "on": True})
    results["param"] = b.get_param("/test/gain")
    results["params"] = b.get_params()
    b.delete_param("/test/gain")
    results["deleted"] = b.get_param("/test/gain")
    results["time"] = a.get_time().secs > 0

    results["actions"] = run_actions(roslibpy, b)

    listener.unsubscribe()
    talker.unadvertise()
    provider.unadvertise()
    a.close()
    b.close()
    return results


def run_actions(roslibpy: Any, ros: Any) -> dict[str, Any]:
    """roslibpy's ROS 2 ActionClient: a goal with feedback, an unknown action, a cancelled goal."""
    found: dict[str, Any] = {}

    def send(action: Any, goal: dict[str, Any], cancel_after: int | None = None) -> dict[str, Any]:
        seen: dict[str, Any] = {"feedback": []}

        def ended(key: str) -> Callable[[dict[str, Any]], None]:
            return lambda outcome: seen.update({key: outcome["status"].name, "values": outcome["values"]})

        def feedback(values: dict[str, Any]) -> None:
            seen["feedback"].append(values["n"])

        goal_id = action.send_goal(roslibpy.Goal(goal), ended("result"), feedback, ended("error"))
        if cancel_after is not None and _until(lambda: len(seen["feedback"]) >= cancel_after):
            action.cancel_goal(goal_id)
        action.wait_goal(goal_id, timeout=WAIT)
        return seen

    count = roslibpy.ActionClient(ros, "/test/count", "test/action/Count")
    found["count"] = send(count, {"to": 3})
    found["unknown"] = send(roslibpy.ActionClient(ros, "/no/such/action", "x/Y"), {})
    found["cancelled"] = send(count, {"to": 5, "hold": 1}, cancel_after=1)
    return found


@pytest.mark.parametrize("transport", ["twisted", "asyncio"])
def test_roslibpy_round_trips(transport: str) -> None:
    from cbrs.rosbridge import Bridge, ServiceError
    from tests.test_rosbridge_actions import count

    def refuse(args: dict[str, Any]) -> dict[str, Any]:
        raise ServiceError("the robot is busy")

    bridge = Bridge(call_timeout=WAIT, params={"/robot/speed": 0.5})
    bridge.add_service("/test/add", "test/Add", lambda args: {"sum": args["a"] + args["b"]})
    bridge.add_service("/test/refuse", "test/Refuse", refuse)
    bridge.add_topic("/test/events", "test/Event")
    bridge.add_action("/test/count", "test/action/Count", count)
    threads = threading.active_count()
    with bridge.start(port=0) as running:
        child = subprocess.run(
            [sys.executable, __file__, str(running.port), transport], capture_output=True, text=True, timeout=60
        )
    assert child.returncode == 0, child.stderr
    results = json.loads(child.stdout.strip().splitlines()[-1])
    assert results == {
        "connected": True,
        "subscribed": True,
        "heard": ["one", "two", "three"],
        "topics": ["/chatter", "/test/events"],
        "topic_type": "std_msgs/String",
        "add": {"sum": 5},
        "refuse": "the robot is busy",
        "advertised": True,
        "upper": {"text": "HELLO"},
        "service_type": "test/Upper",
        "param": {"k": [1, 2.5], "on": True},
        "params": ["/robot/speed", "/test/gain/k", "/test/gain/on"],
        "deleted": None,
        "time": True,
        "actions": {
            "count": {"feedback": [0, 1, 2], "result": "SUCCEEDED", "values": {"reached": 3, "authorised": False}},
            "unknown": {"feedback": [], "error": "UNKNOWN", "values": "action '/no/such/action' does not exist"},
            "cancelled": {"feedback": [0], "result": "CANCELED", "values": {"reached": 1}},
        },
    }
    assert bridge.topics() == [("/test/events", "test/Event")]  # the clients' topics went with them
    assert _until(lambda: threading.active_count() == threads)


if __name__ == "__main__":
    outcome = run_client(int(sys.argv[1]), sys.argv[2] if len(sys.argv) > 2 else "twisted")
    print(json.dumps(outcome), flush=True)
