"""The taxonomy pages read what they need of the whole store (the taxonomy, the usage counts, the
descriptions' labels) once per store generation, not once per page (on OWLS-TC the taxonomy alone took
about 1.5 s a page), and a write to the store shows on the next page."""

from __future__ import annotations

from pathlib import Path

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app, taxonomy

LAB = "http://example.org/cache-lab#"


@pytest.fixture
def kb(fresh_bundled_kb: KnowledgeBase) -> KnowledgeBase:
    """A store of its own: the tests write to it."""
    return fresh_bundled_kb


@pytest.fixture
def reads(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """One entry per read of the whole taxonomy."""
    counted: list[int] = []
    original = taxonomy.Taxonomy.read.__func__  # type: ignore[attr-defined]

    def counting(cls: type[taxonomy.Taxonomy], kb: KnowledgeBase) -> taxonomy.Taxonomy:
        counted.append(1)
        found: taxonomy.Taxonomy = original(cls, kb)
        return found

    monkeypatch.setattr(taxonomy.Taxonomy, "read", classmethod(counting))
    return counted


def client_of(kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(kb)).test_client()


def test_pages_share_one_read_until_the_store_is_written(kb: KnowledgeBase, reads: list[int]) -> None:
    client = client_of(kb)
    assert client.get("/taxonomy.json").status_code == 200
    assert client.get("/taxonomy/class.json", query_string={"iri": "home:RobotPosition"}).status_code == 200
    assert client.get("/taxonomy.json", query_string={"q": "position"}).status_code == 200
    assert len(reads) == 1
    assert LAB + "Gadget" not in client.get("/taxonomy.json", query_string={"q": "gadget"}).text

    kb.update(
        f"PREFIX owl: <http://www.w3.org/2002/07/owl#> PREFIX rdfs: <http://www.w3.org/2000/01/rdf-schema#>\n"
        f"INSERT DATA {{ GRAPH <https://w3id.org/cbrs/graph/ontology> {{\n"
        f"  <{LAB}Gadget> a owl:Class ; rdfs:subClassOf <https://w3id.org/cbrs/home#Device> }} }}"
    )
    found = client.get("/taxonomy.json", query_string={"q": "gadget"}).get_json()
    assert [m["iri"] for m in found["matches"]] == [LAB + "Gadget"]
    page = client.get("/taxonomy/class.json", query_string={"iri": LAB + "Gadget"})
    assert page.status_code == 200 and page.get_json()["kind"] == "class"
    assert len(reads) == 2


def test_a_store_without_a_generation_is_read_every_time(kb: KnowledgeBase, reads: list[int]) -> None:
    """A remote store counts no writes (another robot may write to it): nothing is kept."""
    client = client_of(kb)
    kb.store.generation = None  # type: ignore[attr-defined]  # as a remote store has none
    for _ in range(2):
        assert client.get("/taxonomy/class.json", query_string={"iri": "home:RobotPosition"}).status_code == 200
    assert len(reads) == 2


AD = f"""@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix home: <https://w3id.org/cbrs/home#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
<{LAB}Tracker> a cbrs:DynamicPerceptionComponent ; rdfs:label "lab tracker" ;
    cbrs:deviceName "Tracker1" ; cbrs:serviceName "TrackRobot" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "where" ; cbrs:parameterType home:RobotPosition ] ] .
"""


def test_a_new_advertisement_shows_in_the_usage_of_its_concepts(kb: KnowledgeBase, tmp_path: Path) -> None:
    client = client_of(kb)
    before = client.get("/taxonomy/class.json", query_string={"iri": "home:RobotPosition"}).get_json()["usage"]
    assert LAB + "Tracker" not in {u["iri"] for u in before["advertisements"]}
    path = tmp_path / "tracker.ttl"
    path.write_text(AD, encoding="utf-8")
    kb.load([path])
    after = client.get("/taxonomy/class.json", query_string={"iri": "home:RobotPosition"}).get_json()["usage"]
    tracker = next(u for u in after["advertisements"] if u["iri"] == LAB + "Tracker")
    assert tracker["label"] == "lab tracker" and tracker["roles"] == ["output"]
    assert after["uses"] == before["uses"] + 1


def test_the_overview_counts_follow_a_write(kb: KnowledgeBase, tmp_path: Path) -> None:
    client = client_of(kb)
    before = client.get("/index.json").get_json()
    assert client.get("/index.json").get_json()["counts"] == before["counts"]
    path = tmp_path / "tracker.ttl"
    path.write_text(AD, encoding="utf-8")
    kb.load([path])
    after = client.get("/index.json").get_json()
    assert after["counts"]["services"] == before["counts"]["services"] + 1
    assert after["counts"]["triples"] > before["counts"]["triples"]
    services = {g["name"]: g["triples"] for g in after["graphs"]}
    assert services["graph:services"] > {g["name"]: g["triples"] for g in before["graphs"]}["graph:services"]
