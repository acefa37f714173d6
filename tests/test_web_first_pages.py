"""The first pages after a start: what they read is read once per store generation, a big store has it
read in the background at start (``cbrs.web.warmup``), the camera's first picture shows at once, and the
tasks page starts with a task chosen by a rule over the store's data rather than a name in the code.

Timings are in docs/web.md ("The first pages after a start"), not asserted here.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from flask import Flask

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.tasks import TaskRun, TaskRunner
from cbrs.web import context, create_app, tasks, warmup

KEYS = (
    "derived_prefixes",
    "overview",
    "match_requirements",
    "match_concepts",
    "task_choices",
    "plan_tasks",
    "taxonomy",
)


def app_over(kb: KnowledgeBase, camera: str | None = None) -> Flask:
    sparql = SparqlService(kb)
    return create_app(sparql, tasks=TaskRunner(kb, sparql.lock, camera=camera))


def test_the_matchmaking_page_reads_the_requirements_once_a_store_generation(
    bundled_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls: list[int] = []
    real = KnowledgeBase.requirements
    monkeypatch.setattr(KnowledgeBase, "requirements", lambda self: calls.append(1) or real(self))
    client = app_over(bundled_kb).test_client()
    first, second = (client.get("/match.json").get_json() for _ in range(2))
    assert first["requirements"] == second["requirements"] and len(first["requirements"]) > 5
    assert len(calls) == 1  # every page read them all again: 0.6 s a page on OWLS-TC


def test_a_big_store_has_its_first_pages_read_at_start(bundled_kb: KnowledgeBase) -> None:
    app = app_over(bundled_kb)
    assert warmup.warm_up(app) is None  # the bundled store (7,800 triples) is read fast enough as it is
    app.config["CBRS_WARM_UP_TRIPLES"] = 0  # as if it were big
    state = warmup.warm_up(app)
    assert state is not None and state.finished.wait(60)
    assert state.done == len(state.steps) and state.note() is None
    with app.app_context():
        assert [key for key in KEYS if not context.kept(key)] == []
    page = app.test_client().get("/").text
    assert "Getting ready" not in page


def test_pages_say_what_is_being_read_while_it_is() -> None:
    state = warmup.WarmUp(("the store's namespaces", "the taxonomy index"), done=1, current="the taxonomy index")
    assert state.note() == (
        "Getting ready: reading the taxonomy index (step 2 of 2); a page that needs it waits for it."
    )


@pytest.fixture
def camera_app(bundled_kb: KnowledgeBase) -> Iterator[tuple[Flask, TaskRunner]]:
    app = app_over(bundled_kb, camera="a camera")
    runner: TaskRunner = app.extensions["cbrs.tasks"]
    runner._publish_frame(b"\xff\xd8 a picture \xff\xd9", None)  # as the idle home's render gives it
    app.config.update(CBRS_STREAM_IDLE_SECONDS=0.2, CBRS_CAMERA_REPEAT_SECONDS=3600.0)
    yield app, runner
    runner.close(5)


def test_the_camera_stream_sends_its_first_picture_twice_at_once(camera_app: tuple[Flask, TaskRunner]) -> None:
    """A browser shows a part of the stream once the next begins: the first picture (and the tasks
    page's load) waited for the repeat, two seconds later. With no repeat before the stream ends, it
    still sends two parts."""
    app, _ = camera_app
    stream = app.test_client().get("/camera.mjpg", buffered=False)
    parts = list(stream.response)
    stream.close()
    assert len(parts) == 2 and parts[0] == parts[1] and b"X-Frame: 1" in parts[0]


def test_the_start_form_chooses_a_task_of_several_steps_by_the_store_s_data(fresh_bundled_kb: KnowledgeBase) -> None:
    """FetchMyPen was a name in the code; the form now starts with the first requirement (by name) that
    asks for an action with sub-actions. Without req:FetchMyPen that is RobotArmServeACup, where the old
    rule chose whatever "FetchMyPen" named (here the action, which no requirement asks for)."""
    client = app_over(fresh_bundled_kb).test_client()
    assert client.get("/tasks.json").get_json()["form"]["task"] == "FetchMyPen"
    fresh_bundled_kb.update("DELETE WHERE { GRAPH graph:requirements { req:FetchMyPen ?p ?o } }")
    body = client.get("/tasks.json").get_json()
    assert body["tasks"][0] == "FallDownAlert"  # "FetchMyPen" now names the action, which no requirement asks for
    assert body["form"]["task"] == "RobotArmServeACup"
    assert client.get("/tasks.json?task=RoomTemperature").get_json()["form"]["task"] == "RoomTemperature"


def test_the_start_form_chooses_the_latest_run_s_task_again(bundled_kb: KnowledgeBase) -> None:
    app = app_over(bundled_kb)
    with app.app_context():
        offered = tasks.choices()
        ran = TaskRun("run-1", "req:RoomTemperature", 0, (), iri="https://w3id.org/cbrs/requirement#RoomTemperature")
        assert tasks._first_choice(offered, ran) == "RoomTemperature"  # as the list spells it
        assert tasks._first_choice(offered, None) == "FetchMyPen"


def test_the_tasks_page_says_there_is_no_run_yet(bundled_kb: KnowledgeBase) -> None:
    page = app_over(bundled_kb).test_client().get("/tasks").text
    assert "No run yet: start one above" in page  # the steps table stood empty under "Latest run none yet"
