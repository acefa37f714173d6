"""A run started on ``cbrs serve`` (``POST /tasks``, the ``/cbrs/run_task`` service and action) refuses a
task no plan can come of before it builds the simulated home, as ``cbrs run`` does
(``cbrs.tasks.refusal_in_home``): it ends ``no-plan`` with the answer ``cbrs run --json`` gives, and
clients hear of it as before (``run_started``, ``run_finished`` on ``/cbrs/events``; the action ABORTED).
``open_world`` is replaced by one that fails the run: no world is built here, which is the point."""

from __future__ import annotations

import json
import time
import urllib.request
from collections.abc import Iterator
from typing import Any, cast

import pytest
from click.testing import CliRunner

from cbrs.actions.composer import Composer
from cbrs.bridge_client import BridgeClient
from cbrs.cli import cli
from cbrs.kb.namespaces import PREFIXES
from cbrs.rosbridge import GoalStatus
from cbrs.server import Server
from cbrs.tasks import refusal_in_home
from tests.test_live_components import TOKEN, live_server
from tests.test_rosbridge import Client

TASK, SEED = "RouteToGoal", 4  # no component of the bundled store offers a route
WAIT = 20.0


@pytest.fixture(scope="module")
def built() -> Iterator[list[str]]:
    """The worlds asked for (none should be): ``open_world`` fails whoever calls it."""
    asked: list[str] = []

    def refuse(*_: Any, **__: Any) -> Any:
        asked.append("open_world")
        raise AssertionError("the simulated home was built")

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr("cbrs.sim.world.open_world", refuse)
        yield asked


@pytest.fixture(scope="module")
def server(built: list[str]) -> Iterator[Server]:
    with live_server() as running:
        yield running


@pytest.fixture(scope="module")
def expected(built: list[str]) -> dict[str, Any]:
    """What ``cbrs run --json`` answers for the task (refused early too), without its seed."""
    answer = CliRunner().invoke(cli, ["--store", ":memory:", "run", TASK, "--json", "--seed", str(SEED)])
    assert answer.exit_code == 1, answer.output
    found = json.loads(answer.output)
    assert found.pop("seed") == SEED and found["status"] == "unsolvable"
    return dict(found)


def _ended(server: Server, run_id: str) -> None:
    assert server.tasks.get(run_id).done.wait(WAIT), f"{run_id} did not end within {WAIT:g} s"


def test_a_run_posted_over_http_ends_no_plan_without_a_world(
    server: Server, expected: dict[str, Any], built: list[str]
) -> None:
    heard: list[tuple[str, dict[str, Any]]] = []
    unsubscribe = server.tasks.subscribe(lambda topic, message: heard.append((topic, message)))
    base = f"http://127.0.0.1:{server.http_port}"
    body = json.dumps({"task": TASK, "seed": SEED}).encode()
    headers = {"Content-Type": "application/json", "Authorization": f"Bearer {TOKEN}"}
    try:
        with urllib.request.urlopen(urllib.request.Request(f"{base}/tasks.json", body, headers), timeout=WAIT) as got:
            assert got.status == 202
            location = got.headers["Location"]
            run_id = json.load(got)["started"]["id"]
        _ended(server, run_id)
    finally:
        unsubscribe()
    with urllib.request.urlopen(base + location, timeout=WAIT) as got:
        run = json.load(got)["run"]
    assert run["status"] == "no-plan" and "error" not in run, run.get("error")
    assert run["result"] == expected and run["result"]["sim_seconds"] == 0.0
    assert run["events"] == [] and built == []
    assert [(topic, m["event"], m.get("status")) for topic, m in heard if m.get("run") == run_id] == [
        ("/cbrs/events", "run_started", None),
        ("/cbrs/events", "run_finished", "no-plan"),
    ]


def test_the_run_task_service_answers_no_plan_without_a_world(
    server: Server, expected: dict[str, Any], built: list[str]
) -> None:
    with BridgeClient(f"ws://127.0.0.1:{server.bridge_port}", TOKEN, timeout=WAIT) as client:
        run = client.call_sync("/cbrs/run_task", {"task": TASK, "seed": SEED, "wait": True})
    assert run["status"] == "no-plan" and run["result"] == expected and built == []


def test_the_run_task_action_is_aborted_with_the_no_plan_answer_and_no_feedback(
    server: Server, expected: dict[str, Any], built: list[str]
) -> None:
    me = Client(f"ws://127.0.0.1:{server.bridge_port}")
    try:
        me.send(op="auth", mac=TOKEN)
        me.send(op="subscribe", topic="/cbrs/events")
        me.send(
            op="send_action_goal",
            id="route",
            action="/cbrs/run_task",
            action_type="cbrs/action/RunTask",
            args={"task": TASK, "seed": SEED},
            feedback=True,
        )
        received: list[dict[str, Any]] = []
        deadline = time.monotonic() + WAIT
        while not any(m["op"] == "action_result" for m in received) and time.monotonic() < deadline:
            received.append(me.recv(WAIT))
    finally:
        me.close()
    (result,) = [m for m in received if m["op"] == "action_result"]
    assert (result["result"], result["status"], result["id"]) == (True, GoalStatus.ABORTED, "route")
    run = result["values"]
    assert run["status"] == "no-plan" and run["result"] == expected and built == []
    assert not [m for m in received if m["op"] == "action_feedback"]
    events = [m["msg"] for m in received if m["op"] == "publish" and m["msg"].get("run") == run["id"]]
    assert [e["event"] for e in events][:1] == ["run_started"]


def test_while_the_bridge_passes_components_over_the_home_is_built_so_the_answer_names_them(
    server: Server, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A run names the components it passes over (their calls timed out) in its answer, which the early
    refusal does not know of: with any passed over, the run builds the home as before."""
    monkeypatch.setattr("cbrs.actions.breaker.passed_over", lambda *_: {"urn:x:Thermometer": "timed out"})
    composer = Composer(server.kb)
    assert refusal_in_home(server.kb, PREFIXES["req"] + TASK, composer, transport=cast(Any, object())) is None
    assert refusal_in_home(server.kb, PREFIXES["req"] + TASK, composer) is not None
