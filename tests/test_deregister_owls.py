"""Deregistering a description that ``cbrs load`` made from OWL-S removes the OWL-S triples it was made
from too: its service, profile, process and grounding, their parameters, expressions and results, the
file's stub class declarations and its ``owl:Ontology`` header, but nothing another description still
uses. Before, only the cbrs description and the service node's own triples went: loading
tests/data/owls/services/navigate.owls and deregistering it left 41 triples in graph:services (the
profile, the process, the parameters, the expressions) and 7 in graph:entailed.

Every test compares the store's triples graph by graph: before the load, after the deregistration, and
after loading the same file again."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase, NotFoundError, RdfParseError
from cbrs.kb.namespaces import OWL, RDF, GraphName

from .conftest import make_mini_kb

pytestmark = pytest.mark.both_stores

OWLS = Path(__file__).parent / "data" / "owls"
CATALOG = OWLS / "catalog-v001.xml"
NAVIGATE = "http://example.org/services/navigate.owls#NavigateService"
OPEN_DOOR = "http://example.org/services/open_door.owls#OpenDoorService"
LAB = "http://example.org/lab-services/pair.owls#"

Snapshot = dict[str, set[str]]


def triples_by_graph(kb: KnowledgeBase) -> Snapshot:
    """Every triple of the store, by graph (the default graph included)."""
    found: Snapshot = {}
    for quad in kb.store.quads():
        found.setdefault(str(quad.graph_name), set()).add(f"{quad.subject} {quad.predicate} {quad.object}")
    return found


@pytest.fixture
def kb(store_location: str) -> Iterator[KnowledgeBase]:
    """The core and the mini data, with the OWL-S test ontologies loaded beforehand (so the loads
    below import nothing new)."""
    kb = make_mini_kb(store_location)
    kb.load([OWLS / "ontology"])
    yield kb
    kb.close()


def _pair(stub_use: str = "Widget") -> str:
    """One OWL-S file with two services that share a parameter (``#Robot``) and whose file declares
    two stub classes: ``lab:Widget``, which service A takes, and ``lab:Gadget``, which both give."""
    anyuri = 'rdf:datatype="http://www.w3.org/2001/XMLSchema#anyURI"'
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#"
    xmlns:owl="http://www.w3.org/2002/07/owl#"
    xmlns:service="http://www.daml.org/services/owl-s/1.1/Service.owl#"
    xmlns:profile="http://www.daml.org/services/owl-s/1.1/Profile.owl#"
    xmlns:process="http://www.daml.org/services/owl-s/1.1/Process.owl#"
    xml:base="http://example.org/lab-services/pair.owls">
  <owl:Ontology rdf:about=""/>
  <service:Service rdf:ID="A">
    <service:presents><profile:Profile rdf:ID="AProfile">
      <profile:serviceName>A</profile:serviceName>
      <profile:hasInput rdf:resource="#Robot"/>
      <profile:hasInput><process:Input rdf:ID="Part">
        <process:parameterType {anyuri}>http://example.org/lab#{stub_use}</process:parameterType>
      </process:Input></profile:hasInput>
      <profile:hasOutput><process:Output rdf:ID="AOut">
        <process:parameterType {anyuri}>http://example.org/lab#Gadget</process:parameterType>
      </process:Output></profile:hasOutput>
    </profile:Profile></service:presents>
  </service:Service>
  <service:Service rdf:ID="B">
    <service:presents><profile:Profile rdf:ID="BProfile">
      <profile:serviceName>B</profile:serviceName>
      <profile:hasInput rdf:resource="#Robot"/>
      <profile:hasOutput><process:Output rdf:ID="BOut">
        <process:parameterType {anyuri}>http://example.org/lab#Gadget</process:parameterType>
      </process:Output></profile:hasOutput>
    </profile:Profile></service:presents>
  </service:Service>
  <process:Input rdf:ID="Robot">
    <process:parameterType {anyuri}>http://example.org/ontology/robots.owl#MobileRobot</process:parameterType>
  </process:Input>
  <owl:Class rdf:about="http://example.org/lab#Widget"/>
  <owl:Class rdf:about="http://example.org/lab#Gadget"/>
</rdf:RDF>
"""


def test_an_owls_advertisement_goes_whole_and_comes_back_the_same(kb: KnowledgeBase) -> None:
    before = triples_by_graph(kb)
    kb.load([OWLS / "services" / "navigate.owls"], catalogue=CATALOG)
    loaded = triples_by_graph(kb)
    removed = kb.registry.deregister(NAVIGATE)
    assert triples_by_graph(kb) == before
    assert removed == sum(len(loaded[g] - before.get(g, set())) for g in loaded if g != str(GraphName.ENTAILED.node))
    kb.load([OWLS / "services" / "navigate.owls"], catalogue=CATALOG)
    assert triples_by_graph(kb) == loaded
    assert kb.description(NAVIGATE).service_name == "Navigate to room"


def test_an_owls_requirement_goes_whole(kb: KnowledgeBase) -> None:
    before = triples_by_graph(kb)
    kb.load([OWLS / "services" / "open_door.owls"], graph="requirements", catalogue=CATALOG)
    loaded = triples_by_graph(kb)
    kb.registry.deregister(OPEN_DOOR + "-request")
    assert triples_by_graph(kb) == before
    kb.load([OWLS / "services" / "open_door.owls"], graph="requirements", catalogue=CATALOG)
    assert triples_by_graph(kb) == loaded


def test_deregistering_one_service_leaves_another_file_s_as_loaded(kb: KnowledgeBase) -> None:
    kb.load([OWLS / "services" / "open_door.owls"], catalogue=CATALOG)
    only_open_door = triples_by_graph(kb)
    kb.load([OWLS / "services" / "navigate.owls"], catalogue=CATALOG)
    kb.registry.deregister(NAVIGATE)
    assert triples_by_graph(kb) == only_open_door


def test_the_advertisement_and_the_requirement_of_one_file_go_separately(kb: KnowledgeBase) -> None:
    """The same OWL-S file loaded as a service and as a request: its triples are in both graphs, and
    deregistering the requirement touches graph:requirements only."""
    kb.load([OWLS / "services" / "open_door.owls"], catalogue=CATALOG)
    advertised = triples_by_graph(kb)
    kb.load([OWLS / "services" / "open_door.owls"], graph="requirements", catalogue=CATALOG)
    kb.registry.deregister(OPEN_DOOR + "-request")
    assert triples_by_graph(kb) == advertised


def test_what_two_services_of_one_file_share_stays_until_both_are_gone(kb: KnowledgeBase, tmp_path: Path) -> None:
    before = triples_by_graph(kb)
    pair = tmp_path / "pair.owls"
    pair.write_text(_pair(), encoding="utf-8")
    kb.load([pair])
    services = str(GraphName.SERVICES.node)
    kb.registry.deregister(LAB + "A")
    left = triples_by_graph(kb)[services] - before.get(services, set())
    subjects = {triple.split(" ", 1)[0] for triple in left}
    # B, its profile and output, the shared #Robot, the Gadget stub B uses, and the file's header
    assert f"<{LAB}Robot>" in subjects and "<http://example.org/lab#Gadget>" in subjects
    assert f"<{LAB}B>" in subjects and "<http://example.org/lab-services/pair.owls>" in subjects
    assert not {f"<{LAB}A>", f"<{LAB}AProfile>", f"<{LAB}Part>", "<http://example.org/lab#Widget>"} & subjects
    assert [p.type for p in kb.description(LAB + "B").inputs] == ["http://example.org/ontology/robots.owl#MobileRobot"]
    kb.registry.deregister(LAB + "B")
    assert triples_by_graph(kb) == before


def test_a_stub_class_another_file_uses_stays(kb: KnowledgeBase, tmp_path: Path) -> None:
    """lab:Widget is declared by both files and taken by A of each: it goes with the second only."""
    before = triples_by_graph(kb)
    first, second = tmp_path / "pair.owls", tmp_path / "other.owls"
    first.write_text(_pair(), encoding="utf-8")
    second.write_text(_pair().replace("lab-services/pair.owls", "lab-services/other.owls"), encoding="utf-8")
    kb.load([second])
    only_second = triples_by_graph(kb)
    kb.load([first])
    for service in ("A", "B"):
        kb.registry.deregister(LAB + service)
    assert triples_by_graph(kb) == only_second
    for service in ("A", "B"):
        kb.registry.deregister(LAB.replace("pair", "other") + service)
    assert triples_by_graph(kb) == before


def test_a_stub_a_turtle_description_uses_stays(kb: KnowledgeBase, tmp_path: Path) -> None:
    """A registered Turtle description that takes lab:Widget keeps the OWL-S file's declaration of it."""
    pair = tmp_path / "pair.owls"
    pair.write_text(_pair(), encoding="utf-8")
    kb.load([pair])
    kb.registry.register(
        """@prefix cbrs: <https://w3id.org/cbrs/core#> .
        <http://example.org/lab#Sorter> a cbrs:MethodInvocationComponent ; cbrs:deviceName "Arm" ;
            cbrs:serviceName "Sort" ; cbrs:hasOWLSModel [
                cbrs:hasInput [ cbrs:parameterType <http://example.org/lab#Widget> ] ;
                cbrs:hasOutput [ cbrs:parameterType <http://example.org/lab#Gadget> ] ] ."""
    )
    for service in ("A", "B"):
        kb.registry.deregister(LAB + service)
    services = triples_by_graph(kb)[str(GraphName.SERVICES.node)]
    assert f"<http://example.org/lab#Widget> <{RDF}type> <{OWL}Class>" in services
    assert not [t for t in services if t.startswith(f"<{LAB}")]


def test_deregistering_an_unknown_or_already_deregistered_service_changes_nothing(kb: KnowledgeBase) -> None:
    kb.load([OWLS / "services" / "navigate.owls"], catalogue=CATALOG)
    kb.registry.deregister(NAVIGATE)
    after = triples_by_graph(kb)
    for iri in (NAVIGATE, "http://example.org/services/navigate.owls#NavigateProfile"):
        with pytest.raises(NotFoundError):
            kb.registry.deregister(iri)
    assert triples_by_graph(kb) == after


def test_an_update_in_turtle_replaces_the_owls_source_too(kb: KnowledgeBase) -> None:
    """Before, the update replaced the service node's own OWL-S triples and left its profile, process,
    parameters and expressions, which pointed at a service no longer typed or linked as one."""
    turtle = f"""@prefix cbrs: <https://w3id.org/cbrs/core#> .
<{NAVIGATE}> a cbrs:MethodInvocationComponent ; cbrs:deviceName "P3DX01" ; cbrs:serviceName "Navigate" ;
    cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType <http://example.org/ontology/robots.owl#Position> ] ] .
"""
    before = triples_by_graph(kb)
    kb.registry.register(turtle)
    registered_alone = triples_by_graph(kb)
    kb.registry.deregister(NAVIGATE)
    kb.load([OWLS / "services" / "navigate.owls"], catalogue=CATALOG)
    kb.registry.update(turtle)
    assert triples_by_graph(kb) == registered_alone
    kb.registry.deregister(NAVIGATE)
    assert triples_by_graph(kb) == before


def test_an_edited_file_loads_after_the_old_one_is_deregistered(kb: KnowledgeBase, tmp_path: Path) -> None:
    """What the refusal to merge says to do ("cbrs deregister IRI first") gives the store of the edited file
    alone; before, the old profile, process and parameters stayed and merged with the new ones."""
    edited = tmp_path / "navigate.owls"
    text = (OWLS / "services" / "navigate.owls").read_text(encoding="utf-8")
    edited.write_text(text.replace("Navigate to room", "Drive to room").replace("#Kitchen", "#Room"), encoding="utf-8")
    before = triples_by_graph(kb)
    kb.load([edited], catalogue=CATALOG)
    edited_alone = triples_by_graph(kb)
    kb.registry.deregister(NAVIGATE)
    assert triples_by_graph(kb) == before
    kb.load([OWLS / "services" / "navigate.owls"], catalogue=CATALOG)
    with pytest.raises(RdfParseError, match="cbrs deregister IRI first"):
        kb.load([edited], catalogue=CATALOG)
    kb.registry.deregister(NAVIGATE)
    kb.load([edited], catalogue=CATALOG)
    assert triples_by_graph(kb) == edited_alone
    assert kb.description(NAVIGATE).service_name == "Drive to room"


def test_a_description_citing_an_owls_advertisement_leaves_it_alone(kb: KnowledgeBase) -> None:
    """A lab's Turtle description whose dcterms:source is a loaded OWL-S advertisement: deregistering
    the lab's removed the advertisement's own triples with it (a requirement's source is walked)."""
    kb.load([OWLS / "services" / "navigate.owls"], catalogue=CATALOG)
    loaded = triples_by_graph(kb)
    kb.registry.register(
        f"""@prefix cbrs: <https://w3id.org/cbrs/core#> .
<http://example.org/lab#Drive> a cbrs:MethodInvocationComponent ; cbrs:deviceName "P3DX02" ;
    cbrs:serviceName "Drive" ; <http://purl.org/dc/terms/source> <{NAVIGATE}> ;
    cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType <http://example.org/ontology/robots.owl#Position> ] ] .
"""
    )
    kb.registry.deregister("http://example.org/lab#Drive")
    assert triples_by_graph(kb) == loaded
    assert kb.description(NAVIGATE).service_name == "Navigate to room"


def test_a_resource_described_elsewhere_that_only_the_file_points_at_stays(kb: KnowledgeBase, tmp_path: Path) -> None:
    """An OWL-S contact that is a device another file describes in graph:services: the walk followed
    every node the graph said something about, and removed the device with the service."""
    devices = tmp_path / "devices.ttl"
    devices.write_text(
        '@prefix ex: <http://example.org/mini#> . ex:Cam9 a ex:Camera ; ex:modelName "camera 9" .',
        encoding="utf-8",
    )
    kb.load([devices], graph="services")
    before = triples_by_graph(kb)
    navigate = tmp_path / "navigate.owls"
    text = (OWLS / "services" / "navigate.owls").read_text(encoding="utf-8")
    start, end = text.index("<profile:contactInformation>"), text.index("</profile:contactInformation>")
    contact = '<profile:contactInformation rdf:resource="http://example.org/mini#Cam9"/>'
    navigate.write_text(text[:start] + contact + text[end + len("</profile:contactInformation>") :], encoding="utf-8")
    kb.load([navigate], catalogue=CATALOG)
    kb.registry.deregister(NAVIGATE)
    assert triples_by_graph(kb) == before
