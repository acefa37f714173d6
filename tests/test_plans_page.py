"""The plans page shows a plan without recording it, says so, and links only to pages that exist."""

from __future__ import annotations

import re
from collections.abc import Iterator

import pytest
from flask.testing import FlaskClient

from cbrs.actions.composer import Composer, store_plan
from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app


@pytest.fixture
def kb() -> Iterator[KnowledgeBase]:
    opened = KnowledgeBase.open(":memory:")
    yield opened
    opened.close()


@pytest.fixture
def client(kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(kb)).test_client()


def _links(page: str) -> list[str]:
    """The page's links to IRI pages and to the plans page itself (not the menu's other pages)."""
    found = [href.replace("&amp;", "&") for href in re.findall(r'href="(/[^"#]*)"', page)]
    return [link for link in found if link.startswith(("/resource", "/plans"))]


def test_a_shown_plan_is_not_called_recorded_and_every_link_answers(client: FlaskClient) -> None:
    body = client.get("/plans.json", query_string={"task": "FetchMyPen"}).get_json()
    assert body["recorded"] is False
    page = client.get("/plans", query_string={"task": "FetchMyPen"}).text
    assert "Recorded in the plans graph" not in page
    assert "Shown, not recorded: <code>cbrs plan req:FetchMyPen</code>" in page
    broken = [link for link in sorted(set(_links(page))) if client.get(link).status_code == 404]
    assert not broken, f"links to missing pages: {broken}"


def test_a_plan_recorded_before_is_linked(kb: KnowledgeBase, client: FlaskClient) -> None:
    result = Composer(kb).compose("FetchMyPen")
    assert result.plan is not None
    store_plan(kb, result.plan)
    body = client.get("/plans.json", query_string={"task": "FetchMyPen"}).get_json()
    assert body["recorded"] is True
    page = client.get("/plans", query_string={"task": "FetchMyPen"}).text
    link = next(link for link in _links(page) if result.plan.iri in link)
    assert client.get(link).status_code == 200
