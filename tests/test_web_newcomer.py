"""What a robotics student new to cbrs met walking through the browser, and what now answers them.

Each test is one thing the walk-through found (docs/web.md, "A new user's walk-through"): a run that made
no plan said only "Plan: unsolvable"; a misspelt task in the URL was added to the list; a lab's own task
was listed by its IRI; a lab's file loaded into two graphs showed every triple twice; the home's things
could not be searched; and the rest below. The runs here end at once without the planner or the
simulation (:class:`_Scripted`): these tests are about what the pages say of a run.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from html import unescape
from typing import Any
from urllib.parse import unquote

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.tasks import TaskRun, TaskRunner
from cbrs.web import create_app
from cbrs.web.links import short_text
from tests.helpers_examples import EXAMPLES, lab5_store

WAIT = 10.0
SVC = "https://w3id.org/cbrs/service#"
CAMERAS = tuple(SVC + f"LocateMobileRobot_CeilingCamera0{n}" for n in (1, 2))
UNPLANNABLE = "RouteToGoal"  # a bundled requirement no component chain provides: its runs end no-plan
# What the planner answers for it, in the shape of CompositionResult.to_dict() (actions/unmet.py)
UNMET = [
    {
        "need": f"input markerColour (home:MarkerColour) of {CAMERAS[0]}",
        "text": f"no component provides input "
        f"markerColour (home:MarkerColour) of {CAMERAS[0]}; register a component whose output is a home:MarkerColour",
    },
    {"need": "output route (home:Trajectory)", "text": "no component provides output route (home:Trajectory)"},
]


class _Scripted(TaskRunner):
    """A runner whose runs end at once as a script says: UNPLANNABLE with no plan and UNMET's needs, any
    other task with its first step failing over from one ceiling camera to the other, in the executor's
    words. No planner, no world."""

    def _run(self, run: TaskRun) -> None:
        if run.task == UNPLANNABLE:
            run.result = {"plan": {"status": "unsolvable", "unsatisfied": UNMET}, "sim_seconds": 0.0}
            run.status = "no-plan"
        else:
            first, second = CAMERAS
            progress = [
                {"event": "step_started", "step": 1, "component": first},
                {"event": "step_failed", "step": 1, "component": first, "reason": f"injected failure of {first}"},
                {"event": "step_started", "step": 1, "component": second},
                {"event": "step_succeeded", "step": 1, "component": second},
            ]
            run.events.extend({"topic": "/cbrs/task_progress", "run": run.id, **event} for event in progress)
            run.result = {"plan": {"status": "planned"}, "execution": {"status": "succeeded", "steps": []}}
            run.status = "succeeded"
        run.done.set()


@pytest.fixture(scope="module")
def served(bundled_kb: KnowledgeBase) -> Iterator[tuple[FlaskClient, TaskRunner]]:
    sparql = SparqlService(bundled_kb)
    runner = _Scripted(bundled_kb, sparql.lock, camera=None)
    yield create_app(sparql, tasks=runner).test_client(), runner


def _text(html: str) -> str:
    return " ".join(unescape(re.sub(r"<[^>]+>", " ", html)).split())


def _ran(client: FlaskClient, runner: TaskRunner, task: str) -> dict[str, Any]:
    started = client.post("/tasks.json", json={"task": task}).get_json()["started"]
    assert runner.get(started["id"]).done.wait(WAIT)
    found: dict[str, Any] = client.get(f"/tasks/{started['id']}.json").get_json()["run"]
    return found


def test_a_run_that_made_no_plan_says_why_on_its_page_and_in_the_latest_run_panel(
    served: tuple[FlaskClient, TaskRunner],
) -> None:
    client, runner = served
    run = _ran(client, runner, UNPLANNABLE)
    assert run["status"] == "no-plan" and run["unmet"] == [need["text"] for need in UNMET]
    said = short_text(UNMET[0]["text"])
    assert run["verdict"] == f"no plan (unsolvable), nothing was simulated: {UNMET[0]['text']} (and 1 more, below)"
    page = _text(client.get(run["url"]).text)
    assert "Why no plan came of it" in page and all(short_text(need["text"]) in page for need in UNMET)
    assert f"nothing was simulated: {said} (and 1 more, below)" in page  # the line under the steps said nothing
    assert CAMERAS[0] not in page  # named as the pages name it: svc:LocateMobileRobot_CeilingCamera01
    panel = _text(client.get("/tasks").text)  # the latest run, on the start page
    assert f"nothing was simulated: {said}" in panel


@pytest.fixture(scope="module")
def lab() -> FlaskClient:
    """The bundled store with a lab's visitor in the kitchen and the task to bring them the pen, loaded as
    the examples' headers say: names of the lab's own namespace, which no cbrs prefix declares."""
    kb = lab5_store(things=("lab5_visitor_in_kitchen.ttl",))
    kb.load([EXAMPLES / "lab5_fetch_pen_for_visitor.ttl"], graph="requirements")
    return create_app(SparqlService(kb)).test_client()


@pytest.mark.parametrize(
    "asked", ["FetchPenForVisitor", "lab5:FetchPenForVisitor", "https://example.org/lab5#FetchPenForVisitor"]
)
def test_a_lab_s_own_task_is_listed_by_its_prefixed_name_and_chosen_above_its_plan(
    lab: FlaskClient, asked: str
) -> None:
    body = lab.get("/plans.json", query_string={"task": asked}).get_json()
    assert body["composition"]["requirement"] == "https://example.org/lab5#FetchPenForVisitor"
    option = next(t for t in body["tasks"]["requirements"] if t["name"] == body["selected"])
    assert option["shown"] == "lab5:FetchPenForVisitor"
    page = unescape(lab.get("/plans", query_string={"task": asked}).text)
    chosen = re.findall(r'<option value="([^"]*)" selected>([^<]*)</option>', page)
    assert chosen[0] == (option["name"], "lab5:FetchPenForVisitor")  # the form said "(choose)"
    listed = re.search(r'<select id="task".*?</select>', page, re.S)
    assert listed is not None and "https://example.org/lab5#" not in re.sub(r'value="[^"]*"', "", listed.group(0))


def test_a_task_the_url_misspells_is_a_field_error_with_what_was_meant(served: tuple[FlaskClient, TaskRunner]) -> None:
    client, _ = served
    refused = client.get("/tasks.json", query_string={"task": "FetchMyPn"})
    assert refused.status_code == 400 and "FetchMyPen" in refused.get_json()["fields"]["task"]
    page = client.get("/tasks", query_string={"task": "FetchMyPn"})
    assert page.status_code == 400 and 'id="task-error"' in page.text and 'aria-invalid="true"' in page.text
    assert "did you mean FetchMyPen" in unescape(page.text)


def test_a_task_the_url_names_by_its_iri_is_chosen_as_the_list_spells_it(
    served: tuple[FlaskClient, TaskRunner],
) -> None:
    client, _ = served
    listed = client.get("/tasks.json").get_json()["tasks"]
    for asked in ("req:FetchMyPen", "https://w3id.org/cbrs/requirement#FetchMyPen"):
        body = client.get("/tasks.json", query_string={"task": asked}).get_json()
        assert body["form"]["task"] == "FetchMyPen" and "FetchMyPen" in listed
        page = client.get("/tasks", query_string={"task": asked}).text
        assert re.findall(r'<option value="([^"]*)" selected>', page)[0] == "FetchMyPen"


def test_the_overview_says_where_to_start_with_every_page_of_the_navigation(
    served: tuple[FlaskClient, TaskRunner],
) -> None:
    client, _ = served
    page = client.get("/").text
    start = re.search(r'<section class="start-here">.*?</section>', page, re.S)
    assert start is not None
    linked = re.findall(r'<li><a href="([^"]+)">([^<]+)</a>: [^<]{20,}</li>', start.group(0))
    navigation = re.findall(r'<a href="([^"]+)"[^>]*>([^<]+)</a>', re.search(r"<nav>.*?</nav>", page, re.S).group(0))
    assert linked == [(href, label) for href, label in navigation if href != "/"]
    # each count card reads as a number and a word, to a screen reader too ("53services" before)
    counts = client.get("/index.json").get_json()["counts"]
    cards = [_text(card) for card in re.findall(r'<div class="card">(.*?)</div>', page, re.S)]
    assert cards == [f"{value} {name}" for name, value in counts.items()]


def test_the_search_finds_the_home_s_things_a_lab_added_by_name_and_label(lab: FlaskClient) -> None:
    home = lab.get("/home.json").get_json()["things"]
    for needle in ("visitor", "kitchen", "pen"):
        found = lab.get("/search.json", query_string={"q": needle}).get_json()
        things = found["things"]["matches"]
        assert {t["iri"] for t in things} >= {t["iri"] for t in home if needle in t["name"].casefold()}
        assert found["total"] == sum(
            found[group]["count"] for group in ("terms", "advertisements", "requirements", "things")
        )
        for thing in things:
            assert lab.get("/resource", query_string={"iri": thing["iri"]}).status_code == 200
    visitor = lab.get("/search.json", query_string={"q": "the visitor in"}).get_json()["things"]["matches"]
    assert [(t["name"], t["kind"], t["room"]) for t in visitor] == [("lab5:Visitor1", "person", "Kitchen")]
    page = _text(lab.get("/search", query_string={"q": "visitor"}).text)
    assert "Things in the home (1) lab5:Visitor1 the visitor in the kitchen person in Kitchen" in page


def test_a_triple_stated_in_two_graphs_is_one_row_naming_both(lab: FlaskClient) -> None:
    """The visitor's file goes into graph:ontology and graph:map, as its header says."""
    body = lab.get("/resource.json", query_string={"iri": "lab5:Visitor1"}).get_json()
    stated: dict[tuple[str, str], list[str]] = {}
    for group in body["outgoing"]:
        for value in group["values"]:
            stated.setdefault((group["name"], value["term"]["value"]), []).append(value["graph"])
    assert any(len(graphs) == 2 for graphs in stated.values())  # the twin keeps one value per triple
    page = lab.get("/resource", query_string={"iri": "lab5:Visitor1"}).text
    out = re.search(r"<h2>Out:.*?</table>", page, re.S)
    assert out is not None
    rows = re.findall(r"<tr>\s*<td>(.*?)</td>\s*<td>(.*?)</td>\s*<td class=\"graph\">(.*?)</td>", out.group(0), re.S)
    shown = [[unquote(g) for g in re.findall(r'href="/resource\?iri=([^"]+)"', graphs)] for _, _, graphs in rows]
    assert sorted(shown) == sorted(stated.values())  # one row per value, with every graph that states it


@pytest.mark.parametrize(
    ("path", "asked", "has_page"),
    [
        pytest.param("/taxonomy/class", "home:NoSuchThing", False, id="class-unknown"),
        pytest.param("/taxonomy/class", "world:Kitchen", True, id="individual-as-class"),
        pytest.param("/resource", "home:NoSuchThing", False, id="resource-unknown"),
    ],
)
def test_an_iri_the_store_lacks_is_a_not_found_page_naming_it_as_the_pages_do(
    served: tuple[FlaskClient, TaskRunner], path: str, asked: str, has_page: bool
) -> None:
    client, _ = served
    twin = client.get(path + ".json", query_string={"iri": asked})
    assert twin.status_code == 404 and "<https://w3id.org/cbrs/" in twin.get_json()["message"]  # as it was
    answer = client.get(path, query_string={"iri": asked})
    page = _text(answer.text)
    assert answer.status_code == 404 and "<title>Not Found · cbrs</title>" in answer.text
    assert f" {asked} in the store" in page and "<https://" not in page
    assert f"IRI {twin.get_json()['message'].split('<')[1].split('>')[0]}" in page
    assert ("what the store says of " + asked in page) == has_page
    if has_page:
        link = re.search(r'<a href="([^"]+)">what the store says of', answer.text)
        assert link is not None and client.get(unescape(link.group(1))).status_code == 200


def test_every_matching_method_offered_says_what_it_is(served: tuple[FlaskClient, TaskRunner]) -> None:
    client, _ = served
    methods = client.get("/match.json").get_json()["methods"]
    page = client.get("/match").text
    help_box = re.search(r'<details class="small" id="methods-help">.*?</details>', page, re.S)
    assert help_box is not None and 'aria-describedby="methods-help"' in page
    notes = dict(re.findall(r"<dt><code>([^<]+)</code></dt><dd>([^<]*)</dd>", help_box.group(0)))
    assert list(notes) == methods and all(len(note) > 20 for note in notes.values())
    titles = dict(re.findall(r'<option value="([^"]+)"[^>]* title="([^"]+)">', page))
    assert {m: unescape(titles[m]) for m in methods} == {m: unescape(notes[m]) for m in methods}
    refused = client.get("/match", query_string={"requirement": "req:RobotSelfPosition", "methods": "nope"})
    select = re.search(r'<select id="methods"[^>]*>', refused.text)
    assert refused.status_code == 400 and select is not None
    assert select.group(0).count("aria-describedby") == 1 and 'aria-describedby="methods-error"' in select.group(0)


@pytest.mark.parametrize("table", ["advertisements", "requirements"])
def test_each_cell_of_the_services_tables_names_its_column_for_the_phone_layout(lab: FlaskClient, table: str) -> None:
    page = lab.get("/services").text
    found = re.search(rf'<table id="{table}">.*?</table>', page, re.S)
    assert found is not None
    headers = [_text(h) for h in re.findall(r'<th scope="col">(.*?)</th>', found.group(0))]
    rows = re.findall(r"<tr>(.*?)</tr>", found.group(0).split("<tbody>")[1], re.S)
    assert len(rows) > 1
    for row in rows:
        labels = re.findall(r'<td(?: class="[^"]*")?(?: data-label="([^"]*)")?>', row)
        assert [unescape(label) for label in labels] == [h if h != "ranking" else "" for h in headers][: len(labels)]
        assert len(labels) == len(headers)


@pytest.mark.parametrize(
    ("path", "query", "title"),
    [
        pytest.param("/plans", {"task": "FetchMyPn"}, "Plans", id="plans"),
        pytest.param("/match", {"requirement": "req:RobotSelfPositon"}, "Matchmaking", id="match"),
    ],
)
def test_a_refused_form_is_not_titled_as_if_it_had_an_answer(
    served: tuple[FlaskClient, TaskRunner], path: str, query: dict[str, str], title: str
) -> None:
    client, _ = served
    refused = client.get(path, query_string=query)
    assert refused.status_code == 400 and f"<h1>{title}</h1>" in refused.text and "did you mean" in refused.text
    name = "FetchMyPen" if path == "/plans" else "req:RobotSelfPosition"
    shown = client.get(path, query_string={key: name for key in query})
    assert shown.status_code == 200 and f"<h1>{title if path == '/match' else 'Plan'}" in shown.text
    assert name in re.search(r"<h1>(.*?)</h1>", shown.text).group(1)


def test_the_tasks_list_gives_each_task_s_label_as_the_plans_page_does(served: tuple[FlaskClient, TaskRunner]) -> None:
    client, _ = served
    body = client.get("/tasks.json").get_json()
    plans = client.get("/plans.json").get_json()["tasks"]
    planned = {t["shown"]: t["label"] for group in ("requirements", "actions") for t in plans[group] if t["label"]}
    assert body["labels"] and set(body["labels"]) <= set(body["tasks"])
    for name, label in body["labels"].items():  # the list spells a requirement bare, the plans page prefixed
        assert label in (planned.get(name), *(v for k, v in planned.items() if k.partition(":")[2] == name))
    page = unescape(client.get("/tasks").text)
    options = dict(re.findall(r'<option value="([^"]+)"(?: selected)?>([^<]+)</option>', page))
    for name in body["tasks"]:
        label = body["labels"].get(name)
        assert options[name] == (f"{name} · {label}" if label else name)


@pytest.mark.parametrize(
    ("asked", "member"),
    [
        pytest.param("lab5:Visitor", "lab5:Visitor1", id="lab"),
        pytest.param("home:Kitchen", "world:Kitchen", id="bundled"),
    ],
)
def test_a_class_page_lists_the_individuals_stated_of_it(lab: FlaskClient, asked: str, member: str) -> None:
    body = lab.get("/taxonomy/class.json", query_string={"iri": asked}).get_json()
    members = body["members"]
    assert member in [m["name"] for m in members["shown"]] and members["count"] == len(members["shown"])
    typed = lab.get("/resource.json", query_string={"iri": asked}).get_json()["incoming"]
    stated = {v["term"]["value"] for g in typed if g["name"] == "rdf:type" for v in g["values"]}
    assert {m["iri"] for m in members["shown"]} == stated  # once each, though stated in two graphs
    page = unescape(lab.get("/taxonomy/class", query_string={"iri": asked}).text)
    assert re.search(r'<h2 id="members-heading">Individuals <span class="muted">\(\d+\)</span></h2>', page)
    assert f">{member}</a>" in page
    person = lab.get("/taxonomy/class.json", query_string={"iri": "home:Person"}).get_json()["members"]
    assert "lab5:Visitor1" not in [m["name"] for m in person["shown"]]  # a subclass's individuals are on its page


def test_the_executor_s_reasons_name_components_as_the_page_does(served: tuple[FlaskClient, TaskRunner]) -> None:
    client, runner = served
    run = _ran(client, runner, "FetchMyPen")
    page = _text(client.get(run["url"]).text)
    assert page.count("injected failure of svc:LocateMobileRobot_CeilingCamera01") == 2  # the step, the events
    assert "failure of https://" not in page
    assert short_text(f"(of {SVC}X01, http://example.org/thing.)") == "(of svc:X01, http://example.org/thing.)"


def test_a_wrong_token_for_a_run_is_told_apart_from_none(bundled_kb: KnowledgeBase) -> None:
    token = "right-token"
    sparql = SparqlService(bundled_kb, EndpointConfig(update_token=token, isolate=False))
    runner = _Scripted(bundled_kb, sparql.lock, camera=None)
    client = create_app(sparql, tasks=runner, own_origins=lambda: ["http://127.0.0.1:8080"]).test_client()
    asked = {"task": "FetchMyPen"}
    said = {}
    for name, header in (("none", None), ("wrong", "Bearer wrong-token"), ("basic", "Basic dXNlcjpwYXNz")):
        refused = client.post("/tasks.json", json=asked, headers={"Authorization": header} if header else {})
        assert refused.status_code == 403
        said[name] = refused.get_json()["message"]
    assert "not this server's update token" in said["wrong"] and "not this server's" not in said["none"]
    assert "'Basic', not a bearer token" in said["basic"]
    started = client.post("/tasks.json", json=asked, headers={"Authorization": f"Bearer {token}"})
    assert started.status_code == 202
    assert runner.get(started.get_json()["started"]["id"]).done.wait(WAIT)
