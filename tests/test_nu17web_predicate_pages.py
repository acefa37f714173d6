"""A property's page lists the triples that use it as their predicate. Every resource page links its
predicates (rdf:type, rdfs:label, ...) to their pages, and each was a 404 where the store says nothing
about the property itself: the page looked only at triples the IRI is the subject or object of."""

from __future__ import annotations

import re
from html import unescape
from typing import Any

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import expand
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app
from cbrs.web.resource import MAX_VALUES


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def _twin(client: FlaskClient, iri: str) -> dict[str, Any]:
    response = client.get("/resource.json", query_string={"iri": iri})
    assert response.status_code == 200, response.get_data(as_text=True)
    body: dict[str, Any] = response.get_json()
    return body


def _uses(client: FlaskClient, iri: str) -> int:
    """How many triples use ``iri`` (a constant of these tests) as their predicate, from the endpoint."""
    text = f"SELECT (COUNT(*) AS ?n) WHERE {{ GRAPH ?g {{ ?s <{expand(iri)}> ?o }} }}"
    answer = client.get("/sparql", query_string={"query": text}, headers={"Accept": "application/sparql-results+json"})
    return int(answer.get_json()["results"]["bindings"][0]["n"]["value"])


def test_every_predicate_a_service_page_links_has_a_page(client: FlaskClient) -> None:
    page = client.get("/resource", query_string={"iri": "svc:LocateMobileRobot_CeilingCamera01"}).get_data(as_text=True)
    links = {unescape(href) for href in re.findall(r'href="(/resource\?iri=[^"]+)"', page)}
    assert any("rdf-syntax-ns%23type" in link or "rdf-syntax-ns#type" in link for link in links)
    for link in links:
        assert client.get(link).status_code == 200, link


@pytest.mark.parametrize("iri", ["cbrs:deviceName", "home:hasMarker"])
def test_a_property_used_less_often_than_the_page_shows_lists_every_use(client: FlaskClient, iri: str) -> None:
    uses = _twin(client, iri)["as_predicate"]
    count = _uses(client, iri)
    assert 0 < count <= MAX_VALUES  # the case this test is about
    assert len(uses["triples"]) == count and not uses["more"]
    assert all(t["subject"]["type"] in ("iri", "bnode") for t in uses["triples"])


def test_rdf_type_shows_the_first_uses_and_says_there_are_more(client: FlaskClient) -> None:
    assert _uses(client, "rdf:type") > MAX_VALUES
    uses = _twin(client, "rdf:type")["as_predicate"]
    assert len(uses["triples"]) == MAX_VALUES and uses["more"]
    page = client.get("/resource", query_string={"iri": "rdf:type"}).get_data(as_text=True)
    assert f"the first {MAX_VALUES} triples" in page and page.count("<tr><td>") >= MAX_VALUES
    # The editor's link lists them all.
    listed = client.get("/query.json", query_string={"query": uses["query"]}).get_json()["result"]
    assert listed["kind"] == "select" and listed["truncated"]  # more than the editor's 1,000 rows too


def test_the_editor_link_lists_exactly_the_uses(client: FlaskClient) -> None:
    uses = _twin(client, "cbrs:deviceName")["as_predicate"]
    listed = client.get("/query.json", query_string={"query": uses["query"]}).get_json()["result"]
    assert listed["count"] == _uses(client, "cbrs:deviceName") and not listed["truncated"]
    shown = {(t["subject"]["value"], t["object"]["value"]) for t in uses["triples"]}
    assert {(row["subject"]["value"], row["object"]["value"]) for row in listed["rows"]} == shown


def test_an_iri_used_nowhere_is_still_not_found(client: FlaskClient) -> None:
    assert client.get("/resource.json", query_string={"iri": "http://example.org/nothing"}).status_code == 404
    assert "as-predicate" not in client.get("/resource", query_string={"iri": "home:RobotLocation"}).get_data(
        as_text=True
    )  # a class, never a predicate: no such section


@pytest.mark.parametrize("iri", ["home:RobotLocation", "owl:Class", "svc:LocateMobileRobot_CeilingCamera01"])
def test_a_resource_pages_values_come_in_order(client: FlaskClient, iri: str) -> None:
    """The named query no longer sorts (2.5 to 4 s of owl:Class's page on OWLS-TC): the page orders each
    predicate's values, stated before entailed, then as SPARQL orders terms (blank nodes, IRIs, literals)."""
    kinds = {"bnode": 0, "iri": 1, "literal": 2}
    body = _twin(client, iri)
    for group in body["outgoing"] + body["incoming"]:
        keys = [
            (v["graph"].endswith("/entailed"), kinds[v["term"]["type"]], v["term"]["value"]) for v in group["values"]
        ]
        assert keys == sorted(keys), (iri, group["name"])
        assert len(group["values"]) == min(group["count"], MAX_VALUES)


def test_a_property_only_used_as_a_predicate_shows_its_uses_first(client: FlaskClient) -> None:
    page = client.get("/resource", query_string={"iri": "rdf:type"}).get_data(as_text=True)
    assert page.index('id="as-predicate-heading"') < page.index("<h2>Out:")  # not below two empty sections
    page = client.get("/resource", query_string={"iri": "cbrs:deviceName"}).get_data(as_text=True)
    assert page.index("<h2>In:") < page.index('id="as-predicate-heading"')  # declared: its own triples first
