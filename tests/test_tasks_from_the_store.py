"""The web page and the bridge run any task the store can express, named as ``cbrs run`` takes it.

A task loaded from Turtle under a namespace of its own (``lab:``) is offered by the tasks page and by
``/cbrs/tasks``, runs from either by its bare name, and a misspelt one is refused with a did-you-mean.
Loopback only; every wait is bounded.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.tasks import TaskRunner
from cbrs.web import create_app
from tests.helpers_threads import assert_threads_end
from tests.test_serve import bridge, call

TASKS = Path(__file__).parent / "data" / "tasks"
LAB = "http://example.org/lab#"
HOME, WORLD = PREFIXES["home"], PREFIXES["world"]
TOKEN = "tasks-test-token"
WAIT = 10.0
RUN_WAIT = 120.0


def lab_task(tmp_path: Path) -> Path:
    """The pencil-fetching task of tests/data/tasks, written under the lab's own namespace."""
    text = (TASKS / "fetch_my_pencil.ttl").read_text(encoding="utf-8")
    text = f"@prefix lab: <{LAB}> .\n" + text.replace("req:FetchMyPencil a", "lab:FetchMyPencil a")
    assert "lab:FetchMyPencil a" in text
    written = tmp_path / "lab_task.ttl"
    written.write_text(text, encoding="utf-8")
    return written


@pytest.fixture
def kb(tmp_path: Path) -> Iterator[KnowledgeBase]:
    opened = KnowledgeBase.open(":memory:")
    opened.load([TASKS / "pencil_on_the_table.ttl"], graph="map")
    opened.load([lab_task(tmp_path)], graph="requirements")
    yield opened
    opened.close()


@pytest.fixture
def web(kb: KnowledgeBase) -> Iterator[tuple[FlaskClient, TaskRunner]]:
    sparql = SparqlService(kb)
    runner = TaskRunner(kb, sparql.lock, camera=None)
    yield create_app(sparql, tasks=runner).test_client(), runner
    runner.close(RUN_WAIT)


@pytest.fixture
def server(kb: KnowledgeBase) -> Iterator[Server]:
    threads = threading.active_count()
    running = Server(kb, ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN)))
    running.start()
    yield running
    running.stop(timeout=WAIT)
    assert_threads_end(threads, WAIT)


def test_the_tasks_page_offers_every_task_of_the_store(web: tuple[FlaskClient, TaskRunner]) -> None:
    client, _ = web
    shown = client.get("/tasks.json").get_json()
    assert {"FetchMyPencil", "FetchMyPen", "RobotArmServeACup"} <= set(shown["tasks"])
    assert shown["form"]["task"] == "FetchMyPen"  # the paper's web-initiated scenario comes first
    assert '<option value="FetchMyPencil">' in client.get("/tasks").text


def test_a_misspelt_task_is_a_field_error_with_the_likely_one(web: tuple[FlaskClient, TaskRunner]) -> None:
    client, runner = web
    response = client.post("/tasks.json", data={"task": "FetchMyPencl"})
    assert response.status_code == 400
    assert "did you mean FetchMyPencil" in response.get_json()["fields"]["task"]
    page = client.post("/tasks", data={"task": "FetchMyPencl"}).text
    assert 'id="task-error"' in page and '<option value="FetchMyPencl" selected>' in page  # what was sent stays
    assert runner.runs() == []


@pytest.mark.parametrize("value", ["-1", "twice"])
def test_a_bad_repeat_bound_is_a_field_error(web: tuple[FlaskClient, TaskRunner], value: str) -> None:
    client, runner = web
    response = client.post("/tasks.json", data={"task": "FetchMyPencil", "repeat_failures": value})
    assert response.status_code == 400 and value in response.get_json()["fields"]["repeat_failures"]
    assert runner.runs() == []


def test_a_turtle_task_of_another_namespace_runs_from_the_page(
    web: tuple[FlaskClient, TaskRunner], kb: KnowledgeBase
) -> None:
    """The task is also a new object fetched by a goal-only task, written only in Turtle (the pencil on
    the kitchen table, tests/data/tasks): no hierarchy orders its steps, NavigateToPlace deletes "near
    the person" so it goes first, and the pen stays where it was. (tests/test_knowledge_driven.py's
    other tasks written in Turtle run in process.)"""
    client, runner = web
    response = client.post("/tasks.json", json={"task": "FetchMyPencil", "repeat_failures": 0})
    assert response.status_code == 202, response.get_json()
    started = response.get_json()["started"]
    assert started["iri"] == LAB + "FetchMyPencil" and started["repeat_failures"] == 0
    assert runner.get(started["id"]).done.wait(RUN_WAIT), "the run did not end"
    run = client.get(f"/tasks/{started['id']}.json").get_json()["run"]
    assert run["status"] == "succeeded", run.get("error") or run["result"]["execution"]
    assert run["result"]["plan"]["requirement"] == LAB + "FetchMyPencil"
    order = [step["planned"].rsplit("#", 1)[-1] for step in run["result"]["execution"]["steps"]]
    assert order.index("NavigateToPlace_P3DX01") < order.index("HandOverOntoPlatform_CytonDualArm01")
    assert order.index("HandOverOntoPlatform_CytonDualArm01") < order.index("NavigateToPerson_P3DX01")
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    assert (WORLD + "Pencil1", HOME + "isWith", WORLD + "Person") in facts
    assert (WORLD + "Pen", HOME + "isLocatedOn", WORLD + "KitchenTable") in facts  # the pen stayed


def test_the_bridge_lists_and_checks_the_stores_tasks(server: Server) -> None:
    with bridge(server, TOKEN) as ws:
        listed = call(ws, "/cbrs/tasks", {})
        misspelt = call(ws, "/cbrs/run_task", {"task": "FetchMyPencl"})
        negative = call(ws, "/cbrs/run_task", {"task": "FetchMyPencil", "repeat_failures": -1})
        wrong_type = call(ws, "/cbrs/run_task", {"task": "FetchMyPencil", "repeat_failures": "1"})
        planned = call(ws, "/cbrs/plan", {"task": "FetchMyPencil"})
        misplanned = call(ws, "/cbrs/plan", {"task": "FetchMyPencl"})
    assert listed["result"] is True and "FetchMyPencil" in listed["values"]["tasks"]
    assert misspelt["result"] is False and "did you mean FetchMyPencil" in misspelt["values"]
    assert negative["result"] is False and "max_repeats = -1" in negative["values"]
    assert wrong_type["result"] is False and "'repeat_failures' must be int" in wrong_type["values"]
    assert planned["result"] is True and planned["values"]["requirement"] == LAB + "FetchMyPencil"
    assert misplanned["result"] is False and "did you mean FetchMyPencil" in misplanned["values"]
    assert server.tasks.runs() == []


def test_a_run_longer_than_the_wait_is_answered_running_not_failed(kb: KnowledgeBase) -> None:
    """/cbrs/run_task with wait answers before the bridge's call timeout would fail the call, with the run
    as it is then; the run goes on to its end. Any task shows it: the one-step RobotSelfPosition, whose
    world alone takes longer to build than the wait (the lab's task runs end to end from the page)."""
    from cbrs.bridge_services import KnowledgeServices

    sparql = SparqlService(kb)
    runner = TaskRunner(kb, sparql.lock, camera=None)
    services = KnowledgeServices(sparql, runner)
    services.wait_limit = 0.2  # the run takes a second or more
    try:
        answer = services.run_task({"task": "RobotSelfPosition", "wait": True})
        assert answer["status"] == "running"
        assert runner.get(answer["id"]).done.wait(RUN_WAIT), "the run did not end"
        assert services.task_status({"run": answer["id"]})["status"] == "succeeded"
    finally:
        runner.close(RUN_WAIT)


def test_a_refused_run_is_one_warning_not_a_traceback(kb: KnowledgeBase, caplog: pytest.LogCaptureFixture) -> None:
    """A run refused on purpose (two pens: which to fetch?) ends with status error and the reason, logged
    as one line; the server logged a full traceback at ERROR for it."""
    second_pen = Path(__file__).parent / "data" / "second_pen.ttl"
    kb.load([second_pen], graph="map")
    runner = TaskRunner(kb, threading.RLock(), camera=None)
    try:
        with caplog.at_level(logging.INFO, logger="cbrs"):
            run = runner.run("FetchMyPen", timeout=RUN_WAIT)
    finally:
        runner.close(RUN_WAIT)
    assert run.status == "error" and run.error is not None and run.error.startswith("AmbiguousDesignatorError")
    refused = [r for r in caplog.records if run.id in r.getMessage()]
    assert refused and all(r.levelno == logging.WARNING and r.exc_info is None for r in refused)
