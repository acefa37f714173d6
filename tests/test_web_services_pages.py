"""The services table in pages of ``CBRS_SERVICES_ROWS`` advertisements (``?page=``): OWLS-TC's 1,136
rows made one page of 1.3 MB. The pages together hold every advertisement once, in the same order."""

from __future__ import annotations

import re
from html import unescape

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

ROWS = 10


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    app = create_app(SparqlService(bundled_kb))
    app.config["CBRS_SERVICES_ROWS"] = ROWS
    return app.test_client()


@pytest.fixture(scope="module")
def whole(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def test_the_pages_hold_every_advertisement_once_in_order(client: FlaskClient, whole: FlaskClient) -> None:
    every = [row["service"] for row in whole.get("/services.json").get_json()["advertisements"]]
    first = client.get("/services.json").get_json()
    assert first["page"] == 1 and first["pages"] == -(-len(every) // ROWS) > 1 and first["count"] == len(every)
    seen = []
    for number in range(1, first["pages"] + 1):
        body = client.get("/services.json", query_string={"page": str(number)}).get_json()
        assert body["page"] == number and body["first"] == (number - 1) * ROWS + 1
        assert len(body["advertisements"]) <= ROWS
        seen += [row["service"] for row in body["advertisements"]]
    assert seen == every


def test_the_pager_links_walk_the_pages(client: FlaskClient) -> None:
    pages = client.get("/services.json").get_json()["pages"]
    url, visited = "/services", []
    for _ in range(pages + 1):  # bounded: one more than there are pages
        page = client.get(url)
        assert page.status_code == 200, url
        visited.append(url)
        following = re.search(r'<a href="([^"]+)" rel="next">', page.text)
        if following is None:
            break
        url = unescape(following.group(1))
    assert len(visited) == pages
    assert f"page {pages} of {pages}" in client.get(visited[-1]).text
    assert 'rel="prev"' in client.get(visited[-1]).text and 'rel="prev"' not in client.get("/services").text


def test_a_kind_is_paged_on_its_own(client: FlaskClient, whole: FlaskClient) -> None:
    kind = "cbrs:DynamicPerceptionComponent"
    every = whole.get("/services.json", query_string={"kind": kind}).get_json()["advertisements"]
    body = client.get("/services.json", query_string={"kind": kind}).get_json()
    assert body["count"] == len(every) and body["pages"] == -(-len(every) // ROWS)
    if body["pages"] > 1:
        page = client.get("/services", query_string={"kind": kind}).text
        assert "kind=cbrs:DynamicPerceptionComponent&amp;page=2" in page


@pytest.mark.parametrize("given", ["0", "-1", "x", "999"])
def test_a_page_out_of_range_is_a_field_error(client: FlaskClient, given: str) -> None:
    error = client.get("/services.json", query_string={"page": given})
    assert error.status_code == 400 and "page" in error.get_json()["fields"]
    page = client.get("/services", query_string={"page": given})
    assert page.status_code == 400 and 'id="page-error"' in page.text


def test_the_bundled_store_fits_one_page_by_default(whole: FlaskClient) -> None:
    body = whole.get("/services.json").get_json()
    assert body["pages"] == 1 and len(body["advertisements"]) == body["total"] == 53
    assert 'class="pager"' not in whole.get("/services").text
