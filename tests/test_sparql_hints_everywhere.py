"""``cbrs query``, the SPARQL endpoint (JSON and the HTML a browser gets) and the browser's SPARQL editor
give one hint for a query that does not parse for a prefix nobody declared, from one library function
(:func:`cbrs.kb.sparql_hints.explain_syntax_error`), and one note for a query whose names name nothing
(:func:`cbrs.unmentioned_names.unmentioned_names`; the endpoint answers those as the protocol says).

The endpoint and the editor offered cbrs's own prefixes alone: ``lab:Trolley1`` in a store that derives
``lab4:`` was told "cbrs declares cbrs:, home:, ..." where ``cbrs query`` said "did you mean 'lab4:'
(PREFIX lab4: <https://example.org/lab4#>, derived for this store)?"."""

from __future__ import annotations

import html
import json
from collections.abc import Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner
from flask.testing import FlaskClient

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app

LAB4 = "https://example.org/lab4#"
MISSPELT = "SELECT * WHERE { lab:Trolley1 ?p ?o }"
HINT = f"the prefix 'lab:' is not declared: add PREFIX lab: <IRI>; did you mean 'lab4:' (PREFIX lab4: <{LAB4}>"
NOTHING = "SELECT * WHERE { ?cup home:isLocatedOnn ?table }"


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> str:
    """An on-disk store holding one IRI of a lab's namespace, for which it derives the prefix lab4:."""
    location = str(tmp_path_factory.mktemp("hints") / "store")
    kb = KnowledgeBase.open(location)
    kb.update(f'INSERT DATA {{ GRAPH graph:ontology {{ <{LAB4}Trolley1> rdfs:label "trolley" }} }}')
    kb.close()
    return location


@pytest.fixture(scope="module")
def cli_said(store: str) -> dict[str, str]:
    """What ``cbrs query`` says of each text on standard error (run before the store is opened here)."""
    said = {}
    for text in (MISSPELT, NOTHING):
        result = CliRunner().invoke(cli, ["--store", store, "query", text])
        said[text] = result.stderr
    return said


@pytest.fixture(scope="module")
def client(store: str, cli_said: dict[str, str]) -> Iterator[FlaskClient]:
    kb = KnowledgeBase.open(store)
    yield create_app(SparqlService(kb, EndpointConfig(update_token="hints", isolate=False))).test_client()
    kb.close()


def test_a_misspelt_store_prefix_is_offered_the_same_declaration_everywhere(
    client: FlaskClient, cli_said: dict[str, str]
) -> None:
    assert HINT in cli_said[MISSPELT]
    endpoint = client.get("/sparql", query_string={"query": MISSPELT}, headers={"Accept": "application/json"})
    assert endpoint.status_code == 400 and HINT in endpoint.get_json()["message"]
    page = client.get("/sparql", query_string={"query": MISSPELT}, headers={"Accept": "text/html"})
    assert page.status_code == 400 and HINT in html.unescape(page.get_data(as_text=True))
    editor = client.get("/query.json", query_string={"query": MISSPELT})
    assert editor.status_code == 400 and HINT in editor.get_json()["fields"]["query"]


def test_the_endpoint_gives_a_store_prefix_it_does_not_declare_its_declaration(client: FlaskClient) -> None:
    """The endpoint declares cbrs's prefixes alone; the editor and ``cbrs query`` declare the store's too."""
    text = MISSPELT.replace("lab:", "lab4:")
    endpoint = client.get("/sparql", query_string={"query": text}, headers={"Accept": "application/json"})
    assert endpoint.status_code == 400
    assert (
        f"the prefix 'lab4:' is not declared: add PREFIX lab4: <{LAB4}> (derived for this store"
        in (endpoint.get_json()["message"])
    )
    editor = client.get("/query.json", query_string={"query": text})
    assert editor.status_code == 200 and editor.get_json()["result"]["count"] == 1


def test_a_name_that_names_nothing_gets_one_note_in_the_cli_and_the_editor(
    client: FlaskClient, cli_said: dict[str, str]
) -> None:
    note = "nothing in the store mentions home:isLocatedOnn; did you mean home:isLocatedOn?"
    assert f"note: {note}" in cli_said[NOTHING].splitlines()
    editor = client.get("/query.json", query_string={"query": NOTHING})
    assert editor.status_code == 200 and editor.get_json()["notes"] == [note]
    endpoint = client.get("/sparql", query_string={"query": NOTHING}, headers={"Accept": "application/json"})
    assert json.loads(endpoint.get_data(as_text=True))["results"]["bindings"] == []  # the protocol's answer


def test_the_hint_is_read_from_the_store_only_for_a_prefix_nobody_declared(tmp_path: Path) -> None:
    """``offered`` is called only when the text uses an undeclared prefix: a bracket left open costs no
    read of the store's terms."""
    from cbrs.kb.errors import QuerySyntaxError
    from cbrs.kb.sparql_hints import explain_syntax_error

    def offered() -> dict[str, str]:
        raise AssertionError("read")

    error = QuerySyntaxError("SELECT * WHERE { ?s ?p ?o", "error at 1:26: expected '}'")
    explained = explain_syntax_error(error, "SELECT * WHERE { ?s ?p ?o", "query", offered=offered)
    assert "1 '{' not closed" in str(explained)


def test_a_named_querys_binding_that_names_nothing_gets_the_clis_note_from_the_library() -> None:
    """``cbrs query --name ... --bind`` said which bound IRI names nothing; the note was the CLI's own."""
    from cbrs.unmentioned_names import unmentioned_bindings

    values = {"class": "home:Cup", "room": "world:Kitchn"}
    bound = ["--bind", "class=home:Cup", "--bind", "room=world:Kitchn"]
    result = CliRunner().invoke(cli, ["--store", ":memory:", "query", "--name", "things_in_room", *bound])
    kitchn = "https://w3id.org/cbrs/world#Kitchn"
    note = f"nothing in the store mentions <{kitchn}> (bound to room); did you mean world:Kitchen?"
    assert result.stderr.splitlines() == [f"note: {note}"]
    kb = KnowledgeBase.open(":memory:")
    try:
        assert unmentioned_bindings(kb, "things_in_room", values) == [note]
        assert unmentioned_bindings(kb, "things_in_room", {**values, "room": "world:Kitchen"}) == []
    finally:
        kb.close()
