"""A plan's components and alternatives open their service page (the six-tuple), as the services list and
the rankings do; they opened the page of their raw triples. Every link of the plan table resolves."""

from __future__ import annotations

import re
from html import unescape

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import expand
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


@pytest.mark.parametrize("task", ["req:FetchMyPen", "act:RobotArmServeACup"])
def test_each_step_links_its_service_page(client: FlaskClient, task: str) -> None:
    body = client.get("/plans.json", query_string={"task": task}).get_json()["composition"]
    page = client.get("/plans", query_string={"task": task}).get_data(as_text=True)
    table = page[page.index('<table class="plan">') : page.index("</table>", page.index('<table class="plan">'))]
    services = {unescape(href) for href in re.findall(r'href="(/service\?iri=[^"]+)"', table)}
    for step in body["steps"]:
        for component in [step["component"], *step["alternatives"]]:
            assert any(link.replace("%23", "#").endswith(component) for link in services), component
    for link in services:
        assert client.get(link).status_code == 200, link
    badge = page.index('<span class="badge good">planned</span>')
    heading = page[page.rindex("<h2>", 0, badge) : badge]
    target = "/service?iri=" if task.startswith("req:") else "/resource?iri="  # an action has no six-tuple
    assert target in heading and expand(task).split("#")[1] in heading
