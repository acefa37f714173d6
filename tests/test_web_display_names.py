"""IRIs that no declared prefix shortens (all of OWLS-TC's) show a prefix derived for their namespace on
the pages (``my_ontology1:Car``, cbrs.web.prefixes), the whole IRI in the link's title, instead of
``http://127.0.0.1/ontology/...`` in every cell; one that no prefix shortens at all shows its tail, the
file part muted."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from flask.testing import FlaskClient
from markupsafe import Markup

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app
from cbrs.web.links import display_name

ONTO = "http://127.0.0.1/ontology/my_ontology.owl#"
OTHER = "http://example.com/copy/my_ontology.owl#"  # the same tail as ONTO's
SERVICE = "http://127.0.0.1/services/1.1/car_price_service.owls#CAR_PRICE_SERVICE"
TURTLE = f"""@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
<{ONTO}Car> a owl:Class .
<{ONTO}FourWheeledCar> a owl:Class ; rdfs:subClassOf <{ONTO}Car> .
<{OTHER}Car> a owl:Class .
"""
AD = f"""@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
<{SERVICE}> a cbrs:MethodInvocationComponent ; rdfs:label "car price" ;
    cbrs:deviceName "car_price_service" ; cbrs:serviceName "CarPrice" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "_CAR" ; cbrs:parameterType <{ONTO}FourWheeledCar> ] ] .
"""


@pytest.mark.parametrize(
    ("iri", "label", "shown"),
    [
        ("https://w3id.org/cbrs/home#Position", None, "home:Position"),
        (ONTO + "Car", None, '<span class="ns">my_ontology.owl#</span>Car'),
        (ONTO + "Car", ONTO + "Car", '<span class="ns">my_ontology.owl#</span>Car'),  # the "short" name passed on
        (ONTO + "Car", "a car", "a car"),
        ("http://example.org/things/Widget", None, "Widget"),
        ("http://example.org/", None, "http://example.org/"),
        ("urn:x-lab:thing", None, "urn:x-lab:thing"),
        ("http://example.org/a#<b>", None, '<span class="ns">a#</span>&lt;b&gt;'),
    ],
)
def test_display_name(iri: str, label: str | None, shown: str) -> None:
    assert display_name(iri, label) == Markup(shown)


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> FlaskClient:
    folder = Path(tmp_path_factory.mktemp("display"))
    (folder / "onto.ttl").write_text(TURTLE, encoding="utf-8")
    (folder / "ad.ttl").write_text(AD, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    kb.load([folder / "onto.ttl"])
    kb.load([folder / "ad.ttl"])
    return create_app(SparqlService(kb)).test_client()


def test_pages_show_the_derived_name_and_keep_the_whole_iri_in_the_title(client: FlaskClient) -> None:
    car = f'title="{ONTO}FourWheeledCar">my_ontology1:FourWheeledCar</a>'
    for path, query in (
        ("/services", {}),
        ("/service", {"iri": SERVICE}),
        ("/taxonomy", {}),
        ("/taxonomy/class", {"iri": ONTO + "Car"}),
        ("/search", {"q": "wheeled"}),
    ):
        response = client.get(path, query_string=query)
        assert response.status_code == 200, path
        assert car in response.text, path
        shown = re.sub(r"<svg.*?</svg>", "", response.text, flags=re.S)  # a picture's tooltips are whole
        assert f">{ONTO}FourWheeledCar<" not in shown, path
    twin = client.get("/services.json").get_json()
    ad = next(a for a in twin["advertisements"] if a["service"] == SERVICE)
    assert ad["inputs"] == [ONTO + "FourWheeledCar"]  # the twins keep whole IRIs


def test_the_uses_of_a_class_and_the_paths_to_it_show_derived_names_too(client: FlaskClient) -> None:
    page = client.get("/taxonomy/class", query_string={"iri": ONTO + "FourWheeledCar"}).text
    assert ">car_price_service:CAR_PRICE_SERVICE</a>" in page
    assert "<strong>my_ontology1:FourWheeledCar</strong>" in page
    services = client.get("/services").text
    assert services.count(">car price<") == 1  # the label, beside the service name it differs from


def test_page_titles_name_the_iri_by_its_derived_name(client: FlaskClient) -> None:
    for path, query, title in (
        ("/taxonomy/class", {"iri": ONTO + "Car"}, "Class my_ontology1:Car"),
        ("/service", {"iri": SERVICE}, "car_price_service:CAR_PRICE_SERVICE"),
        ("/resource", {"iri": ONTO + "Car"}, "my_ontology1:Car"),
        ("/resource", {"iri": OTHER + "Car"}, "my_ontology2:Car"),  # the same tail: another prefix
        ("/taxonomy", {"root": ONTO + "Car"}, "Taxonomy below my_ontology1:Car"),
    ):
        page = client.get(path, query_string=query).text
        assert f"<title>{title} · cbrs</title>" in page and f"<h1>{title}</h1>" in page, path


def test_the_match_form_takes_a_concept_as_the_pages_name_it(client: FlaskClient) -> None:
    asked = client.get("/match.json", query_string={"inputs": "my_ontology.owl#FourWheeledCar", "outputs": "car"})
    assert asked.status_code == 400 and "outputs" in asked.get_json()["fields"]  # "car" is no concept
    ranked = client.get("/match.json", query_string={"effects": "", "outputs": "my_ontology.owl#FourWheeledCar"})
    assert ranked.status_code == 200, ranked.text[:300]
    assert ranked.get_json()["requirement"]["outputs"] == [ONTO + "FourWheeledCar"]
    same = client.get("/match.json", query_string={"outputs": "my_ontology.owl#Car"}).get_json()
    assert "2 concepts" in same["fields"]["outputs"] and OTHER + "Car" in same["fields"]["outputs"]
    typo = client.get("/match.json", query_string={"outputs": "my_ontology.owl#FourWheeledCra"}).get_json()
    assert "did you mean my_ontology.owl#FourWheeledCar" in typo["fields"]["outputs"]
    named = client.get("/match.json", query_string={"outputs": "my_ontology1:FourWheeledCar"})  # as pages show it
    assert named.status_code == 200 and named.get_json()["requirement"]["outputs"] == [ONTO + "FourWheeledCar"]
    typo = client.get("/match.json", query_string={"outputs": "my_ontology1:FourWheeledCra"}).get_json()
    assert "did you mean my_ontology1:FourWheeledCar" in typo["fields"]["outputs"]
