"""Every table header a page shows has a name for a screen reader: the requirements table's last column
(the "match" links) had an empty header."""

from __future__ import annotations

import re

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

PAGES = [
    "/",
    "/services",
    "/service?iri=svc:LocateMobileRobot_CeilingCamera01",
    "/service?iri=req:FetchMyPen",
    "/taxonomy/class?iri=home:RobotLocation",
    "/match?requirement=req:RobotSelfPosition",
    "/plans?task=FetchMyPen",
    "/tasks",
    "/resource?iri=rdf:type",
    "/query?query=SELECT+*+WHERE+{+?s+?p+?o+}+LIMIT+3",
]


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


@pytest.mark.parametrize("path", PAGES)
def test_no_table_header_is_empty(client: FlaskClient, path: str) -> None:
    page = client.get(path).get_data(as_text=True)
    headers = re.findall(r"<th\b[^>]*>(.*?)</th>", page, re.DOTALL)
    assert headers, path
    empty = [h for h in headers if not re.sub(r"<[^>]+>", "", h).strip()]
    assert empty == [], path
