"""The plans page and its drawing share one composition per task, store generation and composer: each
composed afresh (0.7 s a page, 1.4 to 3 s a drawing on OWLS-TC)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from flask.testing import FlaskClient

from cbrs.actions.composer import Composer
from cbrs.kb import KnowledgeBase
from cbrs.kb.liveness import Liveness
from cbrs.kb.namespaces import expand
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app, plans

TASK = {"task": "FetchMyPen"}


@pytest.fixture
def counted(monkeypatch: pytest.MonkeyPatch) -> dict[str, list[str]]:
    """The tasks composed and the drawings made, the drawing a stub (the real one is tested elsewhere)."""
    calls: dict[str, list[str]] = {"compose": [], "draw": []}
    original = Composer.compose

    def compose(self: Composer, task: str, *args: Any, **kwargs: Any) -> Any:
        calls["compose"].append(task)
        return original(self, task, *args, **kwargs)

    def draw(result: Any) -> bytes:
        calls["draw"].append(result.task)
        return b"<svg xmlns='http://www.w3.org/2000/svg'/>"

    monkeypatch.setattr(Composer, "compose", compose)
    monkeypatch.setattr(plans, "_svg", draw)
    return calls


@pytest.fixture
def kb() -> Iterator[KnowledgeBase]:
    opened = KnowledgeBase.open(":memory:")
    yield opened
    opened.close()


def _steps(client: FlaskClient, objective: str | None = None) -> list[str]:
    args = {**TASK, **({"objective": objective} if objective else {})}
    response = client.get("/plans.json", query_string=args)
    assert response.status_code == 200, response.get_data(as_text=True)
    return [step["component"] for step in response.get_json()["composition"]["steps"]]


def _drawing(client: FlaskClient) -> bytes:
    response = client.get("/plans/graph.svg", query_string=TASK)
    assert response.status_code == 200 and response.mimetype == "image/svg+xml"
    return response.data


def test_a_page_and_its_drawing_compose_once(kb: KnowledgeBase, counted: dict[str, list[str]]) -> None:
    client = create_app(SparqlService(kb)).test_client()
    first = _steps(client)
    assert _drawing(client) == _drawing(client)
    assert _steps(client) == first
    assert client.get("/plans", query_string=TASK).status_code == 200
    assert counted == {"compose": [expand("req:FetchMyPen")], "draw": [expand("req:FetchMyPen")]}
    _steps(client, "cost")  # another objective is another composition
    assert len(counted["compose"]) == 2


def test_a_write_composes_again(kb: KnowledgeBase, counted: dict[str, list[str]]) -> None:
    sparql = SparqlService(kb)
    client = create_app(sparql).test_client()
    camera = expand("svc:LocateMobileRobot_CeilingCamera01")
    assert camera in _steps(client)
    with sparql.lock:  # as a component leaving through the bridge does
        kb.registry.deregister(camera)
        sparql.changed()
    assert camera not in _steps(client)
    _drawing(client)
    assert len(counted["compose"]) == 2 and len(counted["draw"]) == 1


def test_a_lapsed_lease_composes_again(
    kb: KnowledgeBase, counted: dict[str, list[str]], monkeypatch: pytest.MonkeyPatch
) -> None:
    # a lease that lapses is no write: the store's generation stays, the composers are made again
    client = create_app(SparqlService(kb)).test_client()
    camera = expand("svc:LocateMobileRobot_CeilingCamera01")
    assert camera in _steps(client)
    monkeypatch.setattr(Liveness, "unavailable", lambda self: {camera})
    assert camera not in _steps(client)
    assert len(counted["compose"]) == 2
