"""Follow-ups of the fourteenth blind round, from the browser (docs/web.md, "Tried from the browser alone").

A task file chosen for another graph than requirements was refused by the Load a file page only: ``cbrs load
--graph map`` and the Graph Store took it without a word. The check is the library's now, every way in.
"""

from __future__ import annotations

from pathlib import Path

import pyoxigraph as ox
import pytest
from click.testing import CliRunner
from flask.testing import FlaskClient

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.loader import MisplacedDescriptionError
from cbrs.kb.namespaces import GraphName
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app

EXAMPLES = Path(__file__).resolve().parent.parent / "docs" / "examples"
LAMP_TASK = EXAMPLES / "lab10_switch_on_the_lamp.ttl"
LAMP_PLUG = EXAMPLES / "lab10_lamp_switch.ttl"
TOKEN = "followups-token"
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
