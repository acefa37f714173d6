"""The bundled ontologies: well-formed, declared, loadable by OWL tools, and true to the paper."""

from __future__ import annotations

from pathlib import Path

import pytest
import rdflib
from rdflib.namespace import OWL, RDF, RDFS

from cbrs.kb import Advertisement, KnowledgeBase, Requirement
from cbrs.kb.namespaces import ACT, CBRS, DUL, HOME, REQ, SVC
from cbrs.kb.resources import bundled_files, ontology_dir

OURS = (CBRS, HOME, ACT, SVC, REQ)
DECLARED_TYPES = {
    OWL.Class,
    OWL.ObjectProperty,
    OWL.DatatypeProperty,
    OWL.AnnotationProperty,
    OWL.NamedIndividual,
    RDFS.Class,
    RDF.Property,
}


@pytest.fixture(scope="module")
def merged() -> rdflib.Graph:
    graph = rdflib.Graph()
    for item in bundled_files():
        graph.parse(item.path, format="turtle")
    return graph


def test_bundle_lists_every_ontology_file() -> None:
    folder = ontology_dir()
    listed = {item.path.relative_to(folder) for item in bundled_files()}
    shapes = {path.relative_to(folder) for path in folder.glob("shapes*.ttl")}  # read by the validator, not stored
    files = [*folder.glob("*.ttl"), *folder.glob("standards/*.ttl")]
    assert listed == {path.relative_to(folder) for path in files} - shapes


def test_protege_catalogue_maps_every_import_to_a_bundled_file(merged: rdflib.Graph) -> None:
    import xml.etree.ElementTree as ET

    ns = {"c": "urn:oasis:names:tc:entity:xmlns:xml:catalog"}
    root = ET.parse(ontology_dir() / "catalog-v001.xml").getroot()
    mapping = {uri.get("name"): uri.get("uri") for uri in root.findall("c:uri", ns)}
    for imported in set(merged.objects(None, OWL.imports)):
        assert str(imported) in mapping, imported
        assert (ontology_dir() / mapping[str(imported)]).is_file()


@pytest.mark.parametrize("path", sorted(ontology_dir().glob("*.ttl")), ids=lambda p: p.name)
def test_each_file_has_an_ontology_header(path: Path) -> None:
    graph = rdflib.Graph().parse(path, format="turtle")
    headers = list(graph.subjects(RDF.type, OWL.Ontology))
    assert len(headers) == 1
    assert graph.value(headers[0], RDFS.label) is not None
    assert graph.value(headers[0], OWL.versionInfo) is not None


def test_every_term_we_use_is_declared(merged: rdflib.Graph) -> None:
    declared = {s for s, _, o in merged.triples((None, RDF.type, None)) if isinstance(s, rdflib.URIRef)}
    used = set()
    for _s, p, o in merged:
        used.add(p)
        if p in (RDF.type, RDFS.subClassOf, OWL.someValuesFrom, OWL.onProperty, RDFS.subPropertyOf) or str(p) in (
            CBRS + "parameterType",
            CBRS + "conditionSubject",
            CBRS + "conditionPredicate",
            CBRS + "conditionObject",
        ):
            used.add(o)
    ours = {t for t in used if isinstance(t, rdflib.URIRef) and str(t).startswith(OURS)}
    assert sorted(str(t) for t in ours - declared) == []


def test_has_part_family_roots_at_dul(merged: rdflib.Graph) -> None:
    has_part = rdflib.URIRef(DUL + "hasPart")
    part_props = {
        p for restriction in merged.subjects(OWL.onProperty, None) for p in merged.objects(restriction, OWL.onProperty)
    }
    family = set(merged.transitive_subjects(RDFS.subPropertyOf, has_part))
    assert len(family) > 10
    for prop in part_props:
        if str(prop).startswith(HOME) and prop in family:
            assert has_part in set(merged.transitive_objects(prop, RDFS.subPropertyOf))
    names = {str(p).rsplit("#", 1)[1] for p in family}
    assert {"hasFamilyName", "hasGivenName", "hasStatus", "hasXCoordinate"} <= names


def test_owlready2_loads_the_whole_bundle(merged: rdflib.Graph, tmp_path: Path) -> None:
    # owlready2 reads RDF/XML; what it loads, Protege loads. The imports are all in the merge
    # (Protege resolves them through ontologies/catalog-v001.xml); owlready2 would fetch them.
    import owlready2

    path = tmp_path / "bundle.owl"
    without_imports = rdflib.Graph()
    for triple in merged:
        if triple[1] != OWL.imports:
            without_imports.add(triple)
    without_imports.serialize(path, format="xml")
    world = owlready2.World()
    onto = world.get_ontology(path.as_uri()).load()
    names = {c.name for c in onto.world.classes()}
    assert {"Position", "Location", "Cup", "Advertisement", "PuttingSomethingSomewhere"} <= names


def test_every_description_reads_into_the_model(bundled_kb: KnowledgeBase) -> None:
    ads = bundled_kb.advertisements()
    reqs = bundled_kb.requirements()
    assert len(ads) >= 30 and len(reqs) >= 4
    for ad in ads:
        assert ad.service_name and ad.device_name and ad.kind, ad.iri
        assert ad.outputs or ad.effects, ad.iri


def test_table1_locate_mobile_robot(bundled_kb: KnowledgeBase) -> None:
    ad = bundled_kb.description(SVC + "LocateMobileRobot_CeilingCamera01")
    assert isinstance(ad, Advertisement)
    assert ad.kind == CBRS + "DynamicPerceptionComponent"
    assert ad.service_name == "LocateMobileRobot"
    assert [p.type for p in ad.inputs] == [HOME + "MarkerColour"]
    assert [p.type for p in ad.outputs] == [HOME + "RobotLocation"]
    tree = ad.outputs[0].tree
    assert tree is not None
    parts = {child.via.rsplit("#", 1)[1] for child in tree.children if child.via}
    assert {"hasXCoordinate", "hasYCoordinate"} <= parts


def test_table2_self_position_requirement(bundled_kb: KnowledgeBase) -> None:
    req = bundled_kb.description(REQ + "RobotSelfPosition")
    assert isinstance(req, Requirement)
    assert [p.type for p in req.outputs] == [HOME + "RobotPosition"]
    assert req.requested_by == SVC + "P3DX01"
    # Position and Location are different words for the same parts: matchable through the taxonomy,
    # not by their strings.
    located = bundled_kb.description(SVC + "LocateMobileRobot_CeilingCamera01").outputs[0].tree
    wanted = req.outputs[0].tree
    assert located is not None and wanted is not None
    assert {c.via for c in wanted.children} & {c.via for c in located.children}


def test_put_cup_below_tap_task(bundled_kb: KnowledgeBase) -> None:
    req = bundled_kb.description(REQ + "PutCupBelowOfTapOfWaterDispenser")
    assert isinstance(req, Requirement)
    assert {p.type for p in req.inputs} == {HOME + "Cup", HOME + "BelowOfTap"}
    assert [(e.subject, e.predicate, e.object) for e in req.effects] == [
        (HOME + "Cup", HOME + "isLocated", HOME + "BelowOfTap")
    ]


def test_coarse_action_has_ordered_sub_actions(bundled_kb: KnowledgeBase) -> None:
    rows = bundled_kb.select("action_ordering", {"action": "act:RobotArmServeACup"})
    pairs = {(r["before"].value, r["after"].value) for r in rows}
    second = ACT + "PutCupBelowOfTapOfWaterDispenser"
    assert any(after == second for _, after in pairs) and any(before == second for before, _ in pairs)
