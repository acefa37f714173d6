"""OWL-S 1.1 written by hand in the styles other tools produce: KIF conditions (the OWL-S 1.1 examples'
language, s-expressions like PDDL's), IOPEs on the process only or on the profile only, and a relative
import the catalogue resolves. KIF conditions used to be kept as text only."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase, RdfParseError
from cbrs.kb.catalog import Catalogue
from cbrs.kb.namespaces import RDF

OWLS = Path(__file__).parent / "data" / "owls"
ROBOTS = "http://example.org/ontology/robots.owl#"
PLACES = "http://example.org/ontology/places.owl#"
BASE = "http://example.org/lab-services/"

HEAD = """<?xml version="1.0" encoding="UTF-8"?>
<rdf:RDF
    xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#"
    xmlns:owl="http://www.w3.org/2002/07/owl#"
    xmlns:service="http://www.daml.org/services/owl-s/1.1/Service.owl#"
    xmlns:profile="http://www.daml.org/services/owl-s/1.1/Profile.owl#"
    xmlns:process="http://www.daml.org/services/owl-s/1.1/Process.owl#"
    xmlns:expr="http://www.daml.org/services/owl-s/1.1/generic/Expression.owl#"
    xmlns:robots="http://example.org/ontology/robots.owl#"
    xml:base="http://example.org/lab-services/{name}.owls">
  <owl:Ontology rdf:about="">
    <owl:imports rdf:resource="../ontology/robots.owl"/>
  </owl:Ontology>
"""
TYPE = '<process:parameterType rdf:datatype="http://www.w3.org/2001/XMLSchema#anyURI">{}</process:parameterType>'

PROCESS_ONLY = (
    HEAD
    + """
  <service:Service rdf:ID="Charge">
    <service:presents><profile:Profile rdf:ID="ChargeProfile">
      <profile:serviceName>Charge robot</profile:serviceName>
    </profile:Profile></service:presents>
    <service:describedBy><process:AtomicProcess rdf:ID="ChargeProcess">
      <process:hasInput><process:Input rdf:ID="Robot">{robot}</process:Input></process:hasInput>
      <process:hasLocal><process:Local rdf:ID="Place">{room}</process:Local></process:hasLocal>
      <process:hasPrecondition><expr:KIF-Condition>
        <expr:expressionLanguage rdf:resource="http://www.daml.org/services/owl-s/1.1/generic/Expression.owl#KIF"/>
        <expr:expressionBody>(and (robots:isLocatedIn ?Robot ?Place)
          (=> (robots:isBusy ?Robot ?Place) (robots:Open ?Robot)))</expr:expressionBody>
      </expr:KIF-Condition></process:hasPrecondition>
      <process:hasResult><process:Result><process:hasEffect><expr:KIF-Condition>
        <expr:expressionLanguage rdf:resource="http://www.daml.org/services/owl-s/1.1/generic/Expression.owl#KIF"/>
        <expr:expressionBody>(robots:Charged ?Robot)</expr:expressionBody>
      </expr:KIF-Condition></process:hasEffect></process:Result></process:hasResult>
    </process:AtomicProcess></service:describedBy>
  </service:Service>
</rdf:RDF>
"""
).format(name="charge", robot=TYPE.format(ROBOTS + "MobileRobot"), room=TYPE.format(PLACES + "Room"))

PROFILE_ONLY = (
    HEAD
    + """
  <profile:Profile rdf:ID="FindDoor">
    <profile:serviceName>Find door</profile:serviceName>
    <profile:hasInput><process:Input rdf:ID="Pos">{position}</process:Input></profile:hasInput>
    <profile:hasOutput><process:Output rdf:ID="Door">{door}</process:Output></profile:hasOutput>
    <profile:hasPrecondition><expr:KIF-Condition>
      <expr:expressionBody>(robots:isLocatedIn ?Door ?Pos)</expr:expressionBody>
    </expr:KIF-Condition></profile:hasPrecondition>
  </profile:Profile>
</rdf:RDF>
"""
).format(name="find_door", position=TYPE.format(ROBOTS + "Position"), door=TYPE.format(ROBOTS + "Door"))


@pytest.fixture
def loaded(tmp_path: Path) -> KnowledgeBase:
    (tmp_path / "charge.owls").write_text(PROCESS_ONLY, encoding="utf-8")
    (tmp_path / "find_door.owls").write_text(PROFILE_ONLY, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    report = kb.load([tmp_path], catalogue=Catalogue.open(OWLS / "catalog-v001.xml"))
    assert not report.unresolved_imports  # the relative import, resolved against xml:base, is in the catalogue
    assert {item.ontology for item in report.imports} >= {"http://example.org/ontology/robots.owl"}
    return kb


def _conditions(kb: KnowledgeBase, iri: str) -> set[tuple[str, str, str, str]]:
    rows = kb.select("description_conditions", {"description": iri})
    return {(r["role"].value, r["subject"].value, r["predicate"].value, r["object"].value) for r in rows}


def test_kif_atoms_become_statements(loaded: KnowledgeBase) -> None:
    assert _conditions(loaded, BASE + "charge.owls#Charge") == {
        ("precondition", ROBOTS + "MobileRobot", ROBOTS + "isLocatedIn", PLACES + "Room"),
        ("effect", ROBOTS + "MobileRobot", RDF + "type", ROBOTS + "Charged"),
    }


def test_a_kif_implication_stays_text(loaded: KnowledgeBase) -> None:
    rows = loaded.query(
        "SELECT ?text WHERE { ?c a cbrs:Precondition ; cbrs:conditionText ?text ; cbrs:conditionPredicate ?p }"
    )
    texts = {row["text"].value for row in rows}  # type: ignore[union-attr]
    assert any(text.startswith("(and (robots:isLocatedIn") for text in texts)
    predicates = {
        r["predicate"].value
        for r in loaded.select("description_conditions", {"description": BASE + "charge.owls#Charge"})
    }
    assert ROBOTS + "isBusy" not in predicates and RDF + "type" in predicates


def test_process_only_and_profile_only_iopes(loaded: KnowledgeBase) -> None:
    charge = loaded.description(BASE + "charge.owls#Charge")
    assert [p.type for p in charge.inputs] == [ROBOTS + "MobileRobot"]
    find = loaded.description(BASE + "find_door.owls#FindDoor")
    assert ([p.type for p in find.inputs], [p.type for p in find.outputs]) == ([ROBOTS + "Position"], [ROBOTS + "Door"])
    assert _conditions(loaded, BASE + "find_door.owls#FindDoor") == {
        ("precondition", ROBOTS + "Door", ROBOTS + "isLocatedIn", ROBOTS + "Position")
    }


def test_a_broken_imported_ontology_loads_nothing(tmp_path: Path) -> None:
    """All or nothing, imports included: the catalogue maps the import to a file cut short."""
    (tmp_path / "charge.owls").write_text(PROCESS_ONLY, encoding="utf-8")
    ontology = tmp_path / "ontology"
    ontology.mkdir()
    (ontology / "places.owl").write_bytes((OWLS / "ontology" / "places.owl").read_bytes())
    whole = (OWLS / "ontology" / "robots.owl").read_text(encoding="utf-8")
    (ontology / "robots.owl").write_text(whole[: whole.index("</rdf:RDF>")], encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    before = kb.store.dump()
    with pytest.raises(RdfParseError) as caught:
        kb.load([tmp_path / "charge.owls"], catalogue=Catalogue.open(ontology))
    assert str(caught.value).startswith(str(ontology / "robots.owl"))
    assert kb.store.dump() == before
