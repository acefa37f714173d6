"""The page of an IRI lists at most ``MAX_VALUES`` values per predicate and direction, and counts them
all: owl:Class on OWLS-TC is the object of 13,000 rdf:type triples, which made a page of 3.8 MB."""

from __future__ import annotations

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app, resource


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def test_values_past_the_limit_are_counted_not_listed(client: FlaskClient, monkeypatch: pytest.MonkeyPatch) -> None:
    whole = client.get("/resource.json", query_string={"iri": "owl:Class"}).get_json()
    types = next(g for g in whole["incoming"] if g["name"] == "rdf:type")
    assert types["count"] == len(types["values"]) > 20
    monkeypatch.setattr(resource, "MAX_VALUES", 20)
    cut = client.get("/resource.json", query_string={"iri": "owl:Class"}).get_json()
    listed = next(g for g in cut["incoming"] if g["name"] == "rdf:type")
    assert len(listed["values"]) == 20 and listed["count"] == types["count"]
    assert listed["values"] == types["values"][:20]
    assert cut["counts"] == whole["counts"]  # the headings count every triple
    page = client.get("/resource", query_string={"iri": "owl:Class"}).text
    assert f"and {types['count'] - 20} more rdf:type not listed ({types['count']} in all)" in page


def test_a_small_group_lists_every_value(client: FlaskClient) -> None:
    body = client.get("/resource.json", query_string={"iri": "home:RobotPosition"}).get_json()
    assert all(g["count"] == len(g["values"]) for g in body["outgoing"] + body["incoming"])
    assert "not listed" not in client.get("/resource", query_string={"iri": "home:RobotPosition"}).text
