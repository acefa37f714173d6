"""Keyboard basics of every page: a first link that skips the navigation to the content, the script of
the ``/`` shortcut served from this server (no CDN), and no request for a favicon that is not there
(Chromium logged a 404 on every first page)."""

from __future__ import annotations

import re

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

PAGES = ("/", "/taxonomy", "/services", "/query", "/match", "/plans", "/search?q=camera", "/no-such-page")


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


@pytest.mark.parametrize("path", PAGES)
def test_the_first_link_skips_to_the_main_content(client: FlaskClient, path: str) -> None:
    page = client.get(path, headers={"Accept": "text/html"}).text
    body = page.split("<body>", 1)[1]
    first = re.search(r"<a [^>]*>", body)
    assert first is not None and 'href="#content"' in first.group(0), path
    assert '<main id="content" tabindex="-1">' in page
    assert '<link rel="icon" href="data:,">' in page


def test_every_script_and_stylesheet_comes_from_this_server(client: FlaskClient) -> None:
    for path in PAGES:
        page = client.get(path, headers={"Accept": "text/html"}).text
        sources = re.findall(r'<(?:script|link)[^>]+(?:src|href)="([^"]+)"', page)
        for source in sources:
            if source.startswith("data:"):
                continue
            assert source.startswith("/static/"), (path, source)
            served = client.get(source)
            assert served.status_code == 200, source
            served.close()
    script = client.get("/static/site.js")
    assert script.mimetype in ("text/javascript", "application/javascript") and b'"/"' in script.data


REFERENCES = re.compile(r'(?:for|aria-describedby|aria-labelledby)="([^"]+)"')
LABELLED_PAGES = (
    *PAGES[:-1],
    "/taxonomy?root=home:Position",
    "/taxonomy/class?iri=home:Position",
    "/resource?iri=home:Position",
    "/service?iri=svc:LocateMobileRobot_CeilingCamera01",
    "/match?requirement=req:FetchMyPen",
    "/plans?task=FetchMyPen",
    "/services?kind=cbrs:Toaster",
    "/services?page=9",
)


@pytest.mark.parametrize("path", LABELLED_PAGES)
def test_ids_are_unique_and_every_reference_and_field_label_resolves(client: FlaskClient, path: str) -> None:
    page = client.get(path).text
    ids = re.findall(r'\sid="([^"]+)"', page)
    assert len(ids) == len(set(ids)), path
    missing = [name for found in REFERENCES.findall(page) for name in found.split() if name not in ids]
    assert missing == [], (path, missing)  # a description that is not there (the services' kind-error was)
    anchors = [name for name in re.findall(r'href="#([^"]+)"', page) if name not in ids]
    assert anchors == [], (path, anchors)
    for field in re.findall(r"<(?:input|select|textarea)\b[^>]*>", page):
        if 'type="hidden"' in field or "aria-label=" in field:
            continue
        named = re.search(r'\sid="([^"]+)"', field)
        assert named is not None and f'for="{named.group(1)}"' in page, (path, field)
