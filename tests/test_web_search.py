"""The search across the store by name (``/search``, and the box in every page's header): classes and
properties, advertisements and requirements, ranked exact name first; every link it gives resolves."""

from __future__ import annotations

import re
from html import unescape
from typing import Any

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import expand
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app, ranking, search

from .test_access import HOSTILE


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def found(client: FlaskClient, text: str) -> Any:
    response = client.get("/search.json", query_string={"q": text})
    assert response.status_code == 200, response.text[:300]
    return response.get_json()


def test_a_class_is_found_by_name_with_the_exact_name_first(client: FlaskClient) -> None:
    body = found(client, "position")
    names = [t["name"] for t in body["terms"]["matches"]]
    assert names[0] == "home:Position"
    assert {"home:RobotPosition", "home:Position2D"} <= set(names)
    assert body["terms"]["count"] == len(names)
    assert all(t["kind"] in ("class", "property") for t in body["terms"]["matches"])


def test_a_service_is_found_by_its_name_device_or_label(client: FlaskClient) -> None:
    body = found(client, "ceiling camera")
    services = {ad["service"] for ad in body["advertisements"]["matches"]}
    assert expand("svc:LocateMobileRobot_CeilingCamera01") in services
    assert body["advertisements"]["count"] == len(services)


def test_a_service_is_found_by_the_concept_of_its_outputs_after_those_by_name(client: FlaskClient) -> None:
    ads = found(client, "position")["advertisements"]["matches"]
    by_name = [ad for ad in ads if not ad["via"]]
    by_concept = [ad for ad in ads if ad["via"]]
    assert by_name and by_concept
    assert ads == by_name + by_concept  # the ones found by name come first
    planner = next(ad for ad in by_concept if ad["service_name"] == "PlanPathAStar")
    assert [c["name"] for c in planner["via"]] == ["home:Position"]
    assert expand("home:Position") in planner["inputs"] + planner["outputs"]


def test_a_requirement_is_found_and_the_search_is_case_blind(client: FlaskClient) -> None:
    body = found(client, "fetchmypen")
    assert [r["requirement"] for r in body["requirements"]["matches"]] == [expand("req:FetchMyPen")]
    assert body["total"] == sum(body[g]["count"] for g in ("terms", "advertisements", "requirements"))


def test_a_prefixed_name_goes_to_its_page_and_is_looked_for_by_its_local_name(client: FlaskClient) -> None:
    body = found(client, "home:RobotPosition")
    assert body["iri"] == {"iri": expand("home:RobotPosition"), "name": "home:RobotPosition"}
    assert body["terms"]["matches"][0]["name"] == "home:RobotPosition"
    assert found(client, "home:NoSuchThingAnywhere")["iri"] is None


def test_nothing_found_says_so(client: FlaskClient) -> None:
    body = found(client, "zzqqxx")
    assert body["total"] == 0
    page = client.get("/search", query_string={"q": "zzqqxx"}).text
    assert "No class or property has “zzqqxx”" in page and "No advertisement has" in page


def test_each_group_is_cut_and_counts_every_match(client: FlaskClient, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(search, "SHOWN", 2)
    body = found(client, "position")
    assert len(body["terms"]["matches"]) == 2 and body["terms"]["count"] > 2
    page = client.get("/search", query_string={"q": "position"}).text
    assert f"The first 2 of {body['terms']['count']}" in page


def test_every_link_of_the_results_page_resolves(client: FlaskClient) -> None:
    page = client.get("/search", query_string={"q": "camera"}).text
    links = {unescape(h) for h in re.findall(r'href="(/[^"]*)"', page) if not h.startswith("/static/")}
    assert any(h.startswith("/service?") for h in links) and any(h.startswith("/taxonomy/class?") for h in links)
    for href in sorted(links):
        assert client.get(href).status_code == 200, href


def test_the_header_of_every_page_has_the_search_box(client: FlaskClient) -> None:
    for path in ("/", "/taxonomy", "/services", "/taxonomy/class?iri=home:Position"):
        page = client.get(path).text
        assert '<form class="site-search" method="get" action="/search" role="search">' in page, path
        assert '<label for="site-search"' in page
    # the search page has its own box, not a second one in the header
    assert 'id="site-search"' not in client.get("/search").text


def test_an_empty_search_shows_the_form_and_a_long_one_is_refused_beside_the_field(client: FlaskClient) -> None:
    empty = client.get("/search")
    assert empty.status_code == 200 and 'name="q"' in empty.text and "Advertisements" not in empty.text
    long = client.get("/search", query_string={"q": "x" * 201})
    assert long.status_code == 400 and 'id="q-error"' in long.text and 'aria-invalid="true"' in long.text
    twin = client.get("/search.json", query_string={"q": "x" * 201})
    assert twin.status_code == 400 and "q" in twin.get_json()["fields"]


def test_hostile_search_texts_are_only_text(client: FlaskClient, bundled_kb: KnowledgeBase) -> None:
    before = bundled_kb.store.dump()
    for value in (*HOSTILE, "<script>alert(1)</script>"):
        response = client.get("/search.json", query_string={"q": value})
        assert response.status_code == 200, (value, response.text[:300])
        assert client.get("/search", query_string={"q": value}).status_code == 200
    page = client.get("/search", query_string={"q": "<script>alert(1)</script>"}).text
    assert "<script>alert(1)" not in page and "&lt;script&gt;alert(1)" in page
    assert bundled_kb.store.dump() == before


def test_a_not_found_page_offers_to_search_for_the_name(client: FlaskClient) -> None:
    missing = client.get("/service", query_string={"iri": "home:RobotPosition"})  # a class, not a service
    assert missing.status_code == 404
    assert '<input type="search" id="error-search" name="q" value="RobotPosition"' in missing.text
    found = client.get("/search.json", query_string={"q": "RobotPosition"}).get_json()
    assert found["terms"]["matches"][0]["name"] == "home:RobotPosition"
    gone = client.get("/taxonomy/class", query_string={"iri": "http://example.org/lab#Nothing"})
    assert gone.status_code == 404 and 'value="Nothing"' in gone.text
    plain = client.get("/no-such-page", headers={"Accept": "text/html"})
    assert plain.status_code == 404 and "error-search" not in plain.text


def test_a_name_that_has_the_text_comes_before_a_label_that_has_it_further_in() -> None:
    in_name = ranking.rank("price", ("EuropeTaxedPrice",), ("taxed price in Europe",))
    in_label = ranking.rank("price", ("arbitrage",), ("the purchase of a commodity at a price discrepancy",))
    assert in_name == ranking.CONTAINS and in_label == ranking.IN_LABEL
    assert ranking.rank("position", ("Pos",), ("position",)) == ranking.EXACT  # a label that is the text
    assert ranking.rank("robot pos", ("Thing",), ("robot position",)) == ranking.PREFIX
    assert ranking.rank("zzz", ("Thing",), ("label",)) is None
