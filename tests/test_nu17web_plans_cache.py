"""The plans page plans with composers kept between requests (as the bridge's /cbrs/plan does), sharing the
matchmakers' taxonomy index, and reads its list of tasks once per store generation. A new composer per
request rebuilt the taxonomy index and re-read every requirement: on OWLS-TC a plans page took 7 to 11 s,
of which the composition was 1.4 s."""

from __future__ import annotations

from typing import Any

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import expand
from cbrs.reasoner.taxonomy import TaxonomyIndex
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

CAMERA_1 = expand("svc:LocateMobileRobot_CeilingCamera01")
CAMERA_2 = expand("svc:LocateMobileRobot_CeilingCamera02")


def _components(client: FlaskClient) -> list[str]:
    response = client.get("/plans.json", query_string={"task": "FetchMyPen"})
    assert response.status_code == 200, response.get_data(as_text=True)
    return [step["component"] for step in response.get_json()["composition"]["steps"]]


def test_two_plans_pages_build_the_taxonomy_index_once(
    bundled_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    built: list[int] = []
    original = TaxonomyIndex.from_kb

    def counted(kb: KnowledgeBase, *args: Any, **kwargs: Any) -> TaxonomyIndex:
        built.append(1)
        return original(kb, *args, **kwargs)

    monkeypatch.setattr(TaxonomyIndex, "from_kb", staticmethod(counted))
    client = create_app(SparqlService(bundled_kb)).test_client()
    first = _components(client)
    assert _components(client) == first and len(first) == 15
    client.get("/match.json", query_string={"requirement": "req:RobotSelfPosition"})  # the same index
    assert len(built) == 1


def test_a_component_taken_away_leaves_the_next_plan() -> None:
    """Made stale as the bridge's composers are: a write through the SPARQL service, or a change it is told
    of (a live component leaving)."""
    kb = KnowledgeBase.open(":memory:")
    sparql = SparqlService(kb)
    client = create_app(sparql).test_client()
    assert CAMERA_1 in _components(client)
    with sparql.lock:
        kb.registry.deregister(CAMERA_1)
        sparql.changed()
    again = _components(client)
    assert CAMERA_1 not in again and CAMERA_2 in again


def test_the_task_list_follows_a_write() -> None:
    kb = KnowledgeBase.open(":memory:")
    client = create_app(SparqlService(kb)).test_client()
    names = [t["name"] for t in client.get("/plans.json").get_json()["tasks"]["requirements"]]
    assert "req:RobotSelfPosition" in names
    kb.registry.deregister(expand("req:RobotSelfPosition"))
    names = [t["name"] for t in client.get("/plans.json").get_json()["tasks"]["requirements"]]
    assert "req:RobotSelfPosition" not in names
