"""A run started while one goes waits in the runner's queue (``run_queue``), runs in order, each planned at
its own start, and may be taken out of the queue; a full queue is refused saying so.

Found in the teacher's round (docs/web.md, "Tried by a teacher with a class"): of 15 students pressing Start
at once one run was taken and 14 got 409, each to start again by hand. No simulation here: each run is one
no plan comes of, held until the test lets it end (``refusal_in_home`` stubbed), so every wait is bounded
and short.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from types import SimpleNamespace
from typing import Any

import pytest
from flask.testing import FlaskClient

from cbrs import tasks as tasks_module
from cbrs.kb import KnowledgeBase
from cbrs.rosbridge import ServiceError
from cbrs.settings import setting
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.tasks import RunQueueFullError, TaskBusyError, TaskRunner
from cbrs.web import create_app
from tests.test_rosapi_typedefs import cbrs_types, mismatches

WAIT = 10.0


class Gates:
    """The stubbed runs: each (by its thread, ``cbrs-run-N``) records when it planned, then holds until
    its gate opens."""

    def __init__(self) -> None:
        self.gates: dict[str, threading.Event] = {}
        self.planned: list[tuple[str, float]] = []
        self.lock = threading.Lock()
        self.opened = False  # open_all: every gate, those of runs still to come too

    def gate(self, run_id: str) -> threading.Event:
        with self.lock:
            gate = self.gates.setdefault(run_id, threading.Event())
            if self.opened:
                gate.set()
            return gate

    def __call__(self, *_: Any, **__: Any) -> Any:
        run_id = threading.current_thread().name.removeprefix("cbrs-")
        with self.lock:
            self.planned.append((run_id, time.time()))
        self.gate(run_id).wait(WAIT)
        return SimpleNamespace(report=None, to_dict=dict)

    def open_all(self) -> None:
        with self.lock:
            self.opened = True
            gates = list(self.gates.values())
        for gate in gates:
            gate.set()


@pytest.fixture
def gates(monkeypatch: pytest.MonkeyPatch) -> Iterator[Gates]:
    held = Gates()
    monkeypatch.setattr(tasks_module, "refusal_in_home", held)
    monkeypatch.setattr(tasks_module, "require", lambda *_: None)  # the stub needs no simulation installed
    yield held
    held.open_all()


def _ended(runner: TaskRunner, run_id: str) -> bool:
    return runner.get(run_id).done.wait(WAIT)


def test_the_setting_is_0_by_default_and_a_runner_reads_it(bundled_kb: KnowledgeBase) -> None:
    assert setting("run_queue").resolve(environ={}) == 0
    assert setting("run_queue").resolve(environ={"CBRS_RUN_QUEUE": "15"}) == 15
    with pytest.raises(ValueError, match="CBRS_RUN_QUEUE"):
        setting("run_queue").resolve(environ={"CBRS_RUN_QUEUE": "-1"})
    with pytest.raises(ValueError, match="0 runs or more"):
        TaskRunner(bundled_kb, threading.RLock(), camera=None, queue=-2)


def test_runs_wait_in_order_each_planned_when_the_one_before_has_ended(bundled_kb: KnowledgeBase, gates: Gates) -> None:
    runner = TaskRunner(bundled_kb, threading.RLock(), camera=None, queue=2)
    heard: list[tuple[str, str]] = []
    runner.subscribe(lambda topic, m: heard.append((m["event"], m["run"])) if topic == "/cbrs/events" else None)
    try:
        first = runner.start("FetchMyPen")
        second = runner.start("FetchMyPen", seed=2)
        third = runner.start("FetchMyPen", seed=3)
        assert (first.status, second.status, third.status) == ("running", "queued", "queued")
        assert (second.position, third.position) == (1, 2)
        assert second.to_dict()["position"] == 1 and "position" not in first.to_dict()
        assert [r.id for r in runner.waiting()] == [second.id, third.id]
        with pytest.raises(RunQueueFullError) as full:
            runner.start("FetchMyPen")
        said = str(full.value)
        assert "queue is full" in said and "2 runs wait" in said and first.id in said
        assert full.value.http_status == 409 and full.value.running == first.id
        assert [run_id for run_id, _ in gates.planned] == [first.id]  # the queued have not planned yet
        gates.gate(first.id).set()
        assert _ended(runner, first.id)
        deadline = time.monotonic() + WAIT
        while runner.active() is not second or second.status != "running":
            assert time.monotonic() < deadline, "the next queued run did not start"
            time.sleep(0.01)
        assert third.position == 1 and third.status == "queued"
        gates.gate(second.id).set()
        gates.gate(third.id).set()
        assert _ended(runner, second.id) and _ended(runner, third.id)
        assert [r.status for r in (first, second, third)] == ["no-plan"] * 3
        planned = dict(gates.planned)
        assert [run_id for run_id, _ in gates.planned] == [first.id, second.id, third.id]
        assert first.finished is not None and second.finished is not None
        assert planned[second.id] >= first.finished and planned[third.id] >= second.finished
        events = [(e, r) for e, r in heard if e in ("run_started", "run_queued", "run_finished")]
        assert events == [
            ("run_started", first.id),
            ("run_queued", second.id),
            ("run_queued", third.id),
            ("run_finished", first.id),
            ("run_started", second.id),
            ("run_finished", second.id),
            ("run_started", third.id),
            ("run_finished", third.id),
        ]
        assert runner.active() is None and runner.waiting() == []
    finally:
        gates.open_all()
        runner.close(WAIT)


def test_a_queued_run_stopped_leaves_the_queue_and_those_behind_move_up(
    bundled_kb: KnowledgeBase, gates: Gates
) -> None:
    runner = TaskRunner(bundled_kb, threading.RLock(), camera=None, queue=3)
    try:
        first = runner.start("FetchMyPen")
        second, third = runner.start("FetchMyPen"), runner.start("FetchMyPen")
        runner.cancel(second.id)
        assert second.done.is_set() and second.status == "cancelled"
        assert second.reason is not None and "queue" in second.reason and second.finished is not None
        assert second.to_dict()["reason"] == second.reason and "position" not in second.to_dict()
        assert third.position == 1 and [r.id for r in runner.waiting()] == [third.id]
        # the bridge's types describe a queued run and a stopped one (cbrs/interfaces): a client that
        # checks an answer against them took position and reason for unknown fields
        types = cbrs_types()
        for run in (second, third):
            assert mismatches(types.response("cbrs/TaskStatus"), run.to_dict()) == []
            assert mismatches(types.response("cbrs/RunTask"), run.to_dict(with_events=False)) == []
        feedback = {"run": third.id, "iri": third.iri, "status": "queued", "reason": "queued behind the run going"}
        assert mismatches(types.message("cbrs/RunTaskFeedback"), feedback) == []
        assert first.status == "running" and not first.cancel_requested.is_set()
        gates.open_all()
        assert _ended(runner, first.id) and _ended(runner, third.id)
        assert third.status == "no-plan"
        assert second.id not in {run_id for run_id, _ in gates.planned}  # it never planned
    finally:
        gates.open_all()
        runner.close(WAIT)


def test_the_server_stopping_ends_the_queued_runs_cancelled_with_a_reason(
    bundled_kb: KnowledgeBase, gates: Gates
) -> None:
    runner = TaskRunner(bundled_kb, threading.RLock(), camera=None, queue=2)
    first = runner.start("FetchMyPen")
    second, third = runner.start("FetchMyPen"), runner.start("FetchMyPen")
    closing = threading.Thread(target=runner.close, args=(WAIT,))
    closing.start()
    try:
        assert second.done.wait(WAIT) and third.done.wait(WAIT)
        for queued in (second, third):
            assert queued.status == "cancelled" and queued.reason is not None and "server stopped" in queued.reason
    finally:
        gates.open_all()
        closing.join(WAIT)
    assert first.status == "no-plan"
    assert [run_id for run_id, _ in gates.planned] == [first.id]


def test_without_a_queue_a_second_run_is_refused_as_before(bundled_kb: KnowledgeBase, gates: Gates) -> None:
    runner = TaskRunner(bundled_kb, threading.RLock(), camera=None, queue=0)
    try:
        first = runner.start("FetchMyPen")
        with pytest.raises(TaskBusyError) as busy:
            runner.start("FetchMyPen")
        assert not isinstance(busy.value, RunQueueFullError)
        assert str(busy.value) == f"task run {first.id} is still going; one task runs at a time"
    finally:
        gates.open_all()
        runner.close(WAIT)


def test_runs_kept_forget_only_those_that_ended(bundled_kb: KnowledgeBase, gates: Gates) -> None:
    runner = TaskRunner(bundled_kb, threading.RLock(), keep=2, camera=None, queue=3)
    try:
        ids = [runner.start("FetchMyPen").id for _ in range(4)]
        assert [r.id for r in runner.runs()] == ids  # nothing ended: all kept beyond keep
        gates.gate(ids[0]).set()
        assert _ended(runner, ids[0])
        runner.cancel(ids[3])
        runner.start("FetchMyPen")  # room again: the oldest ended are forgotten first
        kept = [r.id for r in runner.runs()]
        assert ids[0] not in kept and ids[1] in kept and ids[2] in kept
    finally:
        gates.open_all()
        runner.close(WAIT)


# -- the tasks page and the bridge's handlers over the queue ----------------------------------------


@pytest.fixture
def web(bundled_kb: KnowledgeBase, gates: Gates) -> Iterator[tuple[FlaskClient, TaskRunner]]:
    service = SparqlService(bundled_kb, EndpointConfig(update_token="teacher"))
    runner = TaskRunner(bundled_kb, service.lock, camera=None, queue=1)
    try:
        yield create_app(service, tasks=runner).test_client(), runner
    finally:
        gates.open_all()
        runner.close(WAIT)


def test_the_page_queues_a_start_while_a_run_goes_shows_its_place_and_refuses_a_full_queue(
    web: tuple[FlaskClient, TaskRunner], gates: Gates
) -> None:
    client, runner = web
    teacher, student, other = ({"REMOTE_ADDR": f"10.0.0.{n}"} for n in (1, 2, 3))
    first = client.post("/tasks.json", data={"task": "FetchMyPen"}, environ_base=teacher)
    assert first.status_code == 202
    running = first.get_json()["started"]["id"]
    queued = client.post("/tasks.json", data={"task": "FetchMyPen"}, environ_base=student)
    assert queued.status_code == 202, queued.get_json()
    started = queued.get_json()["started"]
    run_id = started["id"]
    assert started["status"] == "queued" and started["position"] == 1 and started["in_line"] == "next in line"
    assert queued.headers["Location"] == f"/tasks/{run_id}.json"
    assert "queued" in queued.get_json()["message"] and "next in line" in queued.get_json()["message"]
    full = client.post("/tasks.json", data={"task": "FetchMyPen"}, environ_base=other)
    assert full.status_code == 409
    assert "queue is full" in full.get_json()["message"] and "1 run waits" in full.get_json()["message"]
    assert full.get_json()["running"] == running
    listing = client.get("/tasks.json").get_json()
    assert [(r["id"], r["status"], r.get("in_line")) for r in listing["runs"][:2]] == [
        (run_id, "queued", "next in line"),
        (running, "running", None),
    ]
    page = client.get(f"/tasks/{run_id}").get_data(as_text=True)
    assert 'id="in-line"' in page and "next in line" in page and "status-queued" in page
    assert 'id="cancel"' in page and 'id="cancel" class="cancel-form" action' in page
    assert 'hidden>\n      <button type="submit" id="cancel-button"' not in page  # Stop shows for a queued run
    tasks_page = client.get("/tasks").get_data(as_text=True)
    assert "a queue of 1" in tasks_page
    # the same who-may-stop rules as for a run going: another computer's page is refused
    refused = client.post(f"/tasks/{run_id}/cancel.json", environ_base=other)
    assert refused.status_code == 403 and runner.get(run_id).status == "queued"
    stopped = client.post(f"/tasks/{run_id}/cancel.json", environ_base=student)
    assert stopped.status_code == 202, stopped.get_json()
    assert "taken out of the queue" in stopped.get_json()["message"]
    after = client.get(f"/tasks/{run_id}.json").get_json()["run"]
    assert after["status"] == "cancelled" and "queue" in after["reason"] and "without starting" in after["verdict"]
    assert runner.get(running).status == "running" and runner.waiting() == []
    again = client.post(f"/tasks/{run_id}/cancel.json", environ_base=student)
    assert again.status_code == 409


def test_the_bridge_queues_a_goal_says_so_and_its_cancel_takes_it_out(
    web: tuple[FlaskClient, TaskRunner], gates: Gates
) -> None:
    from cbrs.bridge_services import KnowledgeServices

    _, runner = web
    services = KnowledgeServices(SparqlService(runner.kb), runner)
    going = services.run_task({"task": "FetchMyPen", "wait": False})
    assert going["status"] == "running"

    class Goal:
        def __init__(self) -> None:
            self.args = {"task": "FetchMyPen"}
            self.feedback: list[dict[str, Any]] = []
            self.cancel: Any = None
            self.fed = threading.Event()

        def publish_feedback(self, message: dict[str, Any]) -> None:
            self.feedback.append(message)
            self.fed.set()

        def on_cancel(self, call: Any) -> None:
            self.cancel = call

    goal = Goal()
    results: list[Any] = []
    worker = threading.Thread(target=lambda: results.append(services.run_task_goal(goal)))  # type: ignore[arg-type]
    worker.start()
    try:
        assert goal.fed.wait(WAIT)
        said = goal.feedback[0]
        assert said["status"] == "queued" and "next in line" in said["reason"]
        deadline = time.monotonic() + WAIT
        while goal.cancel is None:
            assert time.monotonic() < deadline
            time.sleep(0.01)
        with pytest.raises(ServiceError, match="queue is full"):
            services.run_task({"task": "FetchMyPen", "wait": False})  # the queue of 1 is full
        goal.cancel()
        worker.join(WAIT)
        assert not worker.is_alive()
        [result] = results
        assert result.status.name == "CANCELED" and result.values["status"] == "cancelled"
        assert "queue" in result.values["reason"]
        assert runner.get(going["id"]).status == "running"
    finally:
        gates.open_all()
        worker.join(WAIT)


def test_over_the_bridge_a_goal_waits_in_the_queue_and_its_cancel_takes_it_out(
    fresh_bundled_kb: KnowledgeBase, gates: Gates, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``/cbrs/run_task`` over a real websocket of ``cbrs serve`` (``CBRS_RUN_QUEUE=1``): a goal while a run
    goes is said queued, a third is refused naming the full queue, a cancel ends the queued one CANCELED."""
    from cbrs.rosbridge import GoalStatus
    from cbrs.server import ServeConfig, Server
    from tests.test_rosbridge import Client

    monkeypatch.setenv("CBRS_RUN_QUEUE", "1")
    server = Server(fresh_bundled_kb, ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token="t")))
    server.start()
    me = Client(f"ws://127.0.0.1:{server.bridge_port}")

    def goal(goal_id: str) -> None:
        args = {"task": "FetchMyPen"}
        me.send(
            op="send_action_goal",
            id=goal_id,
            action="/cbrs/run_task",
            action_type="cbrs/action/RunTask",
            args=args,
            feedback=True,
        )

    def until(op: str, goal_id: str) -> dict[str, Any]:
        for _ in range(20):  # bounded: status messages and other goals' feedback come between
            message = me.recv(WAIT)
            if message["op"] == op and message.get("id") == goal_id:
                return message
        raise AssertionError(f"no {op} for {goal_id}")

    try:
        me.send(op="auth", mac="t")
        goal("first")
        deadline = time.monotonic() + WAIT
        while server.tasks.active() is None:
            assert time.monotonic() < deadline
            time.sleep(0.01)
        goal("second")
        queued = until("action_feedback", "second")["values"]
        assert queued["status"] == "queued" and queued["reason"] == "queued behind the run going: next in line"
        status = me.call("/cbrs/task_status", {"run": queued["run"]})["values"]
        assert status["status"] == "queued" and status["position"] == 1
        goal("third")
        full = until("action_result", "third")
        assert full["result"] is False and "queue is full" in str(full["values"])
        me.send(op="cancel_action_goal", id="second", action="/cbrs/run_task")
        ended = until("action_result", "second")
        assert ended["status"] == GoalStatus.CANCELED
        assert ended["values"]["status"] == "cancelled" and "queue" in ended["values"]["reason"]
        gates.open_all()
        first = until("action_result", "first")
        assert first["values"]["status"] == "no-plan"
    finally:
        gates.open_all()
        me.close()
        server.stop(timeout=WAIT)


def test_cbrs_serve_takes_the_queue_as_an_option_and_its_runner_holds_it(monkeypatch: pytest.MonkeyPatch) -> None:
    """``cbrs serve --run-queue N`` (the environment variable was the only way), and the server's runner
    queues as many as its configuration says; a negative count is a usage error."""
    from click.testing import CliRunner

    import cbrs.server
    from cbrs.cli import cli

    seen: list[int] = []

    class Stopped(Exception):
        pass

    def built(kb: KnowledgeBase, config: Any) -> Any:
        seen.append(config.run_queue)
        raise Stopped

    monkeypatch.setattr(cbrs.server, "Server", built)
    monkeypatch.delenv("CBRS_RUN_QUEUE", raising=False)
    serve = ["--store", ":memory:", "serve", "--port", "0", "--bridge-port", "0"]
    for options, expected in (([], 0), (["--run-queue", "12"], 12)):
        result = CliRunner().invoke(cli, [*serve, *options])
        assert isinstance(result.exception, Stopped), result.output
        assert seen[-1] == expected
    refused = CliRunner().invoke(cli, [*serve, "--run-queue", "-1"])
    assert refused.exit_code == 2 and "--run-queue" in refused.output
    monkeypatch.undo()
    config = cbrs.server.ServeConfig(port=0, bridge_port=0, run_queue=5)
    server = cbrs.server.Server(KnowledgeBase.open(":memory:"), config)
    try:
        assert server.tasks.queue_size == 5
    finally:
        server.stop(WAIT)
