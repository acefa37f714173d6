"""A service page shows the OWL-S conditions the loader kept as text only (it could make no statement of
them): the page said "No preconditions." of a service that has one. Matching does not use them, and the
page says so; the twin lists them as ``conditions_as_text``."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

OWLS = Path(__file__).parent / "data" / "owls"
NAVIGATE = "http://example.org/services/navigate.owls#NavigateService"


@pytest.fixture(scope="module")
def client() -> Iterator[FlaskClient]:
    kb = KnowledgeBase.open(":memory:")
    kb.load([OWLS / "services" / "navigate.owls"], catalogue=OWLS / "catalog-v001.xml")
    yield create_app(SparqlService(kb)).test_client()
    kb.close()


def test_a_condition_kept_as_text_is_listed_beside_the_statements(client: FlaskClient) -> None:
    body = client.get("/service.json", query_string={"iri": NAVIGATE}).get_json()
    assert body["conditions_as_text"] == [{"role": "precondition", "text": "(not (robots:isBusy ?Robot))"}]
    assert len(body["preconditions"]) == 1  # the statement made of the other atom stays as it was
    page = client.get("/service", query_string={"iri": NAVIGATE}).text
    row = re.search(r'<th scope="row">P .*?</tr>', page, re.S)
    assert row is not None
    assert "<code>(not (robots:isBusy ?Robot))</code>" in row.group(0) and "text only" in row.group(0)
    assert "No preconditions." not in row.group(0)


def test_a_service_without_such_conditions_lists_none(client: FlaskClient) -> None:
    body = client.get("/service.json", query_string={"iri": "svc:LocateMobileRobot_CeilingCamera01"}).get_json()
    assert body["conditions_as_text"] == []
    page = client.get("/service", query_string={"iri": "svc:ProvideGridMap_HomeServer01"}).text
    assert "No preconditions." in page and "text only" not in page
