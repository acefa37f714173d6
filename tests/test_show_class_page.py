"""The browser's class page lists a class's restrictions and other anonymous class expressions (its
parts table shows only the hasPart family's) and the classes whose expressions name it, in Manchester
syntax with the names linked; the JSON twin keeps its keys and adds ``restrictions`` and ``named_in``.
Before, a restriction such as ``home:hasHue some home:Hue`` appeared on no class page at all."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

from .test_show_restrictions import LAB, ONTOLOGY, RED_GRIPPER_ROBOT, ROBOT

KEYS = {"iri", "name", "label", "kind", "comment", "paths", "superclasses", "subclasses", "equivalents"}
KEYS |= {"parts", "part_of", "usage"}


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> Iterator[FlaskClient]:
    path = Path(tmp_path_factory.mktemp("class_page")) / "lab.ttl"
    path.write_text(ONTOLOGY, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    kb.load([path])
    yield create_app(SparqlService(kb)).test_client()
    kb.close()


def test_the_twin_lists_the_restrictions_and_keeps_its_keys(client: FlaskClient) -> None:
    body = client.get("/taxonomy/class.json", query_string={"iri": LAB + "Robot"}).get_json()
    assert set(body) >= KEYS
    assert sorted(r["text"] for r in body["restrictions"]) == sorted(ROBOT)
    assert {r["relation_name"] for r in body["restrictions"]} == {"rdfs:subClassOf"}
    wheels = next(r for r in body["restrictions"] if r["expression"]["type"] == "exactly")
    assert wheels["expression"]["filler"] == {"type": "class", "iri": LAB + "Wheel"}
    gripper = client.get("/taxonomy/class.json", query_string={"iri": LAB + "Gripper"}).get_json()
    assert [(r["iri"], r["relation_name"], r["text"]) for r in gripper["named_in"]] == [
        (LAB + "RedGripperRobot", "owl:equivalentClass", RED_GRIPPER_ROBOT),
        (LAB + "Robot", "rdfs:subClassOf", f"{LAB}hasPart only ({LAB}Arm or {LAB}Wheel or {LAB}Gripper)"),
        (LAB + "Robot", "rdfs:subClassOf", f"{LAB}hasPart some {LAB}Gripper"),
    ]


def test_the_page_links_the_names_and_escapes_the_literals(client: FlaskClient) -> None:
    page = client.get("/taxonomy/class", query_string={"iri": LAB + "Robot"}).text
    assert "Restrictions and other class expressions" in page
    assert "genid" not in page
    text = re.sub(r"<[^>]+>", "", page)
    # a namespace cbrs declares no prefix for gets one from its name (cbrs.web.prefixes), the whole IRI
    # in the link's title
    assert "lab:hasPart exactly 4 lab:Wheel" in text
    assert f'title="{LAB}Wheel"' in page
    assert "&gt;= 1.5, &lt; 80" in page and "&#34;Robbie&#34;@en" in page
    # a class the taxonomy has links to its class page, an individual to its triples
    assert 'href="/taxonomy/class?iri=http://example.org/lab%23Wheel"' in page
    assert 'href="/resource?iri=http://example.org/lab%23Red"' in page


def test_the_bundled_classes_show_theirs(client: FlaskClient) -> None:
    body = client.get("/taxonomy/class.json", query_string={"iri": "home:ColourFeature"}).get_json()
    assert sorted(r["text"] for r in body["restrictions"]) == [
        "home:hasColour some home:Colour",
        "home:hasHue some home:Hue",
    ]
    assert [(r["name"], r["text"]) for r in body["named_in"]] == [
        ("home:ObjectFeature", "home:hasColourFeature some home:ColourFeature")
    ]
    assert body["usage"]["advertisements"]  # what was there before stays


def test_a_class_without_any_shows_no_section(client: FlaskClient) -> None:
    body = client.get("/taxonomy/class.json", query_string={"iri": LAB + "Arm"}).get_json()
    assert body["restrictions"] == []
    page = client.get("/taxonomy/class", query_string={"iri": LAB + "Wheel"}).text
    assert "Restrictions and other class expressions" not in page
    assert "Named in the class expressions of" in page


def test_a_concept_no_ontology_declares_has_a_page_not_a_404() -> None:
    """The service page links every parameter type to its class page; a lab's undeclared (here
    misspelt) class led to a 404. Its page says so, names the declared term it is like, and what uses it."""
    kb = KnowledgeBase.open(":memory:")
    kb.registry.register(
        """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
<http://example.org/lab#DoorCam> a cbrs:DynamicPerceptionComponent ; cbrs:deviceName "DoorCam01" ;
    cbrs:serviceName "DetectDoorState" ;
    cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType home:Door ] ;
                        cbrs:hasOutput [ cbrs:parameterType <http://example.org/lab#DoorStatte> ] ] ."""
    )
    client = create_app(SparqlService(kb)).test_client()
    service = client.get("/service", query_string={"iri": "http://example.org/lab#DoorCam"}).text
    links = {h.replace("&amp;", "&") for h in re.findall(r'href="(/taxonomy/class[^"#]*)"', service)}
    assert links and all(client.get(link).status_code == 200 for link in links)
    body = client.get("/taxonomy/class.json", query_string={"iri": LAB + "DoorStatte"}).get_json()
    assert set(body) >= KEYS and body["kind"] == "undeclared"
    assert [t["name"] for t in body["similar"]] == ["home:DoorStatus"]
    assert [(a["iri"], a["roles"]) for a in body["usage"]["advertisements"]] == [(LAB + "DoorCam", ["output"])]
    page = client.get("/taxonomy/class", query_string={"iri": LAB + "DoorStatte"}).text
    assert "No ontology in the store declares" in page
    assert '<svg class="diagram"' not in page  # nothing to draw: no ontology places it
    # an IRI nothing uses as a concept is still not found
    assert client.get("/taxonomy/class.json", query_string={"iri": LAB + "Nothing"}).status_code == 404
    assert client.get("/taxonomy/class.json", query_string={"iri": "svc:CeilingCamera01"}).status_code == 404
    kb.close()


def test_rdf_type_as_a_statement_s_predicate_is_a_built_in_term() -> None:
    kb = KnowledgeBase.open(":memory:")
    owls = Path(__file__).parent / "data" / "owls"
    kb.load([owls / "services" / "navigate.owls"], catalogue=owls / "catalog-v001.xml")
    client = create_app(SparqlService(kb)).test_client()
    body = client.get("/taxonomy/class.json", query_string={"iri": "rdf:type"}).get_json()
    assert body["kind"] == "built-in" and body["similar"] == []
    assert "which every store knows" in client.get("/taxonomy/class", query_string={"iri": "rdf:type"}).text
    kb.close()
