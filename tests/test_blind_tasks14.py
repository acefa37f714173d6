"""A fourteenth blind round: a lab member who uses only the browser (docs/web.md, "Tried from the browser alone").

A care worker given the URL of a running ``cbrs serve`` and its update token drove the pages as a browser
does: forms submitted as their HTML writes them (method, action, field names, the token field, the
``Origin`` a browser sends), links followed. The store holds the tenth round's reading lamp, loaded into
the ontology and the map as its header says. Each test here failed before its fix. One app per module,
runs that end at once (no planner run, no simulation).
"""

from __future__ import annotations

import io
import json
import re
from collections.abc import Iterator
from html import unescape
from pathlib import Path
from typing import Any

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import CBRS, HOME, RDFS
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.tasks import TaskRun, TaskRunner
from cbrs.web import create_app
from tests.helpers_examples import EXAMPLES

TOKEN = "lab14-token"
OWN = "http://127.0.0.1:8080"
BROWSER = {"Origin": OWN, "Accept": "text/html,application/xhtml+xml,*/*;q=0.8"}
LAMP_TASK = (EXAMPLES / "lab10_switch_on_the_lamp.ttl").read_text(encoding="utf-8")
LAB10 = "https://example.org/lab10#"
REPO = Path(__file__).parent.parent
MUG_TASK = (
    "@prefix lab14: <https://example.org/lab14#> .\n"
    'lab14:FetchMyMug a cbrs:Requirement ; rdfs:label "Fetch my mug"@en ;\n'
    "    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;\n"
    '        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "mug" ; cbrs:parameterType lab14:Mug ] ;\n'
    "        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject lab14:Mug ; "
    "cbrs:conditionPredicate home:isWith ; cbrs:conditionObject home:Person ] ] .\n"
)


class _Ended(TaskRunner):
    """A runner whose runs succeed at once: no planner, no world."""

    def _run(self, run: TaskRun) -> None:
        run.result = {"plan": {"status": "planned"}, "execution": {"status": "succeeded", "steps": []}}
        run.status = "succeeded"
        run.done.set()


@pytest.fixture(scope="module")
def client() -> Iterator[FlaskClient]:
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):  # as lab10_reading_lamp.ttl's header says
        kb.load([EXAMPLES / "lab10_reading_lamp.ttl"], graph=graph)
    sparql = SparqlService(kb, EndpointConfig(update_token=TOKEN))
    app = create_app(sparql, tasks=_Ended(kb, sparql.lock, camera=None), own_origins=lambda: [OWN])
    yield app.test_client()
    kb.close()


def _text(html: str) -> str:
    html = re.sub(r"(?s)<(script|style)[^>]*>.*?</\1>", " ", html)
    return " ".join(unescape(re.sub(r"<[^>]+>", " ", html)).split())


def _errors(html: str) -> list[str]:
    """What the page says is wrong: each field's message and each error box, in words."""
    found = re.findall(r'(?s)class="[^"]*(?:field-error|error-box)[^"]*"[^>]*>(.*?)</(?:p|span|div)>', html)
    return [_text(part) for part in found]


def _post_form(client: FlaskClient, path: str, **fields: Any) -> Any:
    return client.post(path, data=fields, headers=BROWSER)


def test_a_lab_task_saved_on_the_new_task_page_opens_chosen_on_the_tasks_page(client: FlaskClient) -> None:
    """ "Run it on the tasks page" after saving lab10:SwitchOnTheReadingLamp led to a 400: the tasks page
    did not take the derived prefix its own link used ("no requirement or action named
    'lab10:SwitchOnTheReadingLamp'; did you mean SwitchOnTheReadingLamp?"), and Start refused it too."""
    saved = _post_form(client, "/tasks/new", turtle=LAMP_TASK, action="save", token=TOKEN)
    assert saved.status_code == 201, _errors(saved.text)
    link = unescape(re.search(r'id="run-link" href="([^"]+)"', saved.text).group(1))
    page = client.get(link, headers=BROWSER)
    assert page.status_code == 200, _errors(page.text)
    chosen = re.search(r'<option value="([^"]+)" selected>', page.text)
    assert chosen is not None and chosen.group(1) == "SwitchOnTheReadingLamp"
    started = _post_form(client, "/tasks", task="lab10:SwitchOnTheReadingLamp", seed="0")
    assert started.status_code == 303, _errors(started.text)  # on to the run's page (Post/Redirect/Get)
    assert "started: lab10:SwitchOnTheReadingLamp" in _text(started.text)  # as the plans page names it


def test_no_plan_names_a_lab_class_by_its_prefix_on_the_plans_and_new_task_pages(client: FlaskClient) -> None:
    """The plans page and New task's check said "no component provides effect
    (https://example.org/lab10#ReadingLamp, home:hasStatus, home:SwitchedOn)" where the run's page,
    the class page and the home name it lab10:ReadingLamp."""
    checked = _post_form(client, "/tasks/new", turtle=LAMP_TASK, action="check")
    planned = client.get("/plans?task=lab10:SwitchOnTheReadingLamp", headers=BROWSER)
    for page in (checked, planned):
        assert page.status_code == 200, _errors(page.text)
        said = _text(page.text.split("No plan.", 1)[1])
        assert "(lab10:ReadingLamp, home:hasStatus, home:SwitchedOn)" in said
        assert LAB10 not in said


def test_a_save_from_the_page_without_its_token_says_to_type_it_in_the_field(client: FlaskClient) -> None:
    """Save as task with the Update token field left empty said "updates need the server's token:
    Authorization: Bearer <token>", a header a person in a browser cannot send; a mistyped token "the bearer
    token sent is not this server's update token". Both now speak of the page's field."""
    text = LAMP_TASK.replace("SwitchOnTheReadingLamp", "SwitchOnMyLamp")
    empty = _post_form(client, "/tasks/new", turtle=text, action="save", token="")
    wrong = _post_form(client, "/tasks/new", turtle=text, action="save", token="lab14-tokn")
    for page, said in ((empty, "type it in the Update token field"), (wrong, "is not this server's update token")):
        assert page.status_code == 403
        (message,) = _errors(page.text)
        assert said in message and "Authorization" not in message and "Bearer" not in message
    program = client.post("/tasks/new.json", json={"turtle": text, "action": "save"})
    assert program.status_code == 403 and "Authorization: Bearer" in program.get_json()["message"]


def test_a_task_whose_class_is_misspelt_is_told_the_class_meant_and_where(client: FlaskClient) -> None:
    """``lab10:SwitchOnTheReadingLamp a cbrs:Requirment`` was "the text describes no task: a task is a
    cbrs:Requirement", with no word of the misspelt class the text does name, nor of its line."""
    text = LAMP_TASK.replace("a cbrs:Requirement", "a cbrs:Requirment")
    page = _post_form(client, "/tasks/new", turtle=text, action="check")
    assert page.status_code == 400
    (message,) = _errors(page.text)
    line = next(n for n, row in enumerate(text.splitlines(), start=1) if "cbrs:Requirment" in row)
    assert message.startswith(f"line {line}:") and "cbrs:Requirment" in message
    assert "did you mean cbrs:Requirement?" in message


def test_a_concept_written_without_its_prefix_on_the_match_page_is_told_the_one_meant(client: FlaskClient) -> None:
    """Matchmaking with the inputs "MarkerColour" (the name a class page shows after its prefix) said
    "MarkerColour: MarkerColour: is not a known prefix; use one of cbrs, home, act, ..." (25 prefixes); a
    lab's ReadingLamp and a slipped prefix (hom:Cup) were refused so too."""
    page = client.get("/match?inputs=MarkerColour&outputs=ReadingLamp&effects=hom:Cup+home:isWith+home:Person")
    assert page.status_code == 400
    said = " | ".join(_errors(page.text))
    assert "did you mean home:MarkerColour?" in said
    assert "did you mean lab10:ReadingLamp?" in said
    assert "did you mean home:Cup?" in said
    assert "MarkerColour: MarkerColour:" not in said


def _load_form(client: FlaskClient, path: Path, graph: str, token: str, name: str | None = None) -> Any:
    """The Load a file page's form as a browser sends it: multipart, the file under its own name."""
    data = {"graph": graph, "token": token, "file": (io.BytesIO(path.read_bytes()), name or path.name)}
    return client.post("/load", data=data, headers=BROWSER, content_type="multipart/form-data")


def test_a_lab_file_is_loaded_from_the_browser_into_the_graphs_its_header_names(client: FlaskClient) -> None:
    """A lab member with the URL and the token had no page to put their own things into the store: the
    SPARQL editor refuses updates (pointing at /update and a header), New task writes requirements only.
    docs/examples/lab11_coaster.ttl says to load it into the ontology and the map; from /load it is."""
    form = client.get("/load", headers=BROWSER)
    assert form.status_code == 200
    assert 'enctype="multipart/form-data"' in form.text and 'name="file"' in form.text and 'name="token"' in form.text
    coaster = EXAMPLES / "lab11_coaster.ttl"
    before = client.get("/search.json?q=Coaster1").get_json()["things"]["count"]
    refused = _load_form(client, coaster, "map", "")
    assert refused.status_code == 403 and "type it in the Update token field" in " ".join(_errors(refused.text))
    assert client.get("/search.json?q=Coaster1").get_json()["things"]["count"] == before == 0
    for graph in ("ontology", "map"):
        loaded = _load_form(client, coaster, graph, TOKEN)
        assert loaded.status_code == 201, _errors(loaded.text)
        assert f"lab11_coaster.ttl into graph:{graph}" in _text(loaded.text)
    assert client.get("/search.json?q=Coaster1").get_json()["things"]["count"] == 1
    broken = _load_form(client, REPO / "tests" / "data" / "bad" / "broken.ttl", "map", TOKEN, name="my_lamp.ttl")
    assert broken.status_code == 400
    (message,) = _errors(broken.text)
    assert message.startswith("my_lamp.ttl:4:") and "<request body>" not in message


def test_a_file_too_big_to_load_is_told_the_limit_in_words(client: FlaskClient) -> None:
    """A file over the server's request limit got Werkzeug's "The data value transmitted exceeds the
    capacity limit.", naming neither the limit nor what to do."""
    limit = client.application.config["MAX_CONTENT_LENGTH"]
    big = b"# padding\n" * (limit // 10 + 1)
    data = {"graph": "map", "token": TOKEN, "file": (io.BytesIO(big), "big.ttl")}
    page = client.post("/load", data=data, headers=BROWSER, content_type="multipart/form-data")
    assert page.status_code == 413
    said = _text(page.text)
    assert "capacity limit" not in said
    assert f"{limit:,} bytes" in said and "cbrs load" in said


def test_a_new_task_in_a_namespace_the_store_lacks_is_named_by_the_text_s_own_prefix(client: FlaskClient) -> None:
    """A lab's first task, checked before anything of its namespace is stored, was titled "New task:
    https://example.org/lab14#FetchMyMug, unsolvable", its undeclared class named by its IRI, although
    the text declares @prefix lab14: and the user wrote lab14:FetchMyMug."""
    text = MUG_TASK
    page = _post_form(client, "/tasks/new", turtle=text, action="check")
    assert page.status_code == 200, _errors(page.text)
    title = re.search(r"<title>(.*?)</title>", page.text).group(1)
    assert title.startswith("New task: lab14:FetchMyMug")
    assert "https://example.org/lab14#" not in _text(page.text.split("</textarea>", 1)[1])
    assert "https://example.org/lab14#" not in client.get("/").text  # the next page knows no lab14:


def test_a_misspelt_search_offers_the_names_meant(client: FlaskClient) -> None:
    """The search is how a person who types finds things, and "reading lamb", "kitchen tabel" and "celing
    camera" each found nothing in four groups and said no more; each now offers the names meant, each a
    link to its search, in the page and the twin (``meant``)."""
    for typed, meant in (
        ("reading lamb", "reading lamp"),
        ("kitchen tabel", "kitchen table"),
        ("celing camera", "ceiling camera"),
    ):
        page = client.get("/search", query_string={"q": typed})
        assert page.status_code == 200
        assert f'href="/search?q={meant.replace(" ", "+")}"' in page.text, typed
        twin = client.get("/search.json", query_string={"q": typed}).get_json()
        assert twin["total"] == 0 and meant in [m["text"] for m in twin["meant"]]
    found = client.get("/search.json", query_string={"q": "reading lamp"}).get_json()
    assert found["total"] > 0 and found["meant"] == []


def test_a_task_file_chosen_for_the_map_is_told_where_tasks_go(client: FlaskClient) -> None:
    """lab10_switch_on_the_lamp.ttl (a task, "for the requirements graph") chosen for the map was loaded
    there without a word, as cbrs load --graph map does; the page now says where a task goes and writes
    nothing, and so for a component's advertisement chosen for the ontology."""
    before = client.get("/index.json").get_json()
    refused = _load_form(client, EXAMPLES / "lab10_switch_on_the_lamp.ttl", "map", TOKEN, name="switch_on.ttl")
    assert refused.status_code == 400
    (message,) = _errors(refused.text)
    assert "lab10:SwitchOnTheReadingLamp" in message and "the requirements graph" in message
    plug = _load_form(client, EXAMPLES / "lab10_lamp_switch.ttl", "ontology", TOKEN)
    assert plug.status_code == 400 and "the services graph" in " ".join(_errors(plug.text))
    assert client.get("/index.json").get_json()["graphs"] == before["graphs"]


def test_a_misplaced_task_of_a_new_namespace_is_named_by_the_file_s_prefix(client: FlaskClient) -> None:
    """The refusal of a task file chosen for the map named a task of a namespace the store lacks by its
    whole IRI (https://example.org/lab14#FetchMyMug), where the file writes lab14:FetchMyMug."""
    declared = "".join(f"@prefix {p}: <{ns}> .\n" for p, ns in (("cbrs", CBRS), ("home", HOME), ("rdfs", RDFS)))
    body = (declared + MUG_TASK).encode()
    data = {"graph": "map", "token": TOKEN, "file": (io.BytesIO(body), "fetch_my_mug.ttl")}
    page = client.post("/load", data=data, headers=BROWSER, content_type="multipart/form-data")
    assert page.status_code == 400
    (message,) = _errors(page.text)
    assert "a task (lab14:FetchMyMug, a cbrs:Requirement)" in message


def test_a_planned_goal_names_a_lab_class_by_its_prefix(client: FlaskClient) -> None:
    """With the plug's components loaded (from the page, into services), the lamp's task plans, and the
    plans page's Goals said "(https://example.org/lab10#ReadingLamp, home:hasStatus, home:SwitchedOn)".
    Last in the module: the plug makes the lamp's task plannable for the tests after it."""
    saved = _post_form(client, "/tasks/new", turtle=LAMP_TASK, action="save", token=TOKEN, replace="1")
    loaded = _load_form(client, EXAMPLES / "lab10_lamp_switch.ttl", "services", TOKEN)
    assert saved.status_code == 201 and loaded.status_code == 201, _errors(saved.text + loaded.text)
    page = client.get("/plans?task=lab10:SwitchOnTheReadingLamp", headers=BROWSER)
    assert page.status_code == 200 and "No plan." not in page.text
    goals = _text(page.text.split(">Goals<", 1)[1].split("</ul>", 1)[0])
    assert "(lab10:ReadingLamp, home:hasStatus, home:SwitchedOn)" in goals and LAB10 not in goals


def test_the_live_tasks_page_is_given_the_prefix_of_a_lab_s_components(client: FlaskClient) -> None:
    """The tasks page's script names the IRIs of live events (steps, components, reasons) with the
    prefixes the page gives it (``data-prefixes``): cbrs's own only, so a lab's plug (a component over the
    bridge, in no "Make fail" list) read
    https://example.org/lab10#SwitchOnReadingLamp_LampPlug01 live, and lab10:... once the page was
    reloaded. Runs after the plug's components are loaded (the test above)."""
    page = client.get("/tasks", headers=BROWSER)
    given = json.loads(unescape(re.search(r'data-prefixes="([^"]*)"', page.text).group(1)))
    assert given.get("lab10") == LAB10 and given["svc"] == "https://w3id.org/cbrs/service#"
