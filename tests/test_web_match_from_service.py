"""Matchmaking from a service's page: "Find services like this one" asks the matchmaking page for what
the advertisement offers (its inputs, outputs, preconditions and effects as a written requirement), and
each ranked candidate links to its own service page."""

from __future__ import annotations

import re
from html import unescape

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import expand
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

CAMERA = "svc:LocateMobileRobot_CeilingCamera01"


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def test_the_link_asks_for_what_the_service_offers_and_ranks_it_first(client: FlaskClient) -> None:
    body = client.get("/service.json", query_string={"iri": CAMERA}).get_json()
    page = client.get("/service", query_string={"iri": CAMERA}).text
    link = re.search(r'<a class="button" href="([^"]+)">Find services like this one</a>', page)
    assert link is not None and unescape(link.group(1)) == body["similar"]
    ranked = client.get(body["similar"].replace("/match", "/match.json", 1))
    assert ranked.status_code == 200, ranked.text[:300]
    asked = ranked.get_json()["requirement"]
    assert asked["written"] and asked["outputs"] == [expand("home:RobotLocation")]
    assert asked["inputs"] == [expand("home:MarkerColour")] and len(asked["effects"]) == 1
    candidates = ranked.get_json()["rankings"][0]["candidates"]
    assert candidates[0]["advertisement"] == expand(CAMERA) and candidates[0]["score"] == pytest.approx(1.0)


def test_a_requirement_has_no_such_link(client: FlaskClient) -> None:
    body = client.get("/service.json", query_string={"iri": "req:FetchMyPen"}).get_json()
    assert "similar" not in body and body["match"]


def test_each_candidate_links_its_service_page(client: FlaskClient) -> None:
    page = client.get("/match", query_string={"requirement": "req:FetchMyPen", "top": "3"}).text
    services = re.findall(r'<div class="explanation">\s*<p><a href="(/service\?iri=[^"]+)"', page)
    assert len(services) == 3
    for href in services:
        assert client.get(unescape(href)).status_code == 200, href


def test_a_requirement_page_links_its_plan(client: FlaskClient) -> None:
    body = client.get("/service.json", query_string={"iri": "req:FetchMyPen"}).get_json()
    assert body["plan"] == "/plans?task=req:FetchMyPen"
    assert f'<a class="button" href="{body["plan"]}">Plan it</a>' in client.get("/service?iri=req:FetchMyPen").text
    plan = client.get(body["plan"].replace("/plans", "/plans.json", 1)).get_json()
    assert plan["composition"]["status"] == "planned" and plan["composition"]["steps"]
    assert "plan" not in client.get("/service.json", query_string={"iri": CAMERA}).get_json()
