"""cbrs in standard terms: queries that name only OWL-S, SOSA, QUDT and SOMA terms get cbrs's answers.

The store has no reasoner; what ontologies/alignments.ttl entails is materialised into graph:entailed
(kb/standard_terms.py). Each test asks in standard terms and compares with the same answer asked in
cbrs's own terms, so the expectations come from the bundled data, not from copies of it.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pyoxigraph as ox
import pytest
import rdflib

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.resources import bundled_files, ontology_dir
from cbrs.kb.standard_terms import StandardTerms, entailed

SVC = PREFIXES["svc"]
LOCATE = SVC + "LocateMobileRobot_CeilingCamera01"
CAMERA = SVC + "TrackVisitor_CeilingCamera02"
REGISTRATION = f"""@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix home: <https://w3id.org/cbrs/home#> .
<{CAMERA}> a cbrs:DynamicPerceptionComponent ;
    cbrs:device <{SVC}CeilingCamera02> ; cbrs:deviceName "CeilingCamera02" ; cbrs:serviceName "TrackVisitor" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "person" ; cbrs:parameterType home:Person ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "light" ; cbrs:parameterType home:Illuminance ] ] ;
    cbrs:hasQoSModel [ a cbrs:QoSModel ; cbrs:updateRate 2.5 ] .
"""


@pytest.fixture
def kb(store_location: str) -> Iterator[KnowledgeBase]:
    opened = KnowledgeBase.open(store_location)
    yield opened
    opened.close()


def values(kb: KnowledgeBase, query: str, bindings: dict[str, ox.NamedNode] | None = None) -> set[tuple[str, ...]]:
    """The rows' values, bound variables left out (the embedded store wants them projected)."""
    result = kb.query(query, bindings)
    assert isinstance(result, ox.QuerySolutions)
    shown = [v for v in result.variables if v.value not in (bindings or {})]
    return {tuple(row[v].value if row[v] is not None else "" for v in shown) for row in result}


def test_sensors_are_sosa_sensors(bundled_kb: KnowledgeBase) -> None:
    sensors = values(bundled_kb, "SELECT ?s WHERE { ?s a sosa:Sensor }")
    ours = values(bundled_kb, "SELECT ?s WHERE { GRAPH graph:services { ?s a ?c } ?c rdfs:subClassOf* home:Sensor }")
    assert sensors == ours and (SVC + "CeilingCamera01",) in sensors and len(sensors) >= 5
    robots = values(bundled_kb, "SELECT ?p WHERE { ?p a sosa:Platform }")
    assert (SVC + "P3DX01",) in robots and (SVC + "CeilingCamera01",) not in robots


def test_a_sensor_observes_what_its_perception_components_put_out(bundled_kb: KnowledgeBase) -> None:
    observed = values(
        bundled_kb,
        "SELECT ?sensor ?p WHERE { ?sensor sosa:observes ?p }",
        {"sensor": ox.NamedNode(SVC + "CeilingCamera01")},
    )
    outputs = values(
        bundled_kb,
        "SELECT ?sensor ?t WHERE { ?ad a cbrs:DynamicPerceptionComponent ; cbrs:device ?sensor ;"
        " cbrs:hasOWLSModel/cbrs:hasOutput/cbrs:parameterType ?t }",
        {"sensor": ox.NamedNode(SVC + "CeilingCamera01")},
    )
    assert observed == outputs and (PREFIXES["home"] + "RobotLocation",) in observed
    inverse = values(bundled_kb, "SELECT ?s WHERE { home:RobotLocation sosa:isObservedBy ?s }")
    assert (SVC + "CeilingCamera01",) in inverse
    assert bool(bundled_kb.query("ASK { home:RobotLocation a sosa:ObservableProperty }"))


def test_a_mounted_sensor_is_hosted_by_its_robot(bundled_kb: KnowledgeBase) -> None:
    hosted = values(bundled_kb, "SELECT ?sensor ?platform WHERE { ?sensor sosa:isHostedBy ?platform }")
    mounted = values(bundled_kb, "SELECT ?s ?r WHERE { ?s home:mountedOn ?r }")
    assert hosted == mounted and (SVC + "Kinect01", SVC + "CytonDualArm01") in hosted
    assert values(bundled_kb, "SELECT ?s ?p WHERE { ?p sosa:hosts ?s }") == hosted


def test_inputs_outputs_and_preconditions_read_as_owl_s_profiles(bundled_kb: KnowledgeBase) -> None:
    locate = {"service": ox.NamedNode(LOCATE)}
    owls = """SELECT ?service ?role ?type WHERE {
      ?service service:presents ?profile .
      { ?profile profile:hasInput ?p . ?p a process:Input . BIND ("input" AS ?role) }
      UNION { ?profile profile:hasOutput ?p . ?p a process:Output . BIND ("output" AS ?role) }
      ?p a process:Parameter ; process:parameterType ?type .
    }"""
    description = bundled_kb.description(LOCATE)
    ours = {("input", p.type) for p in description.inputs} | {("output", p.type) for p in description.outputs}
    assert values(bundled_kb, owls, locate) == ours and ours
    [(kind,)] = values(
        bundled_kb,
        "SELECT ?service (DATATYPE(?t) AS ?k)"
        " WHERE { ?service service:presents/profile:hasInput/process:parameterType ?t }",
        locate,
    )
    assert kind == PREFIXES["xsd"] + "anyURI"
    conditions = (
        "SELECT ?service ?c WHERE { ?service service:presents/profile:hasPrecondition ?c . ?c a expr:Condition }"
    )
    assert len(values(bundled_kb, conditions, locate)) == len(description.preconditions) > 0
    results = "SELECT ?service ?r WHERE { ?service service:presents/profile:hasResult ?r . ?r a process:Result }"
    assert len(values(bundled_kb, results, locate)) == len(description.effects) > 0
    assert (LOCATE,) in values(bundled_kb, "SELECT ?s WHERE { ?s a service:Service }")


def test_qos_values_carry_their_qudt_unit(bundled_kb: KnowledgeBase) -> None:
    in_hertz = values(bundled_kb, "SELECT ?x ?v WHERE { ?x ?p ?v . ?p qudt:hasUnit unit:HZ }")
    update_rates = values(bundled_kb, "SELECT ?x ?v WHERE { ?x cbrs:updateRate ?v }")
    assert in_hertz == update_rates and update_rates
    units = values(
        bundled_kb,
        "SELECT ?p ?unit ?kind WHERE { ?p rdfs:subPropertyOf cbrs:qosProperty"
        " OPTIONAL { ?p qudt:hasUnit ?unit . ?unit qudt:hasQuantityKind ?kind } }",
    )
    by_metric = {p.rsplit("#", 1)[1]: unit.rsplit("/", 1)[1] for p, unit, _ in units if unit}
    assert by_metric == {
        "responseTime": "SEC",
        "accuracy": "FRACTION",
        "positionError": "M",
        "availability": "FRACTION",
        "updateRate": "HZ",
    }
    assert all(kind for _, unit, kind in units if unit)  # every unit names its quantity kind


def test_action_orderings_read_as_soma_succedences(bundled_kb: KnowledgeBase) -> None:
    action = {"action": ox.NamedNode(PREFIXES["act"] + "PuttingSomethingSomewhere")}
    soma = values(
        bundled_kb,
        "SELECT ?action ?before ?after WHERE { ?action soma:hasSuccedence ?o . ?o a soma:Succedence ;"
        " soma:hasPredecessor ?before ; soma:hasSuccessor ?after }",
        action,
    )
    ours = {
        (row["before"].value, row["after"].value)
        for row in bundled_kb.select("action_ordering", {"action": action["action"]})
    }
    assert soma == ours and len(ours) == 3


@pytest.mark.parametrize("store_location", ["embedded", "remote"], indirect=True)
def test_an_advertisement_registered_at_run_time_is_seen_in_standard_terms(kb: KnowledgeBase) -> None:
    light = {"property": ox.NamedNode(PREFIXES["home"] + "Illuminance")}
    observers = "SELECT ?property ?sensor WHERE { ?sensor sosa:observes ?property }"
    before = values(kb, observers, light)
    assert (SVC + "CeilingCamera02",) not in before
    kb.registry.register(REGISTRATION)
    assert values(kb, observers, light) == before | {(SVC + "CeilingCamera02",)}
    assert (CAMERA,) in values(kb, "SELECT ?s WHERE { ?s a service:Service }")
    rates = "SELECT ?s ?v WHERE { ?s service:presents ?profile ; ?q ?m . ?m ?rate ?v . ?rate qudt:hasUnit unit:HZ }"
    assert values(kb, rates, {"s": ox.NamedNode(CAMERA)}) == {("2.5",)}
    assert _held(kb) == entailed(kb.store)  # the registration's own update is what a full one gives
    kb.registry.update(REGISTRATION.replace("home:Illuminance", "home:PersonLocation"))
    assert values(kb, observers, light) == before and _held(kb) == entailed(kb.store)
    kb.registry.deregister(CAMERA)
    assert (CAMERA,) not in values(kb, "SELECT ?s WHERE { ?s a service:Service }")
    assert _held(kb) == entailed(kb.store)


def test_loading_a_file_refreshes_the_standard_terms(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(":memory:")
    robot = tmp_path / "robot.ttl"
    robot.write_text(
        "@prefix home: <https://w3id.org/cbrs/home#> .\n"
        '<https://example.org/Tiago> a home:MobileRobot ; home:modelName "TIAGo" .\n',
        encoding="utf-8",
    )
    kb.load([robot], graph="services")
    assert bool(kb.query("ASK { <https://example.org/Tiago> a sosa:Platform }"))
    kb.update("DELETE WHERE { GRAPH graph:services { <https://example.org/Tiago> ?p ?o } }")
    assert not bool(kb.query("ASK { <https://example.org/Tiago> a sosa:Platform }"))


def test_the_standard_terms_change_no_cbrs_answer() -> None:
    """graph:entailed is for readers in standard terms: the map, the world state composition starts from,
    the descriptions and the matchmaker's inputs read as they do without it."""
    kb = KnowledgeBase.open(":memory:")
    with_them = _answers(KnowledgeBase(kb.store))
    kb.store.clear_graph(GraphName.ENTAILED.node)
    assert _answers(KnowledgeBase(kb.store)) == with_them


def _answers(kb: KnowledgeBase) -> tuple[object, ...]:
    robots = kb.select("designate", {"class": PREFIXES["home"] + "Robot"})
    return (
        kb.select("world_state"),
        kb.select("map_types"),
        robots,
        [ad.to_dict() for ad in kb.advertisements()],
        [requirement.to_dict() for requirement in kb.requirements()],
    )


def test_a_store_seeded_without_standard_terms_gets_them_when_opened(tmp_path: Path) -> None:
    location = str(tmp_path / "store")
    kb = KnowledgeBase.open(location)
    kb.store.clear_graph(GraphName.ENTAILED.node)
    kb.close()
    reopened = KnowledgeBase.open(location)
    assert bool(reopened.query("ASK { ?s a sosa:Sensor }"))
    reopened.close()


def test_the_alignment_reaches_standard_terms_through_cbrs_classes(bundled_kb: KnowledgeBase) -> None:
    terms = StandardTerms(bundled_kb.store)
    assert terms.alignment().above(PREFIXES["home"] + "KinectSensor") >= {PREFIXES["sosa"] + "Sensor"}
    assert not terms.alignment().above(PREFIXES["home"] + "Cup")


@pytest.mark.parametrize("path", sorted((ontology_dir() / "standards").glob("*.ttl")), ids=lambda p: p.name)
def test_each_standard_subset_names_its_source_and_licence(path: Path) -> None:
    graph = rdflib.Graph().parse(path, format="turtle")
    [header] = graph.subjects(rdflib.RDF.type, rdflib.OWL.Ontology)
    dcterms = rdflib.Namespace("http://purl.org/dc/terms/")
    assert graph.value(header, dcterms.license) is not None and graph.value(header, dcterms.source) is not None
    assert "licen" in path.read_text(encoding="utf-8").split("<https://w3id.org/cbrs/standards/")[0].lower()
    assert path.relative_to(ontology_dir()) in {item.path.relative_to(ontology_dir()) for item in bundled_files()}


def _held(kb: KnowledgeBase) -> set[ox.Quad]:
    return set(kb.store.quads(graph=GraphName.ENTAILED.node))


def test_working_out_the_standard_terms_needs_no_checker_process(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The texts that work out graph:entailed are cbrs's own: on an on-disk store they skip the query
    guard, whose checker process would otherwise start (and stay) after every load and update."""
    store = KnowledgeBase.open(tmp_path / "store")
    admitted: list[str] = []
    monkeypatch.setattr(store.store.guard, "admit", lambda kind, text: admitted.append(text))  # type: ignore[attr-defined]
    refresh = store.refresh_standard_terms()
    assert admitted == []
    assert next(store.store.quads(graph=GraphName.ENTAILED.node), None) is not None, refresh
    store.store.query("SELECT * WHERE { ?s ?p ?o } LIMIT 1")  # any other text is still checked
    assert admitted == ["SELECT * WHERE { ?s ?p ?o } LIMIT 1"]
    store.close()
