"""``cbrs show`` of a class names its restrictions and other anonymous class expressions in Manchester
syntax, in the table and (beside the existing keys) in --json. Before, each was a skolem IRI
(``genid:c74927f3426fa392-c14n106``) that said nothing of what the class is; so was a description's
parameter that takes the class."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb.namespaces import OWL, RDF, RDFS

LAB = "http://example.org/lab#"
ONTOLOGY = """@prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
@prefix xsd: <http://www.w3.org/2001/XMLSchema#> .
@prefix lab: <http://example.org/lab#> .
lab:Gripper a owl:Class . lab:Arm a owl:Class . lab:Wheel a owl:Class .
lab:Red a owl:NamedIndividual . lab:Blue a owl:NamedIndividual .
lab:hasPart a owl:ObjectProperty . lab:hasColour a owl:ObjectProperty . lab:partOf a owl:ObjectProperty .
lab:weight a owl:DatatypeProperty . lab:name a owl:DatatypeProperty . lab:touches a owl:ObjectProperty .
lab:Robot a owl:Class ;
  rdfs:subClassOf [ a owl:Restriction ; owl:onProperty lab:hasPart ; owl:someValuesFrom lab:Gripper ] ,
    [ a owl:Restriction ; owl:onProperty lab:hasColour ; owl:hasValue lab:Red ] ,
    [ a owl:Restriction ; owl:onProperty lab:hasPart ;
      owl:qualifiedCardinality "4"^^xsd:nonNegativeInteger ; owl:onClass lab:Wheel ] ,
    [ a owl:Restriction ; owl:onProperty lab:hasPart ; owl:maxCardinality "10"^^xsd:nonNegativeInteger ] ,
    [ a owl:Restriction ; owl:onProperty lab:hasPart ;
      owl:allValuesFrom [ a owl:Class ; owl:unionOf ( lab:Arm lab:Wheel lab:Gripper ) ] ] ,
    [ a owl:Restriction ; owl:onProperty [ owl:inverseOf lab:partOf ] ; owl:someValuesFrom lab:Arm ] ,
    [ a owl:Restriction ; owl:onProperty lab:weight ; owl:someValuesFrom [ a rdfs:Datatype ;
      owl:onDatatype xsd:decimal ; owl:withRestrictions ( [ xsd:minInclusive 1.5 ] [ xsd:maxExclusive 80 ] ) ] ] ,
    [ a owl:Restriction ; owl:onProperty lab:name ; owl:hasValue "Robbie"@en ] ,
    [ a owl:Restriction ; owl:onProperty lab:touches ; owl:hasSelf true ] ,
    [ a owl:Class ; owl:complementOf lab:Wheel ] ,
    [ a owl:Restriction ; owl:onProperty lab:hasPart ] .
lab:RedGripperRobot a owl:Class ;
  owl:equivalentClass [ a owl:Class ; owl:intersectionOf ( lab:Robot
      [ a owl:Restriction ; owl:onProperty lab:hasPart ; owl:someValuesFrom [ a owl:Class ;
        owl:intersectionOf ( lab:Gripper
          [ a owl:Restriction ; owl:onProperty lab:hasColour ; owl:hasValue lab:Red ] ) ] ]
      [ a owl:Restriction ; owl:onProperty lab:hasColour ;
        owl:someValuesFrom [ a owl:Class ; owl:oneOf ( lab:Red lab:Blue ) ] ] ) ] .
"""
ROBOT = [
    f"{LAB}hasPart some {LAB}Gripper",
    f"{LAB}hasColour value {LAB}Red",
    f"{LAB}hasPart exactly 4 {LAB}Wheel",
    f"{LAB}hasPart max 10",
    f"{LAB}hasPart only ({LAB}Arm or {LAB}Wheel or {LAB}Gripper)",
    f"(inverse {LAB}partOf) some {LAB}Arm",
    f"{LAB}weight some xsd:decimal[>= 1.5, < 80]",
    f'{LAB}name value "Robbie"@en',
    f"{LAB}touches Self",
    f"not {LAB}Wheel",
]
RED_GRIPPER_ROBOT = (
    f"{LAB}Robot and ({LAB}hasPart some ({LAB}Gripper and ({LAB}hasColour value {LAB}Red)))"
    f" and ({LAB}hasColour some {{{LAB}Red, {LAB}Blue}})"
)


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> str:
    folder = tmp_path_factory.mktemp("show")
    (folder / "lab.ttl").write_text(ONTOLOGY, encoding="utf-8")
    location = str(folder / "store")
    result = CliRunner().invoke(cli, ["--store", location, "load", str(folder / "lab.ttl")])
    assert result.exit_code == 0, result.output
    return location


def show(store: str, *args: str) -> str:
    result = CliRunner().invoke(cli, ["--store", store, "show", *args])
    assert result.exit_code == 0, result.output
    return result.output


def _printed(text: str) -> str:
    """``text`` as the table prints it: lab# by the prefix the browser derives for it (--json keeps IRIs)."""
    return text.replace(LAB, "lab:")


def _values(out: str) -> list[str]:
    """The value column of show's table (between the predicate and the graph)."""
    return [line.split("  ", 2)[-1].rsplit("  ", 1)[0].strip() for line in out.splitlines()[3:]]


def test_each_restriction_reads_in_manchester_syntax(store: str) -> None:
    values = [v.split(maxsplit=1)[1] for v in _values(show(store, LAB + "Robot")) if v.startswith("rdfs:subClassOf")]
    assert sorted(v for v in values if "genid:" not in v) == sorted(map(_printed, ROBOT))
    # a restriction without a filler is no class expression: it keeps its node's name
    assert len([v for v in values if v.startswith("genid:")]) == 1


def test_an_intersection_with_nested_restrictions(store: str) -> None:
    values = _values(show(store, LAB + "RedGripperRobot"))
    assert f"owl:equivalentClass  {_printed(RED_GRIPPER_ROBOT)}" in [" ".join(v.split(" ", 1)) for v in values]


def test_a_class_a_restriction_names_shows_where(store: str) -> None:
    out = show(store, LAB + "Gripper")
    assert _printed(f"{LAB}Robot rdfs:subClassOf {LAB}hasPart some {LAB}Gripper") in out
    assert _printed(f"{LAB}RedGripperRobot owl:equivalentClass {RED_GRIPPER_ROBOT}") in out
    assert "genid:" not in out


def test_json_keeps_its_keys_and_adds_the_expression(store: str) -> None:
    rows = json.loads(show(store, LAB + "Robot", "--json"))
    assert all({"direction", "predicate", "other", "graph"} <= set(row) for row in rows)
    by_text = {row["other_text"]: row for row in rows if "other_text" in row and row["direction"] == "out"}
    assert sorted(by_text) == sorted(ROBOT)
    wheels = by_text[f"{LAB}hasPart exactly 4 {LAB}Wheel"]
    assert wheels["other"].startswith("https://w3id.org/cbrs/.well-known/genid/")
    assert wheels["expression"] == {
        "type": "exactly",
        "property": {"type": "property", "iri": LAB + "hasPart"},
        "cardinality": 4,
        "filler": {"type": "class", "iri": LAB + "Wheel"},
    }
    assert by_text[f"{LAB}hasColour value {LAB}Red"]["expression"]["filler"] == {
        "type": "individual",
        "iri": LAB + "Red",
    }
    gripper = json.loads(show(store, LAB + "Gripper", "--json"))
    # the owner, and the properties from it down to the node that points at the class
    owners = {
        (row["predicate"], tuple(row["owner"]["path"]))
        for row in gripper
        if row.get("owner", {}).get("iri") == LAB + "Robot"
    }
    assert owners == {
        (OWL + "someValuesFrom", (RDFS + "subClassOf",)),
        (RDF + "first", (RDFS + "subClassOf", OWL + "allValuesFrom", OWL + "unionOf", RDF + "rest", RDF + "rest")),
    }


def test_a_restriction_s_own_node_says_what_it_is(store: str) -> None:
    rows = json.loads(show(store, LAB + "Robot", "--json"))
    node = next(row["other"] for row in rows if row.get("other_text") == f"{LAB}touches Self")
    out = show(store, node)
    assert out.splitlines()[1] == _printed(f"  = {LAB}touches Self")


def test_a_parameter_that_takes_a_class_is_named_by_its_description(tmp_path: Path) -> None:
    location = str(tmp_path / "store")
    assert CliRunner().invoke(cli, ["--store", location, "init"]).exit_code == 0
    out = show(location, "home:ColourFeature")
    assert "svc:RecogniseObjectByColour_Kinect01 / cbrs:hasOWLSModel / cbrs:hasInput" in out
    assert "home:ObjectFeature rdfs:subClassOf home:hasColourFeature some home:ColourFeature" in out
    assert "home:hasHue some home:Hue" in out
    assert "genid:" not in out


def test_a_remote_store_names_a_bounded_number_of_nodes(
    remote_location: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each named node costs a few requests to a remote store: show names the first
    REMOTE_NAMED_NODES (the class's own node first) and says so."""
    monkeypatch.setattr("cbrs.cli.REMOTE_NAMED_NODES", 3)
    (tmp_path / "lab.ttl").write_text(ONTOLOGY, encoding="utf-8")
    assert CliRunner().invoke(cli, ["--store", remote_location, "load", str(tmp_path / "lab.ttl")]).exit_code == 0
    out = show(remote_location, LAB + "Robot")
    values = [v for v in _values(out) if v.startswith("rdfs:subClassOf")]
    assert len([v for v in values if "genid:" not in v]) == 3
    assert out.rstrip().endswith("(the first 3 anonymous nodes named; on a remote store each costs requests)")
