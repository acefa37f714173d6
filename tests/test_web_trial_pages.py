"""What a new user meets on the bundled store's first pages: named graphs that say what they hold and
what fills them, and a plans page that says what it does before a task is chosen.

A new store's graph:world, graph:plans and graph:liveness hold no triple: the overview listed them with a
0, and their pages said only "It is the subject of no triple." and "It is the object of no triple.".
The plans page showed two drop-downs and a button, and nothing of what planning would show.
"""

from __future__ import annotations

import logging
import re
import sys
import threading
import tomllib
from html import unescape

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import GraphName
from cbrs.kb.resources import ontology_dir
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app, warmup


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def test_every_cbrs_graph_has_a_note_and_no_other_graph_does() -> None:
    listed = tomllib.loads((ontology_dir() / "graphs.toml").read_text(encoding="utf-8"))
    assert sorted(listed) == sorted(graph.value for graph in GraphName)
    assert all(sorted(note) == ["holds", "written_by"] and all(note.values()) for note in listed.values())


def test_the_overview_says_what_each_graph_holds_and_what_fills_an_empty_one(client: FlaskClient) -> None:
    graphs = client.get("/index.json").get_json()["graphs"]
    assert {g["graph"] for g in graphs} == {graph.iri for graph in GraphName}
    empty = [g for g in graphs if not g["triples"]]
    assert empty and len(empty) < len(graphs)  # the bundled store has both
    page = unescape(client.get("/").text)
    rows = re.findall(r"<tr><td>.*?</tr>", page, re.S)
    assert len(rows) == len(graphs)
    for graph, row in zip(graphs, rows, strict=True):
        assert graph["name"] in row and graph["holds"] in row
        assert (f"Empty: {graph['written_by']}." in row) == (graph["triples"] == 0), graph["name"]


@pytest.mark.parametrize("graph", list(GraphName), ids=lambda g: g.value)
def test_a_graph_s_page_says_what_it_holds_and_what_writes_it(client: FlaskClient, graph: GraphName) -> None:
    body = client.get("/resource.json", query_string={"iri": graph.iri}).get_json()
    page = unescape(client.get("/resource", query_string={"iri": graph.iri}).text)
    assert body["graph"]["holds"] in page and body["graph"]["written_by"] in page
    if not body["incoming"] and not body["outgoing"]:  # a graph no triple names: no empty Out and In
        assert "It is the subject of no triple." not in page and "No triple names this graph itself" in page
    assert ("(none yet)" in page) == (body["graph"]["triples"] == 0)
    assert ("The graph's triples (Turtle)" in page) == (body["graph"]["triples"] > 0)


def test_another_iri_s_page_is_as_it_was(client: FlaskClient) -> None:
    body = client.get("/resource.json", query_string={"iri": "home:Pen"}).get_json()
    page = client.get("/resource", query_string={"iri": "home:Pen"}).text
    assert body["graph"] is None and "Written by" not in page and "<h2>Out:" in page


def test_the_plans_page_says_what_it_does_until_a_task_is_chosen(client: FlaskClient) -> None:
    intro = "Choose a task to compose it from the registered services"
    assert intro in client.get("/plans").text
    refused = client.get("/plans", query_string={"task": "NoSuchTask"})
    assert refused.status_code == 400 and intro not in refused.text


def test_serving_any_store_imports_the_first_pages_libraries_once_a_page_is_asked(
    bundled_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """The bundled store is not warmed up (it reads fast), but its first service, plans and tasks pages
    each paid 0.4 to 0.7 s importing networkx and numpy. They are imported with the first page, not at
    start: a server only programs query has no use for their 30 MB. Small modules stand for them here."""
    app = create_app(SparqlService(bundled_kb))
    app.config["CBRS_PRELOAD_MODULES"] = ("colorsys", "no_such_module_here")
    monkeypatch.delitem(sys.modules, "colorsys", raising=False)
    assert warmup.warm_up(app) is None  # nothing of the store is read
    client = app.test_client()
    assert client.get("/sparql", query_string={"query": "ASK {}"}).status_code == 200
    assert client.get("/healthz").status_code == 200
    assert "cbrs.preload" not in app.extensions  # no page yet
    with caplog.at_level(logging.INFO, logger="cbrs.web"):
        assert client.get("/").status_code == 200
        thread = app.extensions["cbrs.preload"]
        assert isinstance(thread, threading.Thread)
        thread.join(timeout=10)
        client.get("/services")
    assert app.extensions["cbrs.preload"] is thread  # once
    assert not thread.is_alive() and "colorsys" in sys.modules
    assert "not preloading no_such_module_here" in caplog.text
    app.config["CBRS_PRELOAD_MODULES"] = ()
    assert warmup.preload(app) is None


def test_an_app_no_server_started_imports_nothing_ahead(bundled_kb: KnowledgeBase) -> None:
    app = create_app(SparqlService(bundled_kb))
    assert app.test_client().get("/").status_code == 200
    assert "cbrs.preload" not in app.extensions


@pytest.mark.parametrize(
    ("asked", "meant"),
    [("req:RobotSelfPositon", "req:RobotSelfPosition"), ("FetchMyPne", "req:FetchMyPen"), ("req:Nothing", None)],
)
def test_an_unknown_stored_requirement_is_named_with_the_ones_meant(
    client: FlaskClient, asked: str, meant: str | None
) -> None:
    """The match form said "no service description <https://w3id.org/cbrs/requirement#...> in the
    store" for a stored requirement it does not have, and nothing of the list the user chose from."""
    answer = client.get("/match.json", query_string={"requirement": asked})
    count = len(client.get("/match.json").get_json()["requirements"])
    message = answer.get_json()["fields"]["requirement"]
    assert answer.status_code == 400 and f"no stored requirement {asked};" in message
    assert (f"did you mean {meant}?" in message) == (meant is not None) and f"the {count} in the list" in message
