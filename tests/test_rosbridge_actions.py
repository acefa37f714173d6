"""rosbridge's ROS 2 action ops over a real websocket: goals, feedback, results, cancels, provided actions.

First with small server actions and client providers (no knowledge base), then the /cbrs/run_task action
of ``cbrs serve`` running a task in the simulated home. Every receive is bounded (``Client.recv``).
"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from cbrs.bridge_services import StepFeed
from cbrs.rosbridge import Bridge, Caller, GoalHandle, GoalResult, GoalStatus, RunningBridge, ServiceError
from cbrs.tasks import TaskRun
from tests.helpers_threads import assert_threads_end
from tests.test_rosapi_typedefs import cbrs_types, mismatches
from tests.test_rosbridge import WAIT, Client, client_maker

TOKEN = "actions-test-token"


def count(goal: GoalHandle) -> dict[str, Any] | GoalResult:
    """Counts to ``to``, a feedback per number; waits for a cancel after ``hold`` numbers."""
    for n in range(goal.args.get("to", 3)):
        goal.publish_feedback({"n": n})
        if n + 1 == goal.args.get("hold") and goal.wait_cancel(WAIT):
            return GoalResult(GoalStatus.CANCELED, {"reached": n + 1})
    if goal.args.get("abort"):
        return GoalResult(GoalStatus.ABORTED, {"reached": goal.args["to"]})
    if goal.args.get("refuse"):
        raise ServiceError("the arm is folded")
    return {"reached": goal.args.get("to", 3), "authorised": goal.caller.authorised}


@pytest.fixture
def bridge() -> Bridge:
    bridge = Bridge(call_timeout=WAIT, reserved=["/cbrs/"], token=TOKEN)
    bridge.add_action("/test/count", "test/action/Count", count)
    return bridge


@pytest.fixture
def server(bridge: Bridge) -> Iterator[RunningBridge]:
    threads = threading.active_count()
    running = bridge.start(port=0)
    yield running
    assert running.stop(timeout=5.0)
    assert_threads_end(threads, WAIT)


@pytest.fixture
def client(server: RunningBridge) -> Iterator[Callable[[], Client]]:
    with client_maker(server.url) as make:
        yield make


def goal(me: Client, action: str, args: Any, goal_id: str = "g1", feedback: bool = True) -> None:
    me.send(
        op="send_action_goal", id=goal_id, action=action, action_type="test/action/Count", args=args, feedback=feedback
    )


# -- server actions ------------------------------------------------------------------------------


def test_a_goal_gets_one_feedback_per_step_then_its_result(client: Callable[[], Client]) -> None:
    me = client()
    goal(me, "test/count", {"to": 3})  # the name as the client wrote it comes back
    feedback = [me.expect("action_feedback") for _ in range(3)]
    assert feedback == [
        {"op": "action_feedback", "action": "test/count", "values": {"n": n}, "id": "g1"} for n in range(3)
    ]
    assert me.expect("action_result") == {
        "op": "action_result",
        "action": "test/count",
        "values": {"reached": 3, "authorised": False},
        "status": GoalStatus.SUCCEEDED,
        "result": True,
        "id": "g1",
    }


def test_without_feedback_true_only_the_result_comes(client: Callable[[], Client]) -> None:
    me = client()
    goal(me, "/test/count", {"to": 2}, feedback=False)
    assert me.expect("action_result")["values"]["reached"] == 2
    me.nothing()


def test_cancel_stops_the_goal_with_status_canceled(client: Callable[[], Client]) -> None:
    me = client()
    goal(me, "/test/count", {"to": 5, "hold": 1}, goal_id="c")
    assert me.expect("action_feedback")["values"] == {"n": 0}
    me.send(op="cancel_action_goal", id="c", action="/test/count")
    result = me.expect("action_result")
    assert (result["status"], result["result"], result["values"], result["id"]) == (5, True, {"reached": 1}, "c")


def test_an_aborted_or_refused_goal_says_so_in_its_result(client: Callable[[], Client]) -> None:
    me = client()
    goal(me, "/test/count", {"to": 1, "abort": True}, feedback=False)
    aborted = me.expect("action_result")
    assert (aborted["status"], aborted["result"], aborted["values"]) == (GoalStatus.ABORTED, True, {"reached": 1})
    goal(me, "/test/count", {"to": 1, "refuse": True}, goal_id="r", feedback=False)
    status = me.expect("status")  # rosbridge logs a failed goal as an error, then answers it
    assert (status["level"], status["id"]) == ("error", "r") and "the arm is folded" in status["msg"]
    refused = me.expect("action_result")
    assert (refused["status"], refused["result"], refused["values"]) == (GoalStatus.UNKNOWN, False, "the arm is folded")


def test_an_unknown_action_fails_the_goal_in_its_callbacks_not_in_silence(client: Callable[[], Client]) -> None:
    me = client()
    goal(me, "/no/such/action", {"order": 3}, goal_id="u")
    status = me.expect("status")
    assert status == {
        "op": "status",
        "level": "error",
        "msg": "send_action_goal: action '/no/such/action' does not exist",
        "id": "u",
    }
    assert me.expect("action_result") == {
        "op": "action_result",
        "action": "/no/such/action",
        "values": "action '/no/such/action' does not exist",
        "status": GoalStatus.UNKNOWN,
        "result": False,
        "id": "u",
    }


@pytest.mark.parametrize(
    ("message", "reason"),
    [
        pytest.param({"action": "/test/count"}, "missing required field 'action_type'", id="no-type"),
        pytest.param({"action": "/test/count", "action_type": "t", "args": 3}, "field 'args' must be", id="args"),
        pytest.param({"action": "/test/count", "action_type": "t", "args": [3]}, "not an array", id="array"),
    ],
)
def test_a_goal_that_cannot_be_read_is_answered_with_a_failed_result(
    client: Callable[[], Client], message: dict[str, Any], reason: str
) -> None:
    me = client()
    me.send(op="send_action_goal", id="bad", **message)
    assert reason in me.expect("status")["msg"]
    result = me.expect("action_result")
    assert (result["result"], result["status"], result["id"]) == (False, 0, "bad")
    assert reason in result["values"]


def test_two_goals_with_one_id_refuse_the_second(client: Callable[[], Client]) -> None:
    me = client()
    goal(me, "/test/count", {"to": 3, "hold": 1}, goal_id="same")
    assert me.expect("action_feedback")["values"] == {"n": 0}
    goal(me, "/test/count", {"to": 1}, goal_id="same")
    me.expect("status")
    assert "already running" in me.expect("action_result")["values"]
    me.send(op="cancel_action_goal", id="same", action="/test/count")
    assert me.expect("action_result")["status"] == GoalStatus.CANCELED


def test_cancelling_a_goal_not_in_progress_is_a_warning(client: Callable[[], Client]) -> None:
    me = client()
    me.send(op="set_level", level="warning")
    me.send(op="cancel_action_goal", id="never", action="/test/count")
    status = me.expect("status")
    assert (status["level"], status["id"]) == ("warning", "never")
    assert "no goal with id 'never'" in status["msg"]


def test_the_handler_sees_who_sent_the_goal(client: Callable[[], Client]) -> None:
    me = client()
    me.send(op="auth", mac=TOKEN)
    goal(me, "/test/count", {"to": 0}, feedback=False)
    assert me.expect("action_result")["values"] == {"reached": 0, "authorised": True}


def test_rosapi_lists_the_actions(client: Callable[[], Client], bridge: Bridge) -> None:
    me = client()
    assert me.call("/rosapi/action_servers")["values"] == {"action_servers": ["/test/count"]}
    provider = client()
    provider.send(op="advertise_action", action="fibonacci", type="example_interfaces/action/Fibonacci")
    provider.sync()
    assert me.call("/rosapi/action_servers")["values"] == {"action_servers": ["/fibonacci", "/test/count"]}
    assert bridge.actions() == [
        ("/fibonacci", "example_interfaces/action/Fibonacci"),
        ("/test/count", "test/action/Count"),
    ]


def test_stopping_the_server_fails_the_goals_and_asks_handlers_to_stop() -> None:
    stopped = threading.Event()

    def wait(goal: GoalHandle) -> dict[str, Any]:
        goal.publish_feedback({"started": True})
        if goal.wait_cancel(WAIT):
            stopped.set()
        return {}

    bridge = Bridge()
    bridge.add_action("/test/wait", "test/Wait", wait)
    threads = threading.active_count()
    running = bridge.start(port=0)
    me = Client(running.url)
    try:
        goal(me, "/test/wait", {})
        me.expect("action_feedback")
        assert running.stop(timeout=5.0)
        assert stopped.is_set()
    finally:
        me.close()
    assert_threads_end(threads, WAIT)


# -- actions a client provides ---------------------------------------------------------------------


def test_a_client_provides_an_action_like_a_service(client: Callable[[], Client]) -> None:
    provider, caller = client(), client()
    provider.send(op="advertise_action", action="fibonacci", type="example_interfaces/action/Fibonacci")
    provider.sync()
    caller.send(
        op="send_action_goal",
        id="f1",
        action="/fibonacci",
        action_type="example_interfaces/action/Fibonacci",
        args={"order": 3},
        feedback=True,
    )
    request = provider.expect("send_action_goal")
    assert request == {
        "op": "send_action_goal",
        "id": request["id"],
        "action": "fibonacci",  # as the provider advertised it: roslibjs dispatches goals on that name
        "action_type": "example_interfaces/action/Fibonacci",
        "args": {"order": 3},
        "feedback": True,
    }
    assert request["id"].startswith("action_goal:/fibonacci:")
    provider.send(op="action_feedback", id=request["id"], action="fibonacci", values={"sequence": [0, 1]})
    assert caller.expect("action_feedback") == {
        "op": "action_feedback",
        "action": "/fibonacci",
        "values": {"sequence": [0, 1]},
        "id": "f1",
    }
    provider.send(
        op="action_result", id=request["id"], action="fibonacci", values={"sequence": [0, 1, 1]}, status=4, result=True
    )
    result = caller.expect("action_result")
    assert (result["values"], result["status"], result["result"], result["id"]) == (
        {"sequence": [0, 1, 1]},
        4,
        True,
        "f1",
    )
    provider.send(op="action_result", id=request["id"], action="fibonacci", status=4, result=True)
    assert "no goal with id" in provider.expect("status")["msg"]  # a second result has no goal to end


def test_a_cancel_goes_to_the_provider_which_ends_the_goal(client: Callable[[], Client]) -> None:
    provider, caller = client(), client()
    provider.send(op="advertise_action", action="/fibonacci", type="example_interfaces/action/Fibonacci")
    provider.sync()
    goal(caller, "/fibonacci", {"order": 9}, goal_id="c1")
    key = provider.expect("send_action_goal")["id"]
    caller.send(op="cancel_action_goal", id="c1", action="/fibonacci")
    assert provider.expect("cancel_action_goal") == {"op": "cancel_action_goal", "id": key, "action": "/fibonacci"}
    provider.send(op="action_result", id=key, action="/fibonacci", values={"sequence": []}, status=5, result=True)
    assert caller.expect("action_result")["status"] == GoalStatus.CANCELED


@pytest.mark.parametrize(
    ("answer", "status"),
    [
        pytest.param({"result": False, "status": 6}, GoalStatus.ABORTED, id="set-failed"),
        pytest.param({"result": True, "status": 2, "values": {"x": 1}}, GoalStatus.ABORTED, id="not-terminal"),
        pytest.param({"result": False, "status": 4}, GoalStatus.ABORTED, id="false-succeeded"),
    ],
)
def test_a_providers_failure_aborts_the_goal_as_ros2_does(
    client: Callable[[], Client], answer: dict[str, Any], status: GoalStatus
) -> None:
    provider, caller = client(), client()
    provider.send(op="advertise_action", action="/fibonacci", type="example_interfaces/action/Fibonacci")
    provider.sync()
    goal(caller, "/fibonacci", {"order": 1}, feedback=False)
    key = provider.expect("send_action_goal")["id"]
    provider.send(op="action_result", id=key, action="/fibonacci", **answer)
    result = caller.expect("action_result")
    assert (result["status"], result["result"]) == (status, True)
    assert result["values"] == answer.get("values", {})


def test_a_provider_leaving_or_unadvertising_fails_its_goals(client: Callable[[], Client]) -> None:
    provider, caller = client(), client()
    provider.send(op="advertise_action", action="/fibonacci", type="example_interfaces/action/Fibonacci")
    provider.sync()
    goal(caller, "/fibonacci", {"order": 1}, goal_id="a", feedback=False)
    provider.expect("send_action_goal")
    provider.send(op="unadvertise_action", action="/fibonacci")
    caller.expect("status")
    result = caller.expect("action_result")
    assert (result["result"], result["status"]) == (False, GoalStatus.UNKNOWN)
    assert result["values"] == "action '/fibonacci' was unadvertised by its provider"
    provider.send(op="advertise_action", action="/fibonacci", type="example_interfaces/action/Fibonacci")
    provider.sync()
    goal(caller, "/fibonacci", {"order": 1}, goal_id="b", feedback=False)
    provider.expect("send_action_goal")
    provider.close()
    caller.expect("status")
    assert caller.expect("action_result")["values"] == "the provider of '/fibonacci' disconnected"
    goal(caller, "/fibonacci", {"order": 1}, goal_id="c", feedback=False)
    caller.expect("status")
    assert caller.expect("action_result")["values"] == "action '/fibonacci' does not exist"


def test_clients_cannot_provide_the_servers_actions(client: Callable[[], Client]) -> None:
    me = client()
    me.send(op="advertise_action", action="/test/count", type="x/Y", id=1)
    assert "provided by the server" in me.expect("status")["msg"]
    me.send(op="advertise_action", action="/cbrs/run_task", type="x/Y", id=2)
    assert "namespace of this server" in me.expect("status")["msg"]
    me.send(op="feedback_for_nobody", id=3)
    assert "unknown op" in me.expect("status")["msg"]
    me.send(op="action_feedback", id="nope", action="/test/count", values={})
    assert "no goal with id 'nope' is waiting for this client" in me.expect("status")["msg"]


# -- /cbrs/run_task in cbrs serve --------------------------------------------------------------------


def test_run_task_feedback_names_the_run_and_its_task_as_the_result_does() -> None:
    """Each feedback carries the run's ``iri`` and ``shown`` (it named no task, so a client following
    several runs had to keep its goals' names), those of steps that ended before the run was known too,
    and only the fields ``cbrs/RunTaskFeedback`` defines; another run's steps are not relayed."""
    sent: list[dict[str, Any]] = []
    goal = GoalHandle("/cbrs/run_task", {}, Caller("127.0.0.1", None, True), lambda text: sent.append(json.loads(text)))
    iri = "http://lab10.example/tasks#SwitchOnTheReadingLamp"
    run = TaskRun("run-7", "SwitchOnTheReadingLamp", 0, (), iri=iri)
    run.shown = "lab10:SwitchOnTheReadingLamp"
    lamp = "http://lab10.example/svc#Lamp"
    feed = StepFeed(goal, {lamp: "http://lab10.example/act#SwitchOn"})
    step = {"run": "run-7", "task": iri, "iri": iri, "shown": run.shown, "step": 1, "component": lamp}
    feed("/cbrs/task_progress", {**step, "event": "step_failed", "reason": "stuck", "failover": None})
    feed.follow(run)
    feed("/cbrs/task_progress", {**step, "run": "run-6", "event": "step_succeeded"})
    feed("/cbrs/task_progress", {**step, "event": "replanning", "plan": 2})
    feed("/cbrs/task_progress", {**step, "event": "step_succeeded"})
    named = {key: run.to_dict()[key] for key in ("iri", "shown")}
    assert named == {"iri": iri, "shown": "lab10:SwitchOnTheReadingLamp"}
    assert [(f["run"], f["iri"], f["shown"], f["plan"], f["status"]) for f in sent] == [
        ("run-7", iri, "lab10:SwitchOnTheReadingLamp", 1, "failed"),
        ("run-7", iri, "lab10:SwitchOnTheReadingLamp", 2, "succeeded"),
    ]
    described = cbrs_types().message("cbrs/RunTaskFeedback")
    assert all(set(f) == set(described[0]["fieldnames"]) and mismatches(described, f) == [] for f in sent), sent


@pytest.fixture
def served(fresh_bundled_kb: Any) -> Iterator[tuple[str, Any]]:
    pytest.importorskip("pybullet", reason="a task run needs the [sim] extra")
    from cbrs.server import ServeConfig, Server
    from cbrs.sparql_service import EndpointConfig

    server = Server(fresh_bundled_kb, ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN)))
    server.start()
    yield f"ws://127.0.0.1:{server.bridge_port}", fresh_bundled_kb
    server.stop(timeout=WAIT)


RUN_WAIT = 120.0  # a run in the simulated home takes 10-20 s on a busy two-core machine


def run_goal(me: Client, goal_id: str, **args: Any) -> None:
    me.send(
        op="send_action_goal",
        id=goal_id,
        action="/cbrs/run_task",
        action_type="cbrs/action/RunTask",
        args={"task": "RobotArmServeACup", **args},
        feedback=True,
    )


def test_run_task_action_needs_the_token_then_reports_each_step_and_the_verdict(served: tuple[str, Any]) -> None:
    url, _ = served
    me = Client(url)
    try:
        run_goal(me, "anonymous")
        me.expect("status")
        refused = me.expect("action_result")
        assert (refused["result"], refused["status"], refused["id"]) == (False, GoalStatus.UNKNOWN, "anonymous")
        assert "update token" in refused["values"]
        me.send(op="auth", mac=TOKEN)
        run_goal(me, "run")
        feedback = []
        while (message := me.recv(RUN_WAIT))["op"] == "action_feedback":
            assert message["id"] == "run"
            feedback.append(message["values"])
        assert message["op"] == "action_result", message
        assert (message["result"], message["status"], message["id"]) == (True, GoalStatus.SUCCEEDED, "run")
        run = message["values"]
        assert run["status"] == "succeeded"
        steps = run["result"]["plan"]["steps"]
        assert [(f["step"], f["component"], f["action"], f["status"]) for f in feedback] == [
            (s["index"], s["component"], s["action"], "succeeded") for s in steps
        ]
        assert {f["run"] for f in feedback} == {run["id"]} and {f["plan"] for f in feedback} == {1}
        assert {(f["iri"], f["shown"]) for f in feedback} == {(run["iri"], "RobotArmServeACup")}
        assert run["iri"].endswith("#RobotArmServeACup")
        described = cbrs_types().message("cbrs/RunTaskFeedback")
        assert [mismatches(described, f) for f in feedback] == [[] for _ in feedback]
        assert run["result"]["goals"] and all(g["holds"] is not False for g in run["result"]["goals"])
    finally:
        me.close()


def test_cancelling_the_run_task_action_stops_the_run_between_steps(served: tuple[str, Any]) -> None:
    url, _ = served
    me = Client(url)
    try:
        me.send(op="auth", mac=TOKEN)
        run_goal(me, "run")
        first = me.expect("action_feedback", RUN_WAIT)
        assert first["values"]["step"] == 1
        me.send(op="cancel_action_goal", id="run", action="/cbrs/run_task")
        feedback = [first["values"]]
        while (message := me.recv(RUN_WAIT))["op"] == "action_feedback":
            feedback.append(message["values"])
        assert message["op"] == "action_result", message
        assert (message["result"], message["status"]) == (True, GoalStatus.CANCELED)
        run = message["values"]
        assert run["status"] == "cancelled"
        execution = run["result"]["execution"]
        assert execution["status"] == "cancelled" and execution["reason"].startswith("cancelled on request after")
        done = [s for s in execution["steps"] if s["outcome"] == "succeeded"]
        assert len(feedback) == len(done) < len(run["result"]["plan"]["steps"])
    finally:
        me.close()
