"""From a service to the requirements it meets: an advertisement's page lists the stored requirements whose
ranking accepts it, where it ranks there, and links each ranking. Before, the page offered only a list of
every requirement to rank the advertisements for, and said nothing of which it meets."""

from __future__ import annotations

import re
from html import unescape
from typing import Any

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


def _service(client: FlaskClient, iri: str) -> dict[str, Any]:
    response = client.get("/service.json", query_string={"iri": iri})
    assert response.status_code == 200
    body: dict[str, Any] = response.get_json()
    return body


def _ranking(client: FlaskClient, requirement: str) -> list[dict[str, Any]]:
    body = client.get("/match.json", query_string={"requirement": requirement, "top": 50}).get_json()
    candidates: list[dict[str, Any]] = body["rankings"][0]["candidates"]
    return candidates


def test_the_ceiling_camera_meets_robot_self_position_first(client: FlaskClient) -> None:
    meets = _service(client, CAMERA)["meets"]
    first = next(m for m in meets if m["name"] == "req:RobotSelfPosition")
    assert first["rank"] == 1 and first["first"] == expand(CAMERA) and first["of"] == 53


def test_each_entry_is_where_the_matchmaking_page_ranks_the_service(client: FlaskClient) -> None:
    """Checked for every advertisement that meets some requirement: rank, score and acceptance agree with
    the ranking the matchmaking page shows, and no accepting ranking is left out."""
    ads = [row["service"] for row in client.get("/services.json").get_json()["advertisements"]]
    rankings = {r["requirement"]: _ranking(client, r["requirement"]) for r in _requirements(client)}
    listed = 0
    for ad in ads:
        meets = {m["requirement"]: m for m in _service(client, ad)["meets"]}
        for requirement, ranking in rankings.items():
            place = next((c for c in ranking if c["advertisement"] == ad), None)
            accepted = place is not None and place["acceptable"]
            assert (requirement in meets) is accepted, (ad, requirement)
            if place is not None and accepted:
                assert meets[requirement]["rank"] == place["rank"]
                assert meets[requirement]["score"] == pytest.approx(place["score"], abs=1e-3)
                listed += 1
        assert [m["rank"] for m in meets.values()] == sorted(m["rank"] for m in meets.values())
    assert listed >= len(rankings)  # every stored requirement's ranking accepts some service


def _requirements(client: FlaskClient) -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = client.get("/services.json").get_json()["requirements"]
    return rows


def test_the_page_links_each_requirement_and_its_ranking(client: FlaskClient) -> None:
    page = client.get("/service", query_string={"iri": CAMERA}).get_data(as_text=True)
    section = page[page.index('id="meets-heading"') : page.index("</table>", page.index('id="meets"'))]
    links = [unescape(href) for href in re.findall(r'href="([^"]+)"', section)]
    assert f"/match?requirement={expand('req:RobotSelfPosition')}" in [link.replace("%23", "#") for link in links]
    for link in links:
        assert client.get(link).status_code == 200, link


def test_a_service_no_ranking_accepts_says_so(client: FlaskClient) -> None:
    ads = [row["service"] for row in client.get("/services.json").get_json()["advertisements"]]
    lonely = next(ad for ad in ads if not _service(client, ad)["meets"])
    page = client.get("/service", query_string={"iri": lonely}).get_data(as_text=True)
    assert "No stored requirement's ranking (Sem-Str) accepts this service." in page
    assert 'id="meets"' not in page


def test_a_requirement_page_has_no_such_section(client: FlaskClient) -> None:
    assert "meets" not in _service(client, "req:RobotSelfPosition")
    page = client.get("/service", query_string={"iri": "req:RobotSelfPosition"}).get_data(as_text=True)
    assert "meets-heading" not in page


def test_a_requirement_taken_away_leaves_the_list_at_the_next_page() -> None:
    kb = KnowledgeBase.open(":memory:")
    client = create_app(SparqlService(kb)).test_client()
    assert "req:RobotSelfPosition" in [m["name"] for m in _service(client, CAMERA)["meets"]]
    kb.registry.deregister(expand("req:RobotSelfPosition"))
    assert "req:RobotSelfPosition" not in [m["name"] for m in _service(client, CAMERA)["meets"]]


def test_on_a_big_store_the_page_offers_the_list_until_the_rankings_are_read() -> None:
    """Past CBRS_MEETS_INLINE advertisements a service page does not wait for the matchmaker (on OWLS-TC
    the first service page took 7 to 12 s); it links the list, and shows it once the rankings are read."""
    kb = KnowledgeBase.open(":memory:")
    app = create_app(SparqlService(kb))
    app.config["CBRS_MEETS_INLINE"] = 10  # the bundled store has 53
    client = app.test_client()
    offered = _service(client, CAMERA)
    assert offered["meets"] is None and offered["meets_url"].endswith("meets=all#meets-heading")
    page = client.get("/service", query_string={"iri": CAMERA}).get_data(as_text=True)
    assert "List the requirements it meets" in page and 'id="meets"' not in page
    asked = client.get(offered["meets_url"].replace("/service", "/service.json", 1)).get_json()
    assert "req:RobotSelfPosition" in [m["name"] for m in asked["meets"]]
    other = _service(client, "svc:LocateMobileRobot_CeilingCamera02")  # read now: shown at once
    assert other["meets"] is not None and other["meets_url"] is None
    kb.registry.deregister(expand("svc:DeadReckoning_P3DX01"))  # a write: the rankings are stale
    assert _service(client, CAMERA)["meets"] is None
