"""``POST /tasks`` answers a program as ``/tasks.json`` does when it prefers JSON, and both say where the run is.

A new lab's program posted a run to ``/tasks`` with ``Accept: application/json`` and got the HTML page
(202, no ``Location``): the run's id could only be scraped from it. The runs here end at once without
the simulation (:class:`_Held`): these tests are about the HTTP answers, not the runs.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.tasks import TaskRun, TaskRunner
from cbrs.web import create_app

BROWSER = "text/html,application/xhtml+xml,application/xml;q=0.9,*/*;q=0.8"
JSON = {"Accept": "application/json"}
WAIT = 10.0


class _Held(TaskRunner):
    """A runner whose runs end when ``release`` is set (at once unless a test holds it): no world, no plan."""

    def __init__(self, kb: KnowledgeBase, lock: threading.RLock) -> None:
        super().__init__(kb, lock, camera=None)
        self.release = threading.Event()
        self.release.set()

    def _run(self, run: TaskRun) -> None:
        self.release.wait(WAIT)
        run.status = "succeeded"
        run.done.set()


@pytest.fixture(scope="module")
def served(bundled_kb: KnowledgeBase) -> Iterator[tuple[FlaskClient, _Held]]:
    sparql = SparqlService(bundled_kb)
    runner = _Held(bundled_kb, sparql.lock)
    yield create_app(sparql, tasks=runner).test_client(), runner
    runner.release.set()


def _ended(runner: _Held, run_id: str) -> None:
    assert runner.get(run_id).done.wait(WAIT)


@pytest.mark.parametrize(
    ("path", "headers"),
    [
        pytest.param("/tasks", JSON, id="accept-json"),
        pytest.param("/tasks", {"Accept": "application/json, text/html;q=0.5"}, id="json-ranked-first"),
        pytest.param("/tasks", {}, id="json-body-no-accept"),
        pytest.param("/tasks", {"Accept": "*/*"}, id="json-body-any"),
        pytest.param("/tasks.json", {}, id="twin"),
    ],
)
def test_a_program_gets_the_run_in_json_and_its_location(
    served: tuple[FlaskClient, _Held], path: str, headers: dict[str, str]
) -> None:
    client, runner = served
    answer = client.post(path, json={"task": "FetchMyPen", "seed": 1}, headers=headers)
    assert answer.status_code == 202 and answer.mimetype == "application/json", answer.text[:200]
    started = answer.get_json()["started"]
    assert started["task"] == "FetchMyPen" and started["seed"] == 1
    assert answer.headers["Location"] == f"/tasks/{started['id']}.json" == started["url"]
    assert started["page"] == f"/tasks/{started['id']}"  # for a person to open
    _ended(runner, started["id"])
    status = client.get(answer.headers["Location"])
    assert status.status_code == 200 and status.get_json()["run"]["id"] == started["id"]
    assert status.get_json()["run"]["status"] == "succeeded"


def test_a_browser_form_gets_the_page_and_the_run_page_as_its_location(served: tuple[FlaskClient, _Held]) -> None:
    """A browser is sent on to the run's page (303, Post/Redirect/Get), the page in the body all the same."""
    client, runner = served
    answer = client.post("/tasks", data={"task": "FetchMyPen"}, headers={"Accept": BROWSER})
    assert answer.status_code == 303 and answer.mimetype == "text/html"
    run_id = answer.headers["Location"].removeprefix("/tasks/")
    assert run_id.startswith("run-") and f"{run_id} started" in answer.text
    assert "Accept" in answer.headers.get("Vary", "")  # one URL, two answers: caches key on Accept
    _ended(runner, run_id)
    assert client.get(f"/tasks/{run_id}", headers={"Accept": BROWSER}).mimetype == "text/html"
    assert client.get(f"/tasks/{run_id}", headers=JSON).get_json()["run"]["id"] == run_id


def test_a_form_post_without_accept_keeps_the_page(served: tuple[FlaskClient, _Held]) -> None:
    """curl's form post (``*/*``) got the page before; it still does."""
    client, runner = served
    answer = client.post("/tasks", data={"task": "FetchMyPen"}, headers={"Accept": "*/*"})
    assert answer.status_code == 202 and answer.mimetype == "text/html"
    _ended(runner, answer.headers["Location"].removeprefix("/tasks/"))


@pytest.mark.parametrize(
    ("body", "field", "says"),
    [
        pytest.param({"task": "FetchMyPen", "sed": 2}, "sed", "did you mean 'seed'?", id="misspelt-field"),
        pytest.param({"task": "FetchMyPn"}, "task", "FetchMyPen", id="misspelt-task"),
        pytest.param({"task": "FetchMyPen", "seed": "two"}, "seed", "'two' is not a whole number", id="bad-seed"),
        pytest.param({"task": "FetchMyPen", "fault_rate": 2}, "fault_rate", "between 0 and 1", id="bad-rate"),
    ],
)
def test_a_program_gets_a_json_error_naming_the_field(
    served: tuple[FlaskClient, _Held], body: dict[str, object], field: str, says: str
) -> None:
    client, _ = served
    answer = client.post("/tasks", json=body, headers=JSON)
    assert answer.status_code == 400 and answer.mimetype == "application/json"
    error = answer.get_json()
    assert error["error"] == "invalid-form" and says in error["fields"][field]
    assert "Location" not in answer.headers
    if field == "sed":
        return  # a form's fields are the page's own: a browser sends no other
    page = client.post("/tasks", data={k: str(v) for k, v in body.items()}, headers={"Accept": BROWSER})
    assert page.mimetype == "text/html" and page.status_code == 400  # the form again, with the message
    assert f'id="{field}-error"' in page.text


def test_a_body_that_is_no_object_and_another_sites_post_are_json_errors(served: tuple[FlaskClient, _Held]) -> None:
    client, _ = served
    broken = client.post("/tasks", data="{task:", headers={**JSON, "Content-Type": "application/json"})
    assert broken.status_code == 400 and broken.mimetype == "application/json"
    assert "the body is not JSON" in broken.get_json()["message"]
    foreign = client.post(
        "/tasks", json={"task": "FetchMyPen"}, headers={**JSON, "Origin": "https://elsewhere.example"}
    )
    assert foreign.status_code == 403 and foreign.mimetype == "application/json"
    assert "https://elsewhere.example" in foreign.get_json()["message"]
    missing = client.get("/tasks/run-999", headers=JSON)
    assert missing.status_code == 404 and missing.mimetype == "application/json"


def test_a_second_start_is_refused_in_json_naming_the_run_going(served: tuple[FlaskClient, _Held]) -> None:
    client, runner = served
    runner.release.clear()
    try:
        first = client.post("/tasks", json={"task": "FetchMyPen"}, headers=JSON)
        assert first.status_code == 202
        second = client.post("/tasks", json={"task": "FetchMyPen"}, headers=JSON)
        assert second.status_code == 409 and second.mimetype == "application/json"
        refused = second.get_json()
        assert refused["error"] == "busy" and refused["running"] == first.get_json()["started"]["id"]
        assert "Location" not in second.headers
    finally:
        runner.release.set()
    _ended(runner, first.get_json()["started"]["id"])


def test_a_browsers_stop_is_sent_on_to_the_runs_page_and_a_programs_gets_202(
    served: tuple[FlaskClient, _Held],
) -> None:
    """Stop's plain form POST (no script) is answered as Start's is: 303 to the run's page, which says the stop
    was asked for, so a reload reads the page and does not send the Stop again (a 409 once the run ended)."""
    client, runner = served
    runner.release.clear()
    try:
        run_id = client.post("/tasks", json={"task": "FetchMyPen"}, headers=JSON).get_json()["started"]["id"]
        stop = client.post(f"/tasks/{run_id}/cancel", headers={"Accept": BROWSER})
        assert stop.status_code == 303 and stop.headers["Location"] == f"/tasks/{run_id}"
        assert runner.get(run_id).cancel_requested.is_set()
        page = client.get(stop.headers["Location"], headers={"Accept": BROWSER})
        assert page.status_code == 200 and f"{run_id}: asked to stop after the step under way" in page.text
        for path, headers in ((f"/tasks/{run_id}/cancel.json", {}), (f"/tasks/{run_id}/cancel", {"Accept": "*/*"})):
            again = client.post(path, headers=headers)  # the script's fetch, and curl's form post
            assert again.status_code == 202 and "Location" not in again.headers, path
        assert "asked to stop" in client.post(f"/tasks/{run_id}/cancel.json").get_json()["message"]
    finally:
        runner.release.set()
    _ended(runner, run_id)
    ended = client.post(f"/tasks/{run_id}/cancel", headers={"Accept": BROWSER})
    assert ended.status_code == 409 and "has already ended" in ended.text  # said on the page, not sent on
