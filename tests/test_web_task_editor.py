"""The task editor (/tasks/new): a task written in Turtle is checked and planned with nothing written, saved
into graph:requirements with the update token only, then chosen on the tasks page and started there.

A trial found the browser had no way to write a task: /match ranked a written requirement but could not
plan, store or start it. Composition runs here (a fresh seeded store, once per module); the run started
at the end is stubbed (:class:`_Ended`): no simulation.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from html import unescape
from pathlib import Path
from typing import Any

import pyoxigraph as ox
import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import REQ, GraphName
from cbrs.kb.resources import ontology_dir
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.tasks import TaskRun, TaskRunner
from cbrs.web import create_app

TOKEN = "editor-test-token"
OWN = "http://127.0.0.1:8080"
PENCIL = (Path(__file__).parent / "data" / "tasks" / "fetch_my_pencil.ttl").read_text(encoding="utf-8")


class _Ended(TaskRunner):
    """A runner whose runs succeed at once: no planner, no world."""

    def _run(self, run: TaskRun) -> None:
        run.result = {"plan": {"status": "planned"}, "execution": {"status": "succeeded", "steps": []}}
        run.status = "succeeded"
        run.done.set()


@pytest.fixture(scope="module")
def served() -> Iterator[tuple[FlaskClient, KnowledgeBase]]:
    kb = KnowledgeBase.open(":memory:")
    sparql = SparqlService(kb, EndpointConfig(update_token=TOKEN))
    runner = _Ended(kb, sparql.lock, camera=None)
    app = create_app(sparql, tasks=runner, own_origins=lambda: [OWN])
    yield app.test_client(), kb
    kb.close()


def _named(text: str, name: str) -> str:
    """The pencil task under another name, so that each test saves a task of its own."""
    return text.replace("req:FetchMyPencil", f"req:{name}")


def _requirements(kb: KnowledgeBase) -> set[ox.Quad]:
    return set(kb.store.quads(graph=GraphName.REQUIREMENTS.node))


def _line(text: str, written: str) -> int:
    return next(n for n, line in enumerate(text.splitlines(), start=1) if written in line)


def _text(html: str) -> str:
    return " ".join(unescape(re.sub(r"<[^>]+>", " ", html)).split())


def _check(client: FlaskClient, text: str) -> Any:
    return client.post("/tasks/new.json", json={"turtle": text, "action": "check"})


def _save(client: FlaskClient, text: str, token: str | None = TOKEN, replace: bool = False) -> Any:
    headers = {"Authorization": f"Bearer {token}"} if token is not None else {}
    return client.post("/tasks/new.json", json={"turtle": text, "action": "save", "replace": replace}, headers=headers)


def test_the_page_starts_from_a_bundled_task_renamed_and_is_reached_from_the_navigation_and_tasks(
    served: tuple[FlaskClient, KnowledgeBase],
) -> None:
    client, _ = served
    body = client.get("/tasks/new.json").get_json()
    example = body["form"]["turtle"]
    name = re.match(r"req:(\w+) a cbrs:Requirement", example)
    assert name is not None and name.group(1) == "MyRobotSelfPosition"
    bundled = (ontology_dir() / "requirements.ttl").read_text(encoding="utf-8")
    assert example.replace("req:MyRobotSelfPosition", "req:RobotSelfPosition") in bundled  # read, not written in code
    assert "@prefix" not in example and body["prefixes"]["home"] == "https://w3id.org/cbrs/home#"
    checked = _check(client, example).get_json()  # valid as it is, with no @prefix line
    assert checked["task"]["exists"] is False and checked["composition"]["status"] == "planned"
    page = client.get("/tasks/new").get_data(as_text=True)
    assert re.search(r'<nav>.*<a href="/tasks/new" aria-current="page">New task</a>.*</nav>', page, re.S)
    assert '<label for="turtle">' in page and '<label for="token">' in page and '<label for="replace">' in page
    assert 'href="/tasks/new"' in client.get("/tasks").get_data(as_text=True)


def test_a_valid_task_is_planned_as_the_plans_page_shows_a_plan_and_nothing_is_written(
    served: tuple[FlaskClient, KnowledgeBase],
) -> None:
    client, kb = served
    before, generation = _requirements(kb), kb.store.generation
    answer = client.post("/tasks/new", data={"turtle": PENCIL, "action": "check"})
    assert answer.status_code == 200
    page = answer.get_data(as_text=True)
    steps = re.findall(r'<tr id="step-(\d+)">', page)
    assert len(steps) > 1 and steps == [str(n) for n in range(1, len(steps) + 1)]
    assert 'class="diagram' in page  # the data flow, as on the plans page
    drawing = re.search(r'<img class="drawing" src="([^"]+)"', page)
    assert drawing is not None and unescape(drawing.group(1)).startswith("/tasks/new/graph.svg?draft=")
    twin = _check(client, PENCIL).get_json()
    assert twin["task"]["iri"] == REQ + "FetchMyPencil" and len(twin["composition"]["steps"]) == len(steps)
    assert _requirements(kb) == before and kb.store.generation == generation  # nothing written
    assert "FetchMyPencil" not in client.get("/tasks.json").get_json()["tasks"]


def test_the_drawing_of_a_checked_task_is_served_and_an_unknown_one_is_a_404(
    served: tuple[FlaskClient, KnowledgeBase], monkeypatch: pytest.MonkeyPatch
) -> None:
    from cbrs.web import task_editor

    drawn: list[str] = []
    monkeypatch.setattr(task_editor, "_svg", lambda result: drawn.append(result.requirement) or b"<svg/>")
    client, _ = served
    page = client.post("/tasks/new", data={"turtle": PENCIL, "action": "check"}).get_data(as_text=True)
    source = re.search(r'<img class="drawing" src="([^"]+)"', page)
    assert source is not None
    assert client.get(unescape(source.group(1))).get_data() == b"<svg/>" and drawn == [REQ + "FetchMyPencil"]
    missing = client.get("/tasks/new/graph.svg?draft=0000")
    assert missing.status_code == 404 and "check the task again" in missing.get_data(as_text=True)


def test_a_shape_error_is_a_422_naming_the_term_and_its_line(served: tuple[FlaskClient, KnowledgeBase]) -> None:
    client, kb = served
    wrong = PENCIL.replace("home:isWith", "home:isWit")
    before = _requirements(kb)
    answer = _check(client, wrong)
    assert answer.status_code == 422
    body = answer.get_json()
    assert body["error"] == "invalid-description"
    problem = body["problems"][0]
    assert problem["term"] == "home:isWit" and problem["line"] == _line(wrong, "home:isWit")
    assert "did you mean home:isWith?" in problem["message"]
    assert body["form"]["turtle"] == wrong  # the offending input, as sent
    page = client.post("/tasks/new", data={"turtle": wrong, "action": "check"})
    assert page.status_code == 422
    shown = page.get_data(as_text=True)
    assert f'data-line="{problem["line"]}">line {problem["line"]}</a>' in shown and "<code>home:isWit</code>" in shown
    assert 'aria-invalid="true"' in shown and _requirements(kb) == before


def test_text_that_does_not_parse_is_a_400_at_its_own_line(served: tuple[FlaskClient, KnowledgeBase]) -> None:
    client, _ = served
    broken = PENCIL.replace('cbrs:deviceName "P3DX01" ;', 'cbrs:deviceName "P3DX01" ;;; ]')
    answer = _check(client, broken)
    assert answer.status_code == 400
    body = answer.get_json()
    assert body["line"] == _line(broken, ";;; ]")  # the text's line, not the line after the declared prefixes
    assert body["message"].startswith(f"line {body['line']}")
    undeclared = _check(client, "req:X a hme:Requirement .").get_json()
    assert "hme:" in undeclared["message"] and "did you mean home:?" in undeclared["message"]


@pytest.mark.parametrize(
    ("text", "said"),
    [
        pytest.param("home:Frisbee rdfs:subClassOf home:PersonalItem .", "describes no task", id="no-task"),
        pytest.param(PENCIL + _named(PENCIL, "FetchMyOtherPencil").split("\n\n", 1)[1], "2 tasks", id="two"),
        pytest.param("", "write a task", id="empty"),
    ],
)
def test_text_that_is_not_one_task_is_a_400_saying_so(
    served: tuple[FlaskClient, KnowledgeBase], text: str, said: str
) -> None:
    client, _ = served
    answer = _check(client, text)
    assert answer.status_code == 400 and said in answer.get_data(as_text=True)


def test_an_undeclared_class_gets_the_advice_cbrs_plan_gives_with_its_line(
    served: tuple[FlaskClient, KnowledgeBase],
) -> None:
    client, _ = served
    frisbee = PENCIL.replace("conditionSubject home:Pencil", "conditionSubject home:Frisbee")
    body = _check(client, frisbee).get_json()
    assert body["composition"]["status"] == "unsolvable"
    assert body["undeclared"] == [{"term": "home:Frisbee", "line": _line(frisbee, "home:Frisbee")}]
    advice = body["composition"]["unsatisfied"][0]["text"]
    assert "home:Frisbee is no class of the ontology" in advice and "home:Frisbee rdfs:subClassOf" in advice
    page = client.post("/tasks/new", data={"turtle": frisbee, "action": "check"}).get_data(as_text=True)
    assert "No plan." in page and "home:Frisbee is no class of the ontology" in _text(page)


def test_saving_needs_the_update_token_and_writes_nothing_without_it(
    served: tuple[FlaskClient, KnowledgeBase],
) -> None:
    client, kb = served
    text = _named(PENCIL, "FetchMyPencilRefused")
    before = _requirements(kb)
    missing = _save(client, text, token=None)
    assert missing.status_code == 403 and "token" in missing.get_json()["message"]
    wrong = _save(client, text, token="not-it")
    assert wrong.status_code == 403 and "not this server's update token" in wrong.get_json()["message"]
    form = {"turtle": text, "action": "save", "token": "not-it"}
    page = client.post("/tasks/new", data=form, headers={"Origin": OWN})
    shown = page.get_data(as_text=True)
    assert page.status_code == 403 and 'id="token-error"' in shown and "not-it" not in shown  # never echoed
    assert "FetchMyPencilRefused" in shown  # the text is kept
    foreign = client.post("/tasks/new", data={**form, "token": TOKEN}, headers={"Origin": "http://elsewhere.example"})
    assert foreign.status_code == 403 and "elsewhere.example" in foreign.get_data(as_text=True)
    broken = _save(client, text.replace("home:isWith", "home:isWit"), token=None)
    assert broken.status_code == 403  # the token is asked first: a shape error is not told without it
    assert _requirements(kb) == before


def test_a_saved_task_is_listed_chosen_on_the_tasks_page_and_starts(served: tuple[FlaskClient, KnowledgeBase]) -> None:
    client, kb = served
    text = _named(PENCIL, "FetchMyPencilSaved")
    page = client.post("/tasks/new", data={"turtle": text, "action": "save", "token": TOKEN}, headers={"Origin": OWN})
    assert page.status_code == 201
    run = page.headers["Location"]
    assert run == "/tasks?task=req:FetchMyPencilSaved" and f'href="{run}"' in page.get_data(as_text=True)
    body = client.get("/tasks.json?task=req:FetchMyPencilSaved").get_json()
    assert "FetchMyPencilSaved" in body["tasks"] and body["form"]["task"] == "FetchMyPencilSaved"
    assert kb.description(REQ + "FetchMyPencilSaved").label == "Fetch my pencil"
    started = client.post("/tasks.json", json={"task": "FetchMyPencilSaved"}, headers={"Origin": OWN})
    assert started.status_code == 202 and started.get_json()["started"]["task"] == "FetchMyPencilSaved"


def test_a_stored_name_is_refused_unless_replace_is_asked(served: tuple[FlaskClient, KnowledgeBase]) -> None:
    client, kb = served
    text = _named(PENCIL, "FetchMyPencilTwice")
    assert _save(client, text).status_code == 201
    stored = _requirements(kb)
    relabelled = text.replace('"Fetch my pencil"@en', '"Bring the pencil"@en')
    assert _check(client, relabelled).get_json()["task"]["exists"] is True
    refused = _save(client, relabelled)
    assert refused.status_code == 409
    assert "req:FetchMyPencilTwice is stored already" in refused.get_json()["message"]
    assert refused.get_json()["errors"].keys() == {"replace"} and _requirements(kb) == stored
    replaced = _save(client, relabelled, replace=True)
    assert replaced.status_code == 201 and replaced.get_json()["saved"]["replaced"] is True
    assert kb.description(REQ + "FetchMyPencilTwice").label == "Bring the pencil"  # the old label is gone
    assert len(_requirements(kb)) == len(stored)  # one description, not two merged


def test_the_json_twin_is_negotiated_and_refuses_an_unknown_field(served: tuple[FlaskClient, KnowledgeBase]) -> None:
    client, _ = served
    negotiated = client.post("/tasks/new", json={"turtle": PENCIL}, headers={"Accept": "application/json"})
    assert negotiated.is_json and negotiated.get_json()["composition"]["status"] == "planned"
    assert "Accept" in negotiated.headers["Vary"]
    unknown = client.post("/tasks/new.json", json={"turtel": PENCIL})
    assert unknown.status_code == 400 and "did you mean 'turtle'?" in unknown.get_json()["fields"]["turtel"]
    action = client.post("/tasks/new.json", json={"turtle": PENCIL, "action": "run"})
    assert action.status_code == 400 and "'run' is not check or save" in action.get_json()["fields"]["action"]


REFERENCES = re.compile(r'(?:for|aria-describedby|aria-labelledby)="([^"]+)"')


@pytest.mark.parametrize(
    ("form", "status"),
    [
        pytest.param(None, 200, id="start"),
        pytest.param({"turtle": PENCIL, "action": "check"}, 200, id="planned"),
        pytest.param(
            {"turtle": PENCIL.replace("home:Pencil ;", "home:Frisbee ;"), "action": "check"}, 200, id="no-plan"
        ),
        pytest.param({"turtle": PENCIL.replace("home:isWith", "home:isWit"), "action": "check"}, 422, id="shape"),
        pytest.param({"turtle": PENCIL, "action": "save", "token": "not-it"}, 403, id="token"),
    ],
)
def test_every_state_of_the_page_has_labelled_fields_and_references_that_resolve(
    served: tuple[FlaskClient, KnowledgeBase], form: dict[str, str] | None, status: int
) -> None:
    client, _ = served
    answer = client.get("/tasks/new") if form is None else client.post("/tasks/new", data=form)
    assert answer.status_code == status
    page = answer.get_data(as_text=True)
    ids = re.findall(r'\sid="([^"]+)"', page)
    assert len(ids) == len(set(ids))
    assert [name for found in REFERENCES.findall(page) for name in found.split() if name not in ids] == []
    assert [name for name in re.findall(r'href="#([^"]+)"', page) if name not in ids] == []
    for field in re.findall(r"<(?:input|select|textarea)\b[^>]*>", page):
        named = re.search(r'\sid="([^"]+)"', field)
        assert named is not None and f'for="{named.group(1)}"' in page, field
    assert '<script src="/static/task_editor.js" defer></script>' in page  # our own script, no CDN
    assert client.get("/static/task_editor.js").status_code == 200


def test_the_page_leads_to_the_line_that_does_not_parse(served: tuple[FlaskClient, KnowledgeBase]) -> None:
    client, _ = served
    broken = PENCIL.replace('cbrs:deviceName "P3DX01" ;', 'cbrs:deviceName "P3DX01" ;;; ]')
    page = client.post("/tasks/new", data={"turtle": broken, "action": "check"})
    line = _line(broken, ";;; ]")
    assert page.status_code == 400 and f'data-line="{line}">Go to line {line}</a>' in page.get_data(as_text=True)
