"""Follow-ups of the fourteenth blind round, from the browser (docs/web.md, "Tried from the browser alone").

A task file chosen for another graph than requirements was refused by the Load a file page only: ``cbrs load
--graph map`` and the Graph Store took it without a word. The check is the library's now, every way in.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pyoxigraph as ox
import pytest
from click.testing import CliRunner
from flask.testing import FlaskClient

from cbrs.bridge_services import KnowledgeServices
from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.derived_prefixes import StoreNames
from cbrs.kb.loader import MisplacedDescriptionError
from cbrs.kb.namespaces import PREFIXES, GraphName, store_names
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.tasks import TaskRun, TaskRunner, shown_name
from cbrs.web import create_app

EXAMPLES = Path(__file__).resolve().parent.parent / "docs" / "examples"
LAMP_TASK = EXAMPLES / "lab10_switch_on_the_lamp.ttl"
LAMP_PLUG = EXAMPLES / "lab10_lamp_switch.ttl"
LAMP = EXAMPLES / "lab10_reading_lamp.ttl"
TOKEN = "followups-token"
BROWSER = {"Accept": "text/html,application/xhtml+xml,application/xml;q=0.9,*/*;q=0.8"}
WAIT = 10.0
AUTH = {"Authorization": f"Bearer {TOKEN}"}


@pytest.fixture(scope="module")
def kb() -> KnowledgeBase:
    return KnowledgeBase.open(":memory:")


@pytest.fixture(scope="module")
def client(kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(kb, EndpointConfig(update_token=TOKEN, isolate=False))).test_client()


def _sizes(kb: KnowledgeBase) -> dict[str, int]:
    return {g.value: sum(1 for _ in kb.store.quads(graph=g.node)) for g in GraphName}


def test_load_refuses_a_task_in_the_map_and_an_advertisement_in_the_ontology(kb: KnowledgeBase) -> None:
    """KnowledgeBase.load (cbrs load --graph) wrote the lamp's task into graph:map: "added 16 triples"."""
    before = _sizes(kb)
    with pytest.raises(MisplacedDescriptionError) as task:
        kb.load([LAMP_TASK], "map")
    assert task.value.subject == "https://example.org/lab10#SwitchOnTheReadingLamp"
    assert task.value.belongs is GraphName.REQUIREMENTS and task.value.graph == GraphName.MAP.iri
    assert "lab10:SwitchOnTheReadingLamp" in str(task.value)  # by the file's own prefix
    assert "tasks go into graph:requirements, not graph:map; nothing was loaded" in str(task.value)
    with pytest.raises(MisplacedDescriptionError) as plug:
        kb.load([LAMP_PLUG], "ontology")
    assert plug.value.belongs is GraphName.SERVICES and "lab10:SwitchOnReadingLamp_LampPlug01" in str(plug.value)
    with pytest.raises(MisplacedDescriptionError):
        kb.load([LAMP_PLUG], "requirements")
    with pytest.raises(MisplacedDescriptionError):  # no class of its own: a task alone is no ontology's
        kb.load([LAMP_TASK], "ontology")
    assert _sizes(kb) == before


def test_the_cli_says_where_a_task_goes_and_fails() -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "load", "--graph", "map", str(LAMP_TASK)])
    assert result.exit_code != 0
    assert "lab10:SwitchOnTheReadingLamp" in result.output and "graph:requirements" in result.output
    assert "added" not in result.output


@pytest.mark.parametrize("method", ["post", "put"])
def test_the_graph_store_refuses_a_task_in_the_map(client: FlaskClient, kb: KnowledgeBase, method: str) -> None:
    before = _sizes(kb)
    answer = getattr(client, method)(
        "/store",
        query_string={"graph": GraphName.MAP.iri},
        data=LAMP_TASK.read_bytes(),
        content_type="text/turtle",
        headers=AUTH,
    )
    assert answer.status_code == 400, answer.text
    body = answer.get_json()
    assert body["error"] == "bad-request" and "tasks go into graph:requirements" in body["message"]
    assert _sizes(kb) == before


def test_the_graph_store_refuses_an_advertisement_in_a_dataset_post(client: FlaskClient, kb: KnowledgeBase) -> None:
    """A TriG body's quads are judged in the graphs they name."""
    plug = ox.parse(LAMP_PLUG.read_bytes(), format=ox.RdfFormat.TURTLE)
    quads = [ox.Quad(t.subject, t.predicate, t.object, GraphName.REQUIREMENTS.node) for t in plug]
    body = ox.serialize(quads, format=ox.RdfFormat.N_QUADS)
    before = _sizes(kb)
    answer = client.post("/store", data=body, content_type="application/n-quads", headers=AUTH)
    assert answer.status_code == 400 and "advertisements go into graph:services" in answer.get_json()["message"]
    assert _sizes(kb) == before


def test_a_task_into_requirements_and_a_plug_into_services_still_load(kb: KnowledgeBase) -> None:
    """Last of item 1: it changes the module's store."""
    kb.load([LAMP_TASK], "requirements")
    kb.load([LAMP_PLUG], "services")
    assert _sizes(kb)["requirements"] > 0


class _Ended(TaskRunner):
    """A runner whose runs end at once, without the world: these tests are about the pages, not the runs."""

    def _run(self, run: TaskRun) -> None:
        run.status = "succeeded"
        run.done.set()


@pytest.fixture(scope="module")
def served() -> Iterator[tuple[FlaskClient, _Ended]]:
    """The lamp in the ontology and the map, its task in requirements; runs that end at once."""
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([LAMP], graph)
    kb.load([LAMP_TASK], "requirements")
    sparql = SparqlService(kb)
    runner = _Ended(kb, sparql.lock, camera=None)
    yield create_app(sparql, tasks=runner).test_client(), runner


def _started(runner: _Ended, location: str) -> TaskRun:
    run = runner.get(location.removesuffix(".json").rsplit("/", 1)[1])
    assert run.done.wait(WAIT)
    return run


def test_a_browser_s_start_is_sent_on_to_the_run_s_page(served: tuple[FlaskClient, _Ended]) -> None:
    """After Start the browser stayed at /tasks, so a reload asked to send the form again, and while the run
    went that gave a 409. A browser's form is sent on to the run's page (303); the JSON API answers as it did."""
    client, runner = served
    answer = client.post("/tasks", data={"task": "FetchMyPen", "seed": "0"}, headers=BROWSER)
    assert answer.status_code == 303
    location = answer.headers["Location"]
    assert re.fullmatch(r"/tasks/run-\d+", location), location
    run = _started(runner, location)
    page = client.get(location, headers=BROWSER)
    assert page.status_code == 200 and f"Run {run.id}: FetchMyPen" in page.text
    twin = client.post("/tasks.json", data={"task": "FetchMyPen"})  # what tasks.js sends
    assert twin.status_code == 202 and twin.get_json()["started"]["task"] == "FetchMyPen"
    _started(runner, twin.headers["Location"])
    program = client.post("/tasks", json={"task": "FetchMyPen"}, headers={"Accept": "application/json"})
    assert program.status_code == 202 and program.headers["Location"].endswith(".json")
    _started(runner, program.headers["Location"])
    curl = client.post("/tasks", data={"task": "FetchMyPen"}, headers={"Accept": "*/*"})
    assert curl.status_code == 202 and "started: FetchMyPen" in curl.text  # a program's form keeps the page
    _started(runner, curl.headers["Location"])


def test_the_tasks_page_names_a_lab_s_task_by_its_prefix(served: tuple[FlaskClient, _Ended]) -> None:
    """The tasks page and a run's title said SwitchOnTheReadingLamp where the plans page says
    lab10:SwitchOnTheReadingLamp; the list's value stays the name cbrs run takes."""
    client, runner = served
    page = client.get("/tasks", query_string={"task": "SwitchOnTheReadingLamp"}, headers=BROWSER)
    option = re.search(r'<option value="SwitchOnTheReadingLamp" selected>([^<]*)</option>', page.text)
    assert option is not None and option.group(1).startswith("lab10:SwitchOnTheReadingLamp · "), page.text[:300]
    assert '<option value="FetchMyPen"' in page.text and ">FetchMyPen · " in page.text  # cbrs's own as listed
    plans = client.get("/plans", headers=BROWSER).text
    assert ">lab10:SwitchOnTheReadingLamp · " in plans  # the name the plans page gives it
    curl = client.post("/tasks", data={"task": "SwitchOnTheReadingLamp"}, headers={"Accept": "*/*"})
    assert curl.status_code == 202 and "started: lab10:SwitchOnTheReadingLamp" in curl.text
    run = _started(runner, curl.headers["Location"])
    shown = client.get(f"/tasks/{run.id}", headers=BROWSER).text
    assert f"<title>Run {run.id}: lab10:SwitchOnTheReadingLamp, succeeded" in shown
    assert f"{run.id}</a> · lab10:SwitchOnTheReadingLamp" in shown
    listed = client.get("/tasks", headers=BROWSER).text
    assert "<td>lab10:SwitchOnTheReadingLamp</td>" in listed  # the recent runs
    twin = client.get("/tasks.json").get_json()
    assert twin["runs"][0]["shown"] == "lab10:SwitchOnTheReadingLamp" and twin["runs"][0]["task"] == run.task


def test_a_cross_site_load_is_refused_in_the_load_page_s_words(client: FlaskClient, kb: KnowledgeBase) -> None:
    """Another site's page posting to /load was told "a task may be loaded only from this server's own pages":
    the page loads files, of any kind."""
    before = _sizes(kb)
    data = {"graph": "map", "token": TOKEN, "file": (LAMP.open("rb"), LAMP.name)}
    headers = {**BROWSER, "Origin": "https://elsewhere.example"}
    answer = client.post("/load", data=data, headers=headers, content_type="multipart/form-data")
    assert answer.status_code == 403
    said = answer.text.replace("&#39;", "'")
    assert (
        "a file may be loaded into the store only from this server's own pages, not from https://elsewhere.example"
        in said
    )
    assert "a task may" not in said
    assert _sizes(kb) == before


def test_a_run_s_events_and_answers_name_its_task_alike(served: tuple[FlaskClient, _Ended]) -> None:
    """/cbrs/events named a lab's task as the list does (SwitchOnTheReadingLamp) and /cbrs/task by its IRI, and
    the tasks page fetched the run to learn the name it shows. Every message of a run and the services' answers
    carry the IRI and the shown name alike, ``task`` as before. The real runner: the lamp's task has no plug
    here, so it ends no-plan before any world is built."""
    client, ended = served
    runner = TaskRunner(ended.kb, ended.lock, camera=None)
    heard: list[tuple[str, dict[str, Any]]] = []
    runner.subscribe(lambda topic, message: heard.append((topic, message)))
    run = runner.run("SwitchOnTheReadingLamp", timeout=60.0)
    assert run.done.is_set() and run.status == "no-plan", run.error
    iri, shown = "https://example.org/lab10#SwitchOnTheReadingLamp", "lab10:SwitchOnTheReadingLamp"
    naming = {"run": run.id, "task": "SwitchOnTheReadingLamp", "iri": iri, "shown": shown}
    assert heard == [
        ("/cbrs/events", {"event": "run_started", **naming}),
        ("/cbrs/events", {"event": "run_finished", **naming, "status": "no-plan"}),
    ]
    services = KnowledgeServices(SparqlService(ended.kb), runner)
    answer = services.task_status({"run": run.id})
    assert (answer["task"], answer["iri"], answer["shown"]) == ("SwitchOnTheReadingLamp", iri, shown)
    page = client.get("/tasks", query_string={"task": "SwitchOnTheReadingLamp"}, headers=BROWSER)
    assert f'<option value="SwitchOnTheReadingLamp" selected>{shown} · ' in page.text  # the pages' name, the same
    with store_names(StoreNames(lambda: ended.kb)):  # cbrs's own tasks keep the name they were asked for
        own = PREFIXES["req"] + "FetchMyPen"
        assert [shown_name(name, own) for name in ("FetchMyPen", "req:FetchMyPen", own)] == [
            "FetchMyPen",
            "req:FetchMyPen",
            "req:FetchMyPen",
        ]
        assert [shown_name(name, iri) for name in ("SwitchOnTheReadingLamp", f"<{iri}>", shown)] == [shown] * 3
