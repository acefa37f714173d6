"""OWL-S 1.1 import: conversion to the cbrs six-tuple, the offline catalogue, the load command."""

from __future__ import annotations

import socket
import urllib.request
from pathlib import Path
from typing import Any

import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import Advertisement, CatalogueError, GraphName, KnowledgeBase, RdfParseError, Requirement, Store
from cbrs.kb.catalog import Catalogue
from cbrs.kb.loader import expand_paths, parse_file
from cbrs.kb.namespaces import RDF, RDFS
from cbrs.kb.owls import Vocabulary, convert, requirement_iri
from cbrs.kb.resources import ontology_dir
from cbrs.kb.vocab import CBRS

OWLS = Path(__file__).parent / "data" / "owls"
ONTOLOGY = OWLS / "ontology"
NAVIGATE = OWLS / "services" / "navigate.owls"
OPEN_DOOR = OWLS / "services" / "open_door.owls"
ROBOTS = "http://example.org/ontology/robots.owl#"
PLACES = "http://example.org/ontology/places.owl#"
NAVIGATE_SERVICE = "http://example.org/services/navigate.owls#NavigateService"
OPEN_DOOR_SERVICE = "http://example.org/services/open_door.owls#OpenDoorService"

TC = Path(__file__).resolve().parents[2] / "shared" / "owls-tc4"
needs_tc = pytest.mark.skipif(not TC.is_dir(), reason=f"the OWLS-TC 4 collection is not at {TC}")
TC_PREFIX = "http://127.0.0.1/ontology/"

pytestmark = pytest.mark.both_stores


def _kb(location: str = ":memory:") -> KnowledgeBase:
    """The core ontology alone: the descriptions read back need nothing else."""
    kb = KnowledgeBase(Store.open(location))
    kb.load([ontology_dir() / "core.ttl"], graph="ontology")
    return kb


@pytest.fixture
def kb(store_location: str) -> KnowledgeBase:
    return _kb(store_location)


def _objects(kb: KnowledgeBase, subject: str, predicate: str) -> list[str]:
    return sorted(q.object.value for q in kb.store.quads(ox.NamedNode(subject), ox.NamedNode(predicate)))


def _condition_nodes(kb: KnowledgeBase, kind: str) -> dict[str, list[str]]:
    """Condition node -> its texts, for every node of ``kind`` (cbrs:Precondition or cbrs:Effect)."""
    rows = kb.query(f"SELECT ?c ?text WHERE {{ ?c a <{kind}> ; cbrs:conditionText ?text }}")
    assert isinstance(rows, ox.QuerySolutions)
    found: dict[str, list[str]] = {}
    for row in rows:
        found.setdefault(row["c"].value, []).append(row["text"].value)
    return found


# -- conversion ------------------------------------------------------------------------------------


def test_profile_gives_name_description_category_device_and_parameters(kb: KnowledgeBase) -> None:
    report = kb.load([NAVIGATE], catalogue=ONTOLOGY)
    ad = kb.description(NAVIGATE_SERVICE)
    assert isinstance(ad, Advertisement)
    assert ad.kind == CBRS.MethodInvocationComponent  # "Navigation" names no component kind
    assert ad.service_name == ad.label == "Navigate to room"
    assert ad.comment == "Drives a mobile robot to a room and reports where it stopped."
    assert ad.category == "Navigation"
    assert ad.device_name == "P3DX01"  # the contact's actor:name
    inputs = {p.name: p.type for p in ad.inputs}
    assert inputs == {"Robot": ROBOTS + "MobileRobot", "goalRoom": PLACES + "Kitchen"}  # empty label -> local name
    assert [(p.name, p.type) for p in ad.outputs] == [("StopPosition", ROBOTS + "Position")]  # type given as an IRI
    summary = report.files[0].owls
    assert summary is not None
    assert [(s.inputs, s.outputs, s.preconditions, s.effects, s.text_only) for s in summary.services] == [
        (2, 1, 1, 1, 1)
    ]


def test_pddl_atoms_become_statements_over_parameter_types(kb: KnowledgeBase) -> None:
    kb.load([NAVIGATE], catalogue=ONTOLOGY)
    ad = kb.description(NAVIGATE_SERVICE)
    # (isLocatedIn ?Robot ?Goal) with full IRIs: each variable stands for its parameter's type
    assert [(s.subject, s.predicate, s.object) for s in ad.effects] == [
        (ROBOTS + "MobileRobot", ROBOTS + "isLocatedIn", PLACES + "Kitchen")
    ]
    # (robots:Charged ?Robot): a prefixed class atom says the parameter's type is of that class
    assert [(s.subject, s.predicate, s.object) for s in ad.preconditions] == [
        (ROBOTS + "MobileRobot", RDF + "type", ROBOTS + "Charged")
    ]
    effects = _condition_nodes(kb, CBRS.Effect)
    assert [texts[0].split() for texts in effects.values()] == [
        [
            "(http://example.org/ontology/robots.owl#isLocatedIn",
            "?http://example.org/services/navigate.owls#Robot",
            "?http://example.org/services/navigate.owls#Goal)",
        ]
    ]


def test_swrl_atoms_become_statements(kb: KnowledgeBase) -> None:
    kb.load([OPEN_DOOR], catalogue=ONTOLOGY)
    ad = kb.description(OPEN_DOOR_SERVICE)
    assert isinstance(ad, Advertisement)
    # an IndividualPropertyAtom in an RDF atom list; argument2 is a process:Local
    assert [(s.subject, s.predicate, s.object) for s in ad.preconditions] == [
        (ROBOTS + "Door", ROBOTS + "isLocatedIn", PLACES + "Room")
    ]
    # a ClassAtom inside an rdf:parseType="Literal" expression body
    assert [(s.subject, s.predicate, s.object) for s in ad.effects] == [
        (ROBOTS + "Door", RDF + "type", ROBOTS + "Open")
    ]
    assert ad.kind == CBRS.PhysicalManipulationComponent  # from the category "Physical manipulation"
    assert ad.device_name == "open_door"  # no contact: the file's stem
    [effect_text] = next(iter(_condition_nodes(kb, CBRS.Effect).values()))
    assert effect_text.startswith("<swrl:AtomList") and "swrl:ClassAtom" in effect_text


def test_an_expression_that_makes_no_statement_is_kept_as_text(kb: KnowledgeBase) -> None:
    kb.load([NAVIGATE], catalogue=ONTOLOGY)
    preconditions = _condition_nodes(kb, CBRS.Precondition)
    assert sorted(texts[0] for texts in preconditions.values()) == [
        "(not (robots:isBusy ?Robot))",
        "(robots:Charged ?Robot)",
    ]
    text_only = next(node for node, texts in preconditions.items() if texts[0].startswith("(not"))
    assert not _objects(kb, text_only, CBRS.conditionSubject)
    # hung off the OWLS model with rdfs:seeAlso, not cbrs:hasPrecondition, so readers see no half statement
    [model] = _objects(kb, NAVIGATE_SERVICE, CBRS.hasOWLSModel)
    assert _objects(kb, model, RDFS + "seeAlso") == [text_only]
    assert len(kb.description(NAVIGATE_SERVICE).preconditions) == 1


def test_pddl_that_does_not_parse_or_is_conditional_stays_text() -> None:
    text = """@prefix service: <http://www.daml.org/services/owl-s/1.1/Service.owl#> .
@prefix profile: <http://www.daml.org/services/owl-s/1.1/Profile.owl#> .
@prefix process: <http://www.daml.org/services/owl-s/1.1/Process.owl#> .
@prefix expr: <http://www.daml.org/services/owl-s/1.1/generic/Expression.owl#> .
@prefix ex: <http://example.org/x#> .
ex:S a service:Service ; service:presents ex:P ; service:describedBy ex:Q .
ex:P a profile:Profile ; profile:hasInput ex:A .
ex:A a process:Input ; process:parameterType "http://example.org/o#Thing" .
ex:Q a process:AtomicProcess ;
    process:hasPrecondition [ expr:expressionBody "(and (ex:on ?A" ] ;
    process:hasResult [ process:hasEffect [ expr:expressionBody "(when (ex:on ?A) (ex:off ?A))" ] ] .
"""
    quads = list(ox.parse(input=text, format=ox.RdfFormat.TURTLE))
    result = convert(quads, "mem.ttl", prefixes={"ex": "http://example.org/o#"})
    assert (result.expressions, result.expressions_turned, result.expressions_text_only) == (2, 0, 2)
    assert any("unclosed" in note for note in result.notes)
    [service] = result.services
    assert service.text_only == 2


def test_turtle_owls_is_detected_by_its_namespaces(kb: KnowledgeBase, tmp_path: Path) -> None:
    path = tmp_path / "lamp.ttl"
    path.write_text(
        """@prefix service: <http://www.daml.org/services/owl-s/1.1/Service.owl#> .
@prefix profile: <http://www.daml.org/services/owl-s/1.1/Profile.owl#> .
@prefix process: <http://www.daml.org/services/owl-s/1.1/Process.owl#> .
<http://example.org/lamp#Switch> a service:Service ; service:presents [ a profile:Profile ;
    profile:serviceName "Switch lamp" ;
    profile:hasOutput [ a process:Output ; process:parameterType <http://example.org/o#LampState> ] ] .
""",
        encoding="utf-8",
    )
    [item] = kb.load([path]).files
    assert item.owls is not None and item.graph == GraphName.SERVICES.iri
    ad = kb.description("http://example.org/lamp#Switch")
    assert ad.service_name == "Switch lamp" and ad.device_name == "lamp"
    assert [(p.name, p.type) for p in ad.outputs] == [("output1", "http://example.org/o#LampState")]


def test_a_profile_without_a_service_describes_itself() -> None:
    text = """@prefix profile: <http://www.daml.org/services/owl-s/1.1/Profile.owl#> .
@prefix process: <http://www.daml.org/services/owl-s/1.1/Process.owl#> .
<http://example.org/p#Weather> a profile:Profile ; profile:serviceName "Weather" ;
    profile:hasOutput <http://example.org/p#Forecast> .
<http://example.org/p#Forecast> process:parameterType "http://example.org/o#Forecast" .
"""
    result = convert(list(ox.parse(input=text, format=ox.RdfFormat.TURTLE)), "/data/weather.owls", "requirement")
    [service] = result.services
    assert service.iri == requirement_iri("http://example.org/p#Weather") and service.outputs == 1
    assert all(q.graph_name == ox.DefaultGraph() for q in result.quads)


def test_requirement_role_when_loaded_into_requirements(kb: KnowledgeBase) -> None:
    [item] = kb.load([NAVIGATE], graph="requirements", catalogue=ONTOLOGY).files
    iri = requirement_iri(NAVIGATE_SERVICE)
    assert item.graph == GraphName.REQUIREMENTS.iri
    requirement = kb.description(iri)
    assert isinstance(requirement, Requirement)
    assert {p.type for p in requirement.inputs} == {ROBOTS + "MobileRobot", PLACES + "Kitchen"}
    assert len(requirement.effects) == 1
    assert _objects(kb, iri, "http://purl.org/dc/terms/source") == [NAVIGATE_SERVICE]
    assert not kb.advertisements()


def test_an_unresolvable_parameter_type_is_reported(kb: KnowledgeBase) -> None:
    report = kb.load([OPEN_DOOR], catalogue=ONTOLOGY)
    assert [(u.iri, u.used_as, u.used_by) for u in report.unresolved_concepts] == [
        (ROBOTS + "DoorReport", "parameter type", OPEN_DOOR_SERVICE)
    ]
    # it still loads, with the type as given
    assert [p.type for p in kb.description(OPEN_DOOR_SERVICE).outputs] == [ROBOTS + "DoorReport"]


def test_a_broken_owls_file_loads_nothing(kb: KnowledgeBase) -> None:
    before = kb.store.dump()
    with pytest.raises(RdfParseError) as caught:
        kb.load([NAVIGATE, OWLS / "broken.owls"], catalogue=ONTOLOGY)
    assert caught.value.line == 12 and "broken.owls" in str(caught.value)
    assert kb.store.dump() == before


def test_loading_an_owls_file_twice_adds_nothing(kb: KnowledgeBase) -> None:
    kb.load([NAVIGATE, OPEN_DOOR], catalogue=ONTOLOGY)
    once = kb.store.dump()
    kb.load([NAVIGATE, OPEN_DOOR], catalogue=ONTOLOGY)
    assert kb.store.dump() == once


def test_a_utf16_ontology_is_imported(kb: KnowledgeBase) -> None:
    report = kb.load([NAVIGATE], catalogue=ONTOLOGY)
    # places.owl (UTF-16 with a byte-order mark) comes in through robots.owl's own owl:imports
    assert sorted(Path(item.source).name for item in report.imports) == ["places.owl", "robots.owl"]
    assert all(item.graph == GraphName.ONTOLOGY.iri for item in report.imports)
    assert _objects(kb, PLACES + "Kitchen", RDFS + "label") == ["Küche"]
    assert _objects(kb, PLACES + "Kitchen", RDFS + "subClassOf") == [PLACES + "Room"]


# -- the catalogue -------------------------------------------------------------------------------


def test_catalogue_from_a_directory() -> None:
    catalogue = Catalogue.open(ONTOLOGY)
    assert catalogue.resolve("http://example.org/ontology/robots.owl") == ONTOLOGY / "robots.owl"
    assert catalogue.resolve("http://elsewhere.org/any/path/places.owl#Kitchen") == ONTOLOGY / "places.owl"
    assert catalogue.resolve(TC_PREFIX + "robots.owl") == ONTOLOGY / "robots.owl"
    assert catalogue.resolve("http://example.org/ontology/missing.owl") is None


@pytest.mark.parametrize("name", ["catalog-v001.xml", "catalog.tsv"])
def test_catalogue_from_a_mapping_file(kb: KnowledgeBase, name: str) -> None:
    catalogue = Catalogue.open(OWLS / name)
    assert catalogue.resolve("http://example.org/ontology/places.owl") == ONTOLOGY / "places.owl"
    assert catalogue.resolve(ROBOTS + "Door") == ONTOLOGY / "robots.owl"
    assert catalogue.resolve("http://elsewhere.org/robots.owl") is None  # a mapping file has no folder rule
    report = kb.load([NAVIGATE], catalogue=catalogue)
    assert len(report.imports) == 2 and not report.unresolved_concepts


def test_the_bundled_protege_catalogue_reads() -> None:
    catalogue = Catalogue.open(ontology_dir() / "catalog-v001.xml")
    assert catalogue.resolve("https://w3id.org/cbrs/home") == ontology_dir() / "home.ttl"


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("http://a.org/x.owl only-one-column\n", "two tab-separated columns"),
        ("<notacatalog/>", "not an OASIS <catalog>"),
        ("<catalog", "not well-formed XML"),
    ],
)
def test_a_bad_catalogue_file_is_named(tmp_path: Path, content: str, message: str) -> None:
    path = tmp_path / "catalogue"
    path.write_text(content, encoding="utf-8")
    with pytest.raises(CatalogueError, match=message):
        Catalogue.open(path)


def test_a_missing_import_is_reported_and_never_fetched(kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch) -> None:
    def no_network(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("the loader tried to use the network")

    monkeypatch.setattr(socket.socket, "connect", no_network)
    monkeypatch.setattr(socket, "create_connection", no_network)
    monkeypatch.setattr(urllib.request, "urlopen", no_network)
    report = kb.load([OPEN_DOOR], catalogue=ONTOLOGY)
    assert [(u.iri, Path(u.needed_by).name, u.reason) for u in report.unresolved_imports] == [
        ("http://example.org/ontology/missing.owl", "open_door.owls", "owl:imports")
    ]
    assert kb.description(OPEN_DOOR_SERVICE).service_name == "OpenDoor"


def test_without_a_catalogue_imports_are_not_followed(kb: KnowledgeBase) -> None:
    report = kb.load([NAVIGATE])
    assert not report.imports and not report.unresolved_imports
    assert {u.iri for u in report.unresolved_concepts} >= {ROBOTS + "MobileRobot", PLACES + "Kitchen"}


# -- loader details --------------------------------------------------------------------------------


def test_a_directory_loads_its_rdf_files_in_name_order(tmp_path: Path) -> None:
    (tmp_path / "b.owls").write_bytes(NAVIGATE.read_bytes())
    (tmp_path / "a.owl").write_bytes((ONTOLOGY / "robots.owl").read_bytes())
    (tmp_path / "catalog-v001.xml").write_bytes((OWLS / "catalog-v001.xml").read_bytes())
    (tmp_path / "notes.txt").write_text("not RDF", encoding="utf-8")
    assert [p.name for p in expand_paths([tmp_path])] == ["a.owl", "b.owls"]


@pytest.mark.parametrize(
    ("body", "repair"),
    [
        ('<owl:Class rdf:ID="1stClass"/>', "rdf:ID values that are not XML names"),
        ('<owl:Class rdf:ID="Twice"/><owl:Class rdf:ID="Twice"/>', "an rdf:ID given twice"),
    ],
)
def test_common_rdfxml_slips_are_mended(tmp_path: Path, body: str, repair: str) -> None:
    path = tmp_path / "slips.owl"
    path.write_text(
        """<?xml version="1.0"?>
<!DOCTYPE rdf:RDF [ <!ENTITY owl 'http://www.w3.org/2002/07/owl#'> ]>
<rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#" xmlns:owl="&owl;"
    xml:base="http://example.org/slips.owl">"""
        + body
        + "</rdf:RDF>",
        encoding="utf-8",
    )
    parsed = parse_file(path)
    assert any(item.startswith(repair) for item in parsed.repairs)
    assert "entity declarations in single quotes" in parsed.repairs
    assert all(q.subject.value.startswith("http://example.org/slips.owl#") for q in parsed.quads)


def test_vocabulary_tells_classes_from_properties() -> None:
    vocabulary = Vocabulary.from_quads(parse_file(ONTOLOGY / "robots.owl").quads)
    assert vocabulary.is_class(ROBOTS + "Door") and vocabulary.is_property(ROBOTS + "opens")
    assert vocabulary.by_local_name("opens", ["http://example.org/ontology/robots.owl"]) == [ROBOTS + "opens"]
    assert vocabulary.declares(RDF + "type") and not vocabulary.declares(ROBOTS + "Nothing")


# -- the command line ------------------------------------------------------------------------------


def test_cli_load_with_a_catalogue() -> None:
    result = CliRunner().invoke(
        cli, ["--store", ":memory:", "load", "--catalog", str(ONTOLOGY), str(NAVIGATE), str(OPEN_DOOR)]
    )
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[0] == (
        f"loaded {NAVIGATE}: 1 advertisement (2 inputs, 1 output, 1 precondition, 1 effect, "
        "1 condition as text only), 79 triples into graph:services"
    )
    assert lines[1].startswith(f"loaded {OPEN_DOOR}: 1 advertisement (1 input, 1 output, 1 precondition, 1 effect)")
    assert "imported 2 ontologies (21 triples) into graph:ontology" in lines
    assert "unresolved imports: 1 (http://example.org/ontology/missing.owl)" in lines
    assert f"unresolved parameter types (declared by no loaded ontology): 1 ({ROBOTS}DoorReport)" in lines


def test_cli_load_of_a_broken_owls_file_fails_in_one_line() -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "load", str(NAVIGATE), str(OWLS / "broken.owls")])
    assert result.exit_code == 1
    assert result.output.count("\n") == 1 and "broken.owls:12" in result.output


# -- the OWLS-TC 4 collection ------------------------------------------------------------------------

TC_SERVICES = [
    ("car_price_service.owls", "http://127.0.0.1/services/1.1/car_price_service.owls#CAR_PRICE_SERVICE"),
    ("lock_door.owls", "http://127.0.0.1/services/1.1/lock_door.owls#LockDoorService"),
    (
        "1personbicyclecar_price_service.owls",  # rdf:ID values that start with a digit
        "http://127.0.0.1/services/1.1/1personbicyclecar_price_service.owls#1PERSONBICYCLECAR_PRICE_SERVICE",
    ),
    ("getLocationOfUSCity.owls", "http://127.0.0.1/services/1.1/getLocationOfUSCity.owls#CITY_LOCATION_SERVICE"),
    ("book_price_service.owls", "http://127.0.0.1/services/1.1/book_price_service.owls#BOOK_PRICE_SERVICE"),
]


@pytest.fixture(scope="module")
def tc_kb() -> KnowledgeBase:
    kb = _kb()
    kb.load([TC / "services" / name for name, _ in TC_SERVICES], catalogue=TC / "ontology")
    kb.load(
        [TC / "queries" / "lock_door.owls", TC / "queries" / "getLocationOfUSCity.owls"],
        graph="requirements",
        catalogue=TC / "ontology",
    )
    return kb


@needs_tc
def test_tc_services_read_back_as_advertisements(tc_kb: KnowledgeBase) -> None:
    for _, iri in TC_SERVICES:
        ad = tc_kb.description(iri)
        assert isinstance(ad, Advertisement) and ad.kind == CBRS.MethodInvocationComponent, iri
        assert ad.outputs or ad.effects, iri
    car = tc_kb.description(TC_SERVICES[0][1])
    assert [p.type for p in car.inputs] == [TC_PREFIX + "my_ontology.owl#Car"]
    assert [p.type for p in car.outputs] == [TC_PREFIX + "concept.owl#Price"]
    bicycle = tc_kb.description(TC_SERVICES[2][1])
    assert {p.type for p in bicycle.inputs} == {
        TC_PREFIX + "my_ontology.owl#Car",
        TC_PREFIX + "my_ontology.owl#OnePersonBicycle",
    }
    # the parameter types' ontologies came in through the catalogue and know the classes
    assert tc_kb.describes(TC_PREFIX + "my_ontology.owl#OnePersonBicycle")


@needs_tc
def test_tc_queries_read_back_as_requirements(tc_kb: KnowledgeBase) -> None:
    lock = tc_kb.description(requirement_iri(TC_SERVICES[1][1]))
    assert isinstance(lock, Requirement)
    assert [p.type for p in lock.inputs] == [TC_PREFIX + "messemodul.owl#Door"]
    door, closed, unlocked, locked = (
        TC_PREFIX + "messemodul.owl#" + name for name in ("Door", "Closed", "Unlocked", "Locked")
    )
    assert {(s.subject, s.predicate, s.object) for s in lock.preconditions} == {
        (door, RDF + "type", closed),
        (door, RDF + "type", unlocked),
    }
    assert [(s.subject, s.object) for s in lock.effects] == [(door, locked)]
    city = tc_kb.description(requirement_iri(TC_SERVICES[3][1]))
    assert isinstance(city, Requirement)
    assert {p.type for p in city.inputs} == {TC_PREFIX + "protonu.owl#City", TC_PREFIX + "protonu.owl#State"}
    assert [s.predicate for s in city.preconditions] == [TC_PREFIX + "protont.owl#locatedIn"]
    # the service the request copies is still an advertisement of its own
    assert isinstance(tc_kb.description(TC_SERVICES[1][1]), Advertisement)
