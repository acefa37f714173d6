"""An update written in the SPARQL editor is refused as an update, saying where updates go: it was
"SPARQL syntax error: ... POST it as update= ... with the update token", which a new user read as a
fault of the text, and on a read-only server (no update token) there is no token to use."""

from __future__ import annotations

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app

UPDATES = ["INSERT DATA { <urn:x:a> <urn:x:b> <urn:x:c> }", "DELETE WHERE { ?s ?p ?o }"]


def _message(client: FlaskClient, text: str) -> str:
    response = client.get("/query.json", query_string={"query": text})
    assert response.status_code == 400
    message: str = response.get_json()["fields"]["query"]
    return message


@pytest.mark.parametrize("text", UPDATES)
def test_a_read_only_server_says_it_takes_no_updates(bundled_kb: KnowledgeBase, text: str) -> None:
    client = create_app(SparqlService(bundled_kb)).test_client()
    before = bundled_kb.store.dump()
    message = _message(client, text)
    assert "syntax error" not in message and "runs queries and changes nothing" in message
    assert "started read-only (no update token set)" in message
    assert bundled_kb.store.dump() == before


def test_a_writable_server_says_where_updates_go(bundled_kb: KnowledgeBase) -> None:
    client = create_app(SparqlService(bundled_kb, EndpointConfig(update_token="secret"))).test_client()
    message = _message(client, UPDATES[0])
    assert "POST the update to /update" in message and "secret" not in message


def test_a_broken_query_still_gets_the_parsers_words(bundled_kb: KnowledgeBase) -> None:
    client = create_app(SparqlService(bundled_kb)).test_client()
    assert _message(client, "SELECT ?x WHERE {").startswith("SPARQL syntax error")
